"""Energy integrals of the exact solver (models.solvers.exact_model): the work of every element over a run,
integrated exactly between switches from the same solution operators as the states (the per-sample sums numba
kernels on plain float arrays, cached on disk like models.solvers.exact_kernels; a key's integral operators,
built once per key, NumPy)."""

from __future__ import annotations

import numpy as np
from numba import njit

from .exact_kernels import matvec


def power_integrals(one_step: np.ndarray, balanced: np.ndarray, scale: np.ndarray, forms: np.ndarray, step_s: float,
                    step_powers: np.ndarray, step_grams: np.ndarray, series: np.ndarray) -> None:
    """The integrals G(s) = int_0^s expm(A^T u) Q expm(A u) du of one key's power forms Q_q (power w^T Q w,
    models.solvers.exact_system.Model.power_forms): ``step_powers`` [j] = E^j (E = expm(A h), j <= p, the sub-steps
    of a sample); ``series`` [q, k] = S_k / (k + 1), the integrand's Taylor coefficients S_0 = Q,
    S_k = (A^T S_(k-1) + S_(k-1) A) / k (it solves F' = A^T F + F A), formed on the balanced matrix
    A_b = D^-1 A D (S_k = D^-1 S_k,b(D Q D) D^-1), so that G(s) = sum_k s^(k+1) series[q, k] for s <= h (the
    truncation after the Taylor order K of the sub-step leaves 2^(K+1) / (K+1)! of it, below 1e-14);
    ``step_grams`` [q, j] = G(j h) = sum_(l < j) (E^l)^T G(h) E^l. NumPy, not compiled: matrix products once per
    key (numba took 2.1 CPU s to compile it on a process's first run)."""
    size, steps, terms = one_step.shape[0], step_powers.shape[0], series.shape[1]
    step_powers[0] = np.eye(size)
    for j in range(1, steps):
        step_powers[j] = np.dot(one_step, step_powers[j - 1])
    unscale = 1.0 / np.multiply.outer(scale, scale)
    balanced_t = balanced.T.copy()
    with np.errstate(over="ignore", invalid="ignore"):  # a diverging scene's terms: inf, as the run's check reports
        for q in range(forms.shape[0]):
            coefficient, gram = scale[:, None] * forms[q] * scale[None, :], np.zeros((size, size))
            power = step_s
            for k in range(terms):
                if k:
                    coefficient = (np.dot(balanced_t, coefficient) + np.dot(coefficient, balanced)) / k
                series[q, k] = coefficient / (k + 1) * unscale
                gram += series[q, k] * power
                power *= step_s
            step_grams[q, 0] = 0.0
            for j in range(1, steps):
                carried = step_powers[j - 1]
                step_grams[q, j] = step_grams[q, j - 1] + np.dot(np.dot(carried.T, gram), carried)


@njit(cache=True)
def quadratic(form: np.ndarray, w: np.ndarray) -> float:
    """w^T Q w."""
    total = 0.0
    for r in range(w.shape[0]):
        partial = 0.0
        for c in range(w.shape[0]):
            partial += form[r, c] * w[c]
        total += w[r] * partial
    return total


@njit(cache=True, fastmath=True)
def series_value(series: np.ndarray, outer: np.ndarray, last: int, s: float) -> float:
    """sum_(k <= last) s^k <C_k, w w^T> (Frobenius products with the flattened C_k = series[k] and
    outer = w w^T, summed by Horner's rule): w^T (sum_k s^k C_k) w."""
    value = 0.0
    for k in range(last, -1, -1):
        product = 0.0
        for e in range(outer.shape[0]):
            product += series[k, e] * outer[e]
        value = value * s + product
    return value


@njit(cache=True)
def integrate_powers(time_s: np.ndarray, rows: np.ndarray, row_keys: np.ndarray, step_powers: np.ndarray,
                     step_grams: np.ndarray, series: np.ndarray, step_s: float, sample_interval_s: float,
                     out: np.ndarray) -> None:
    """out[r, q] = int w^T Q_q w dt from row r - 1 to row r for every interval that is not a whole sample
    interval (those are left as they are), for every quadratic form q of a key, exactly: between two
    rows one key propagates w(t_(r-1) + s) = expm(A s) w_(r-1), so the integral is w_(r-1)^T G(s) w_(r-1),
    G(s) = int_0^s expm(A^T u) Q expm(A u) du: the j whole sub-steps first, G(j h) (``step_grams``
    [key, q, j], j up to the sub-steps of a sample) with the state carried on by expm(A h)^j
    (``step_powers`` [key, j]), then the rest s < h by the series G(s) = sum_k s^(k+1) C_k (``series``
    [key, q, k], each C_k flattened) from the first k whose bound (2 s / h)^(k+1) / (k+1)! (||A|| h
    <= 1 on the balanced matrix) is below 1e-17."""
    size, count, terms, most = step_powers.shape[2], step_grams.shape[1], series.shape[2], step_powers.shape[1] - 1
    w, carried, outer = np.empty(size), np.empty(size), np.empty(size * size)
    for r in range(1, time_s.shape[0]):
        rest = time_s[r] - time_s[r - 1]
        if rest <= 0.0 or abs(rest - sample_interval_s) <= 1e-9 * sample_interval_s:
            continue
        key = row_keys[r - 1]
        for q in range(count):
            out[r, q] = 0.0
        for c in range(size):
            w[c] = rows[r - 1, c]
        whole = 0
        while rest > step_s * (1.0 + 1e-9):
            whole += 1
            rest -= step_s
        while whole > 0:
            j = min(whole, most)
            for q in range(count):
                out[r, q] += quadratic(step_grams[key, q, j], w)
            matvec(step_powers[key, j], w, carried)
            for c in range(size):
                w[c] = carried[c]
            whole -= j
        last, bound, ratio = 0, 2.0 * rest / step_s, 2.0 * rest / step_s
        while bound > 1e-17 and last < terms - 1:
            last += 1
            bound *= ratio / (last + 1)
        for a in range(size):
            for b in range(size):
                outer[a * size + b] = w[a] * w[b]
        for q in range(count):
            out[r, q] += series_value(series[key, q], outer, last, rest) * rest
