"""Compiled event loop of the exact solver (models.solvers.exact_model): numba kernels on plain float arrays.

The solution operators come from SciPy (``expm`` once per rock mode and pulse phase, in
models.solvers.exact_model); these kernels only combine them. A batch of sub-grid points takes two matrix
products (BLAS through ``np.dot``): the anchor states expm(A a B h) s0 (a < A), then the outputs
R expm(A b h) of every point a B + b from its anchor, in chunks of CHUNK anchors up to the first
crossing; R stacks the identity, the rock and piston force rows and the exit rows, so a point's
outputs are (w, F_r, F_d, g_e). Compiled functions are cached on disk (``cache=True``); :func:`assemble`, run once
per key, is plain NumPy.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

OK, TOO_MANY_SWITCHES, DIVERGED, MISSING_KEY, BLOW_START = 0, 1, 2, 3, 4  # kernel status
RESUME_PHASE, RESUME_MODE = 2, 1  # progress[4]: start the pulse phase (a blow reset applied), go on in a mode
CHUNK = 4  # anchors whose points are formed per matrix product
BRENT_MAX_ITERATIONS = 100
BRENT_RTOL = 4 * np.finfo(float).eps
BRENT_XTOL = 1e-24


@njit(cache=True)
def matvec(matrix: np.ndarray, vector: np.ndarray, out: np.ndarray) -> None:
    """out = M v."""
    for r in range(out.shape[0]):
        total = 0.0
        for c in range(vector.shape[0]):
            total += matrix[r, c] * vector[c]
        out[r] = total


@njit(cache=True)
def taylor_sum(terms: np.ndarray, s: float, out: np.ndarray) -> None:
    """out_j = sum_k s^k terms_kj for the first len(out) columns j (Horner)."""
    last = terms.shape[0] - 1
    for j in range(out.shape[0]):
        out[j] = terms[last, j]
    for k in range(last - 1, -1, -1):
        for j in range(out.shape[0]):
            out[j] = out[j] * s + terms[k, j]


@njit(cache=True)
def taylor_terms(taylor: np.ndarray, w: np.ndarray, terms: np.ndarray) -> None:
    """terms_k = R A^k w / k!, k = 0..K, for w (1 x m), from taylor = [(R A^0/0!)^T | ... | (R A^K/K!)^T]
    (m x (K + 1) r), into terms (1 x (K + 1) r): the outputs at t + s are sum_k s^k terms_k."""
    np.dot(w, taylor, terms)


@njit(cache=True)
def horner(coefficients: np.ndarray, s: float) -> float:
    """sum_k c_k s^k."""
    value = 0.0
    for k in range(coefficients.shape[0] - 1, -1, -1):
        value = value * s + coefficients[k]
    return value


@njit(cache=True, error_model="numpy")
def brent(coefficients: np.ndarray, low: float, high: float) -> float:
    """Root of the polynomial sum_k c_k s^k in [low, high] (signs differ at the ends) by Brent's
    method, as scipy.optimize.brentq: |error| < (BRENT_XTOL + BRENT_RTOL |root|) / 2. An interpolation
    step that divides by zero (two equal values) is inf or nan, fails the acceptance test and bisects,
    as in SciPy's C code (error_model="numpy": IEEE division, no ZeroDivisionError)."""
    x_pre, x_cur = low, high
    f_pre, f_cur = horner(coefficients, x_pre), horner(coefficients, x_cur)
    if f_pre == 0.0:
        return x_pre
    if f_cur == 0.0:
        return x_cur
    x_blk = f_blk = s_pre = s_cur = 0.0
    for _ in range(BRENT_MAX_ITERATIONS):
        if f_pre != 0.0 and f_cur != 0.0 and (f_pre < 0.0) != (f_cur < 0.0):
            x_blk, f_blk = x_pre, f_pre
            s_pre = s_cur = x_cur - x_pre
        if abs(f_blk) < abs(f_cur):
            x_pre, x_cur, x_blk = x_cur, x_blk, x_cur
            f_pre, f_cur, f_blk = f_cur, f_blk, f_cur
        delta = (BRENT_XTOL + BRENT_RTOL * abs(x_cur)) / 2
        s_bis = (x_blk - x_cur) / 2
        if f_cur == 0.0 or abs(s_bis) < delta:
            return x_cur
        bisect = True
        if abs(s_pre) > delta and abs(f_cur) < abs(f_pre):
            if x_pre == x_blk:  # secant
                s_try = -f_cur * (x_cur - x_pre) / (f_cur - f_pre)
            else:  # inverse quadratic extrapolation
                d_pre = (f_pre - f_cur) / (x_pre - x_cur)
                d_blk = (f_blk - f_cur) / (x_blk - x_cur)
                s_try = -f_cur * (f_blk * d_blk - f_pre * d_pre) / (d_blk * d_pre * (f_blk - f_pre))
            if 2 * abs(s_try) < min(abs(s_pre), 3 * abs(s_bis) - delta):
                s_pre, s_cur, bisect = s_cur, s_try, False
        if bisect:
            s_pre = s_cur = s_bis
        x_pre, f_pre = x_cur, f_cur
        x_cur += s_cur if abs(s_cur) > delta else (delta if s_bis > 0 else -delta)
        f_cur = horner(coefficients, x_cur)
    return x_cur


@njit(cache=True)
def diverged(rows: np.ndarray, row: int, bodies: int, position_limit_m: float) -> bool:
    """rows[row] starts with a non-finite velocity or a position not within +-position_limit_m (checked
    at every switch, pulse switch and batch end; the caller locates the first such sample)."""
    for i in range(bodies):
        if not abs(rows[row, i]) <= position_limit_m or not math.isfinite(rows[row, bodies + i]):
            return True
    return False


@njit(cache=True)
def record(time_out: np.ndarray, rows: np.ndarray, row_keys: np.ndarray, row: int, time_s: float, w: np.ndarray,
           rock_row: np.ndarray, impact_row: np.ndarray, key: int) -> None:
    """time_out[row] = t, rows[row, :m + 2] = (w, F_r = rock_row . w, F_d = impact_row . (1, u1, u2)),
    row_keys[row] = the key that propagates from this row on."""
    size = rock_row.shape[0]
    time_out[row] = time_s
    row_keys[row] = key
    rock = 0.0
    for c in range(size):
        rows[row, c] = w[c]
        rock += rock_row[c] * w[c]
    rows[row, size] = rock
    rows[row, size + 1] = impact_row[0] * w[size - 3] + impact_row[1] * w[size - 2] + impact_row[2] * w[size - 1]


@njit(cache=True)
def first_crossing(coefficients: np.ndarray, slopes: np.ndarray, low: float, high: float) -> float:
    """Earliest s in [low, high] where p(s) = sum_k c_k s^k is on the crossed side (p > 0), inf if none:
    the root of p before high where p(high) > 0 (low if p(low) >= 0 already); where p(high) <= 0 but p
    rises at low and falls at high, the root before its maximum if that maximum is above 0 (a crossing
    and its return within one interval of the sub-grid, which the signs at the points cannot see).
    ``slopes`` is scratch for the coefficients of p'."""
    last = coefficients.shape[0] - 1
    for k in range(last):
        slopes[k] = (k + 1) * coefficients[k + 1]
    slopes[last] = 0.0
    value_low = horner(coefficients, low)
    if horner(coefficients, high) > 0.0:
        return low if value_low >= 0.0 else brent(coefficients, low, high)
    if horner(slopes, low) > 0.0 and horner(slopes, high) < 0.0:
        peak = brent(slopes, low, high)
        if horner(coefficients, peak) > 0.0:
            return low if value_low >= 0.0 else brent(coefficients, low, peak)
    return math.inf


@njit(cache=True)
def exit_polynomial(terms: np.ndarray, exits0: int, e: int, direction: float, coefficients: np.ndarray) -> None:
    """coefficients_k = direction_e g_e,k: exit function e on its crossed side where positive."""
    for k in range(terms.shape[0]):
        coefficients[k] = direction * terms[k, exits0 + e]


@njit(cache=True)
def locate(terms: np.ndarray, exits0: int, exit_count: int, directions: np.ndarray, low: float, high: float,
           coefficients: np.ndarray, slopes: np.ndarray, outputs: np.ndarray) -> tuple[float, int]:
    """Earliest switch s in [low, high] from the Taylor terms of the outputs (taylor_terms): the
    earliest :func:`first_crossing` of the exit functions g_e direction_e; with none, s = high and
    the exit furthest on its crossed side there. outputs = outputs at s; returns (s, e)."""
    root, exit_ = math.inf, -1
    for e in range(exit_count):
        exit_polynomial(terms, exits0, e, directions[e], coefficients)
        candidate = first_crossing(coefficients, slopes, low, high)
        if candidate < root:
            root, exit_ = candidate, e
    if exit_ < 0:  # a crossing the sub-grid saw but the polynomial puts at round-off level
        root, largest = high, -math.inf
        for e in range(exit_count):
            exit_polynomial(terms, exits0, e, directions[e], coefficients)
            value = horner(coefficients, high)
            if value > largest:
                largest, exit_ = value, e
    taylor_sum(terms, root, outputs)
    return root, exit_


@njit(cache=True)
def turns_across(terms: np.ndarray, exits0: int, e: int, direction: float, low: float, high: float,
                 coefficients: np.ndarray, slopes: np.ndarray) -> bool:
    """Exit function e, on its uncrossed side at both ends of [low, high], crosses and returns in between
    (:func:`first_crossing` from the terms of the interval's start)."""
    exit_polynomial(terms, exits0, e, direction, coefficients)
    return first_crossing(coefficients, slopes, low, high) < math.inf


@njit(cache=True)
def run_events(taylor: np.ndarray, one_step: np.ndarray, anchors: np.ndarray, readout: np.ndarray,
               exit_counts: np.ndarray, directions: np.ndarray, next_modes: np.ndarray, rock_rows: np.ndarray,
               impact_rows: np.ndarray, key_of: np.ndarray, phase_times_s: np.ndarray, phase_ids: np.ndarray,
               phase_pulse_states: np.ndarray, blow_starts: np.ndarray, reset_counts: np.ndarray, reset_targets: np.ndarray,
               reset_rows: np.ndarray, monotone: int, step_s: float, per_anchor: int, per_sample: int,
               min_switch_interval_s: float, max_switches: int, bodies: int, position_limit_m: float,
               progress: np.ndarray, clock: np.ndarray, w: np.ndarray, time_out: np.ndarray, rows: np.ndarray,
               row_keys: np.ndarray, switch_times_s: np.ndarray, switch_modes: np.ndarray) -> int:
    """The event loop of models.solvers.exact_model (its module doc), from pulse phase progress[0] on.

    Per key (rock mode, pulse phase), with R = (I_m, rock row, piston row, exit rows c_e, their slope
    rows c_e A), r rows, and
    B = ``per_anchor``: ``taylor`` [(R A^k / k!)^T]_k, ``one_step`` expm(A h), ``anchors``
    [expm(A a B h)^T]_a (m x A m), ``readout``
    [(R expm(A b h))^T]_b (m x B r); per exit e of a key the next mode id ``next_modes`` and the entry
    resets w[reset_targets[j]] = reset_rows[j] . w (j < reset_counts; the ``monotone`` entry keeps the
    larger of old and new value). Fills ``time_out``, ``rows`` (w, F_r, F_d; both sides of every
    switch), ``row_keys`` (the key propagating from each row) and the switch log. The run's state is
    progress = (phase, mode id, rows filled, switches,
    resume), clock = (t, mode start) and w: a key not built yet (key_of -1) returns MISSING_KEY with
    resume = 1, and the call after it is built goes on from there. A phase that starts a blow
    (``blow_starts`` nonzero) returns BLOW_START first, with w at the blow start and resume = 2: the
    caller sets the rock state the blow meets (and its mode id) and calls again. Returns OK,
    TOO_MANY_SWITCHES, DIVERGED, MISSING_KEY or BLOW_START.
    """
    size, width = w.shape[0], readout.shape[2] // per_anchor  # m, r
    exits0 = size + 2  # first exit output
    slopes0 = exits0 + directions.shape[1]  # first exit slope output
    anchor_count = anchors.shape[2] // size  # A
    batch = anchor_count * per_anchor  # J = A B
    h = step_s
    # buffers and views made once: a view made in the loop costs two atomic reference counts
    start, base, final = np.empty((1, size)), np.empty((1, size)), np.empty(width)
    start_row, base_row = start[0], base[0]
    scratch = np.empty((batch, width))
    anchor_states = np.empty((anchor_count, size))
    anchor_flat = anchor_states.reshape(1, anchor_count * size)
    terms = np.empty((taylor.shape[2] // width, width))
    terms_flat = terms.reshape(1, terms.size)
    coefficients, slopes = np.empty(terms.shape[0]), np.empty(terms.shape[0])
    start_slopes = np.empty(directions.shape[1])
    p, mode, row, switches, resume = progress[0], progress[1], progress[2], progress[3], progress[4]
    t, mode_start_s = clock[0], clock[1]
    while p < phase_ids.shape[0]:
        end_s, phase = phase_times_s[p, 1], phase_ids[p]
        if resume == 0 and blow_starts[p]:  # the caller sets the state the blow meets first
            progress[0], progress[1], progress[2], progress[3], progress[4] = p, mode, row, switches, RESUME_PHASE
            clock[0], clock[1] = phase_times_s[p, 0], mode_start_s
            return BLOW_START
        if resume != RESUME_MODE:  # a pulse phase starts
            t = phase_times_s[p, 0]
            w[size - 2], w[size - 1] = phase_pulse_states[p, 0], phase_pulse_states[p, 1]
        resume = 0
        key = key_of[mode, phase]
        if key < 0:
            progress[0], progress[1], progress[2], progress[3], progress[4] = p, mode, row, switches, RESUME_MODE
            clock[0], clock[1] = t, mode_start_s
            return MISSING_KEY
        taylor_k, step_k, anchors_k, readout_k = taylor[key], one_step[key], anchors[key], readout[key]
        rock_k, impact_k, directions_k, exit_count = rock_rows[key], impact_rows[key], directions[key], exit_counts[key]
        record(time_out, rows, row_keys, row, t, w, rock_k, impact_k, key)
        row += 1
        while True:
            # sub-grid points first + i, i < count <= J, after t and before end_s
            first = math.floor(t / h) + 1
            if first * h <= t:
                first += 1
            count = 0
            while count < batch and (first + count) * h < end_s:
                count += 1
            crossed, done = -1, 0  # first point on the crossed side of an exit function; points formed
            for e in range(exit_count):  # the exit functions' slopes at w, for the turns in its interval
                start_slopes[e] = 0.0
                for c in range(size):
                    start_slopes[e] += taylor_k[c, slopes0 + e] * w[c]
            # dense output (every sub-grid point a sample): the points are formed in place in ``rows``
            point = rows[row:row + batch] if per_sample == 1 else scratch
            if count:
                if (first - 1) * h == t:
                    matvec(step_k, w, start_row)
                else:
                    for c in range(size):
                        base_row[c] = w[c]
                    taylor_terms(taylor_k, base, terms_flat)
                    taylor_sum(terms, first * h - t, start_row)
                used = (count + per_anchor - 1) // per_anchor
                if used == 1:
                    for c in range(size):
                        anchor_states[0, c] = start_row[c]
                else:
                    np.dot(start, anchors_k, anchor_flat)
                points = point.reshape(anchor_count, per_anchor * width)
                while done < count and crossed < 0:
                    low_anchor = done // per_anchor
                    high_anchor = min(used, low_anchor + CHUNK)
                    np.dot(anchor_states[low_anchor:high_anchor], readout_k, points[low_anchor:high_anchor])
                    for i in range(done, min(count, high_anchor * per_anchor)):
                        for e in range(exit_count):
                            direction = directions_k[e]
                            if point[i, exits0 + e] * direction > 0.0:
                                crossed = i
                                break
                            before = point[i - 1, slopes0 + e] if i else start_slopes[e]
                            if before * direction > 0.0 and point[i, slopes0 + e] * direction < 0.0:
                                # it turns back between the points: does it cross and return?
                                t_before = (first + i - 1) * h if i else t
                                for c in range(size):
                                    base_row[c] = point[i - 1, c] if i else w[c]
                                taylor_terms(taylor_k, base, terms_flat)
                                low = max(0.0, min(mode_start_s + min_switch_interval_s, (first + i) * h) - t_before)
                                if turns_across(terms, exits0, e, direction, low, (first + i) * h - t_before,
                                                coefficients, slopes):
                                    crossed = i
                                    break
                        if crossed >= 0:
                            break
                    done = min(count, high_anchor * per_anchor)
            more = count == batch and (first + batch) * h < end_s  # end_s lies beyond this batch
            if crossed < 0 and not more:  # the phase end: point ``count``
                for c in range(size):
                    base_row[c] = point[count - 1, c] if count else w[c]
                taylor_terms(taylor_k, base, terms_flat)
                t_before = (first + count - 1) * h if count else t
                taylor_sum(terms, end_s - t_before, final)
                for e in range(exit_count):
                    direction = directions_k[e]
                    before = point[count - 1, slopes0 + e] if count else start_slopes[e]
                    low = max(0.0, min(mode_start_s + min_switch_interval_s, end_s) - t_before)
                    if final[exits0 + e] * direction > 0.0 or (
                            before * direction > 0.0 and final[slopes0 + e] * direction < 0.0
                            and turns_across(terms, exits0, e, direction, low, end_s - t_before, coefficients,
                                             slopes)):
                        crossed = count
                        break
            formed = crossed if crossed >= 0 else count
            if crossed > 0:
                t_left = (first + crossed - 1) * h
                for c in range(size):
                    base_row[c] = point[crossed - 1, c]
                taylor_terms(taylor_k, base, terms_flat)
            elif crossed < 0:
                for c in range(size):
                    w[c] = point[count - 1, c] if more else final[c]
            for i in range((-first) % per_sample, formed, per_sample):
                time_out[row] = (first + i) * h
                row_keys[row] = key
                if per_sample > 1:
                    for c in range(width):
                        rows[row, c] = point[i, c]
                row += 1
            if formed and diverged(point, formed - 1, bodies, position_limit_m):
                progress[2], progress[3] = row, switches
                return DIVERGED
            if crossed < 0:
                if not more:
                    record(time_out, rows, row_keys, row, end_s, final, rock_k, impact_k, key)
                    row += 1
                    p += 1
                    break
                t = (first + count - 1) * h
                continue
            if crossed == 0:
                t_left = t
                for c in range(size):
                    base_row[c] = w[c]
                taylor_terms(taylor_k, base, terms_flat)
            t_right = (first + crossed) * h if crossed < count else end_s
            low = max(0.0, min(mode_start_s + min_switch_interval_s, t_right) - t_left)
            root, e = locate(terms, exits0, exit_count, directions_k, low, t_right - t_left, coefficients, slopes,
                             final)
            t = t_left + root
            record(time_out, rows, row_keys, row, t, final, rock_k, impact_k, key)
            row += 1
            mode, mode_start_s = next_modes[key, e], t
            for c in range(size):
                w[c] = final[c]
            for j in range(reset_counts[key, e]):  # entry values of the new mode, from the switch state
                target, value = reset_targets[key, e, j], 0.0
                for c in range(size):
                    value += reset_rows[key, e, j, c] * final[c]
                w[target] = max(final[target], value) if target == monotone else value
            switch_times_s[switches], switch_modes[switches] = t, mode
            switches += 1
            resume = RESUME_MODE  # the new mode goes on from (t, w) in this pulse phase
            break
        progress[2], progress[3] = row, switches
        if switches > max_switches:
            return TOO_MANY_SWITCHES
        if diverged(rows, row - 1, bodies, position_limit_m):  # the last record: phase end or switch
            return DIVERGED
    return OK


def assemble(one_step: np.ndarray, matrix: np.ndarray, readout_rows: np.ndarray, anchor_count: int, per_anchor: int,
             readout: np.ndarray, anchors: np.ndarray, taylor: np.ndarray) -> None:
    """The cached operators of one key from E = expm(A h), A and R: readout [(R E^b)^T]_b (b < B),
    anchors [(E^(a B))^T]_a (a < A), taylor [(R A^k / k!)^T]_k (k <= K). NumPy, not compiled: a few dozen
    matrix products once per key (numba took 3.8 CPU s to compile it on a process's first run)."""
    size, width = one_step.shape[0], readout_rows.shape[0]
    powers = np.empty((max(per_anchor, anchor_count) + 1, size, size))
    # E^b = E^(b // 2) E^(b - b // 2), then the same for (E^B)^a: products of depth log2
    powers[0], powers[1] = np.eye(size), one_step
    for b in range(2, per_anchor + 1):
        powers[b] = np.dot(powers[b // 2], powers[b - b // 2])
    for b in range(per_anchor):
        readout[:, b * width:(b + 1) * width] = np.dot(readout_rows, powers[b]).T
    powers[1] = powers[per_anchor]
    for a in range(2, anchor_count):
        powers[a] = np.dot(powers[a // 2], powers[a - a // 2])
    for a in range(anchor_count):
        anchors[:, a * size:(a + 1) * size] = powers[a].T
    term = readout_rows.copy()  # R A^k / k!
    with np.errstate(over="ignore", invalid="ignore"):  # a diverging scene's terms: inf, reported by the run's check
        for k in range(taylor.shape[1] // width):
            if k:
                term = np.dot(term, matrix) / k
            taylor[:, k * width:(k + 1) * width] = term.T
