"""A key's propagators, works and impulses over dyadic fractions of the wave step, and the first switch
located on them.

For a key (models.waves.system) and the step h, level j (j = 0 .. LEVELS, s_j = h / 2^j) holds
E_j = expm(A s_j) (each level its own exponential: squaring the finer ones lost 1e-7 of Lundberg's
efficiency on a rigid unloading), the Gram matrices G_j = int_0^s_j expm(A^T u) Q expm(A u) du of the power forms
(models.waves.works) and, with kinematic bodies, Phi_j = int_0^s_j expm(A u) du. The levels with
||A|| s_j <= 1/2 take G from its Taylor series in the Lyapunov operator L(X) = A^T X + X A,

    G(s) = sum_k s^(k+1) / (k+1)! L^k(Q),

summed to round-off (each term at most half the one before there: 4e-16 of Van Loan's block exponential
[[-A^T, Q], [0, A]] on the 30 m hole's keys, at a 16th of its cost), and Phi from its block exponential
[[A, I], [0, 0]], built when first needed; the coarser ones by doubling,

    G_{j-1} = G_j + E_j^T G_j E_j,   Phi_{j-1} = Phi_j + E_j Phi_j

(a series or Van Loan's block over a whole step would overflow on a stiff mode, a rigid unloading or a stiff
contact; doubling from much finer levels than needed loses digits: measured 2.8e-7 of Lundberg's
efficiency from the finest level against 5e-12 from the first level with ||A|| s_j <= 1/2). A piece
of any length s <= h is then the product of the levels of the binary digits of s / h (to h / 2^LEVELS,
5e-16 s at a step of 2 us): no matrix exponential per piece. The first switch in a piece (the first exit
function to cross zero in its direction) is found by bisection on the same grid (models.waves.kernels:
``first_crossing``).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.linalg import expm

from .kernels import first_crossing
from .system import Key
from .works import power_forms

LEVELS = 32
MAX_TERMS = 64  # the Gram series' terms at most (||A|| s <= 1/2: about 20 reach round-off)
ROUND_OFF = 1e-17  # the series stops at a term this small against the sum


class KeyLevels:
    """The levels of one key (module doc)."""

    def __init__(self, matrix: np.ndarray, forms: np.ndarray, step_s: float, impulses: bool) -> None:
        self.step_s, self.matrix, self.forms, self.impulses = step_s, matrix, forms, impulses
        m = matrix.shape[0]
        norm = np.linalg.norm(matrix, 1) * step_s
        self.first = min(LEVELS, max(0, math.ceil(math.log2(max(norm / 0.5, 1.0)))))
        self.steps = np.array([expm(matrix * (step_s / 2**j)) for j in range(LEVELS + 1)]).reshape(LEVELS + 1, m, m)
        self._grams: dict[int, np.ndarray] = {}
        self._integrals: dict[int, np.ndarray] = {}

    def gram(self, j: int) -> np.ndarray:
        """G_j of every form (module doc)."""
        if j not in self._grams:
            if j >= self.first:
                self._grams[j] = _gram_series(self.matrix, self.forms, self.step_s / 2**j)
            else:
                finer = self.gram(j + 1)
                self._grams[j] = finer + self.steps[j + 1].T @ finer @ self.steps[j + 1]
        return self._grams[j]

    def integral(self, j: int) -> np.ndarray:
        """Phi_j (module doc)."""
        if j not in self._integrals:
            if j >= self.first:
                m = self.matrix.shape[0]
                block = np.zeros((2 * m, 2 * m))
                block[:m, :m], block[:m, m:] = self.matrix, np.eye(m)
                self._integrals[j] = expm(block * (self.step_s / 2**j))[:m, m:]
            else:
                finer = self.integral(j + 1)
                self._integrals[j] = finer + self.steps[j + 1] @ finer
        return self._integrals[j]

    def units(self, span_s: float) -> int:
        """``span_s`` in finest steps."""
        return round(float(span_s) / self.step_s * 2**LEVELS)

    def advance(self, w: np.ndarray, span_s: float) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
        """(w after ``span_s``, the works over it (one per form), int_0^span w(u) du or None)."""
        units = self.units(span_s)
        works = np.zeros(len(self.forms))
        moved = np.zeros_like(w) if self.impulses else None
        for j in range(LEVELS + 1):
            if units >> (LEVELS - j) & 1:
                works += (self.gram(j).reshape(-1, len(w)) @ w).reshape(len(works), -1) @ w
                if moved is not None:
                    moved += self.integral(j) @ w
                w = self.steps[j] @ w
        return w, works, moved

    def first_switch(self, rows: np.ndarray, slopes: np.ndarray, w0: np.ndarray, span_s: float,
                     candidates: np.ndarray) -> tuple[float, int] | None:
        """(time into the piece, exit) of the first crossing of ``rows`` . w > 0 in (0, span] among the
        exits ``candidates`` (a mask: those on their crossed side at the piece's end or with a maximum
        inside), to one finest step (module doc); None when there is none (a maximum that stays below)."""
        exits = np.flatnonzero(candidates)
        units, exit_ = first_crossing(self.steps, np.ascontiguousarray(rows[candidates]),
                                      np.ascontiguousarray(slopes[candidates]), np.ascontiguousarray(w0),
                                      self.units(span_s), LEVELS)
        if exit_ < 0:
            return None
        return units * self.step_s / 2**LEVELS, int(exits[exit_])


def _gram_series(matrix: np.ndarray, forms: np.ndarray, span_s: float) -> np.ndarray:
    """int_0^s expm(A^T u) Q expm(A u) du of every form Q: sum_k s^(k+1) / (k+1)! L^k(Q), L(X) = A^T X + X A,
    to round-off (||A|| s <= 1/2; module doc)."""
    scaled = matrix * span_s
    term = forms * span_s
    total = term.copy()
    for k in range(2, MAX_TERMS):
        term = (scaled.T @ term + term @ scaled) / k
        total += term
        if np.max(np.abs(term)) <= ROUND_OFF * np.max(np.abs(total)):
            break
    return total


def key_levels(stepper, key: Key) -> KeyLevels:
    """The levels of ``key`` on the stepper's step, built on first use."""
    if "levels" not in key.cache:
        forms = key.cache.get("forms")
        if forms is None:
            forms = key.cache["forms"] = power_forms(stepper, key)
        key.cache["levels"] = KeyLevels(key.matrix, forms, stepper.step_s, bool(stepper.kinematic))
    return key.cache["levels"]
