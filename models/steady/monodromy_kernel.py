"""Compiled monodromy matrix of an exact run (models.steady.exact_map): the ordered product

    dw/dw0 = ... S_j expm(A_k dt_k) ... S_1 expm(A_1 dt_1)

over the run's pieces (one operator key each) and switches, applied to the columns dw0/dy0, from the exact
solver's cached operators (models.solvers.exact_model.Operators: the Taylor matrices A^k / k!, the anchors
expm(A a B h), the read-outs expm(A b h)) and its exits and resets (the saltation matrix of a switch,
S = M + (f+ - M f-) c^T / (c . f-), f- = A_old w-, f+ = A_new w+, applied without forming S). The same
arithmetic as the solver's own propagation, in numba: a Python loop over the pieces cost about 0.3 ms per
blow, more than the run itself.
"""

from __future__ import annotations

import numpy as np
from numba import njit

OK, NO_EXIT = 0, 1  # kernel status: NO_EXIT where a switch's modes have no exit between them


@njit(cache=True)
def _copy(source: np.ndarray, target: np.ndarray) -> None:
    """target = source, element by element: a slice assignment compiles numba's shape-mismatch message, with its
    string formatting, for a check these equal shapes never fail (the kernel's compilation 7.2 -> 2.8 s without it:
    benchmarks/bench_compile.py)."""
    for r in range(source.shape[0]):
        for c in range(source.shape[1]):
            target[r, c] = source[r, c]


@njit(cache=True)
def _left_multiply(matrix: np.ndarray, transposed: bool, product: np.ndarray, out: np.ndarray) -> None:
    """out = M product (``transposed``: ``matrix`` holds M^T); the innermost loop runs along product's rows."""
    size, columns = product.shape
    out[:] = 0.0
    for k in range(size):
        for r in range(size):
            factor = matrix[k, r] if transposed else matrix[r, k]
            for c in range(columns):
                out[r, c] += factor * product[k, c]


@njit(cache=True)
def _propagate(key: int, length_s: float, taylor: np.ndarray, anchors: np.ndarray, readout: np.ndarray,
               step_s: float, width: int, anchor_count: int, per_anchor: int, product: np.ndarray,
               scratch: np.ndarray) -> None:
    """product <- expm(A t) product, t = (q A B + a B + b) h + s (s < h): (E^(A B))^q by squaring, then
    E^b and E^(a B) from the cached blocks, then sum_k s^k A^k / k!."""
    size = product.shape[0]
    steps = int(length_s // step_s)
    rest = length_s - steps * step_s
    if rest < 0.0:
        steps, rest = steps - 1, rest + step_s
    whole = steps // (anchor_count * per_anchor)
    part = steps - whole * anchor_count * per_anchor
    anchor, power = part // per_anchor, part % per_anchor
    if whole:  # E^(A B) = E^((A - 1) B) E^B, its binary powers
        block = np.empty((size, size))
        last = anchors[key, :, (anchor_count - 1) * size:anchor_count * size]
        first = anchors[key, :, size:2 * size]
        for r in range(size):
            for c in range(size):
                total = 0.0
                for k in range(size):
                    total += last[k, r] * first[c, k]
                block[r, c] = total
        squared = np.empty((size, size))
        while whole:
            if whole & 1:
                _left_multiply(block, False, product, scratch)
                _copy(scratch, product)
            whole >>= 1
            if whole:
                _left_multiply(block, False, block, squared)
                _copy(squared, block)
    if power:
        _left_multiply(readout[key, :, power * width:power * width + size], True, product, scratch)
        _copy(scratch, product)
    if anchor:
        _left_multiply(anchors[key, :, anchor * size:(anchor + 1) * size], True, product, scratch)
        _copy(scratch, product)
    order = taylor.shape[2] // width - 1
    series = np.zeros((size, size))  # sum_k s^k A^k / k! (stored transposed, as the Taylor matrices)
    power_of_rest = 1.0
    for k in range(order + 1):
        for j in range(size):
            for r in range(size):
                series[j, r] += power_of_rest * taylor[key, j, k * width + r]
        power_of_rest *= rest
    _left_multiply(series, True, product, scratch)
    _copy(scratch, product)


@njit(cache=True)
def monodromy(columns: np.ndarray, time_s: np.ndarray, rows: np.ndarray, keys: np.ndarray, key_modes: np.ndarray,
              taylor: np.ndarray, anchors: np.ndarray, readout: np.ndarray, exit_counts: np.ndarray,
              next_modes: np.ndarray, reset_counts: np.ndarray, reset_targets: np.ndarray, reset_rows: np.ndarray,
              monotone: int, step_s: float, anchor_count: int, per_anchor: int, product: np.ndarray) -> int:
    """product = dw/dw0 columns over the run (module doc); OK, or NO_EXIT."""
    size = columns.shape[0]
    width = readout.shape[2] // per_anchor
    _copy(columns, product)
    scratch = np.empty_like(product)
    before, after, jump, c_product = np.empty(size), np.empty(size), np.empty(size), np.empty(product.shape[1])
    last = time_s.shape[0] - 1
    start = 0
    for i in range(last + 1):
        if i < last and time_s[i + 1] - time_s[i] > 0.0:
            continue  # inside a piece
        if i > start:
            _propagate(keys[start], time_s[i] - time_s[start], taylor, anchors, readout, step_s, width,
                       anchor_count, per_anchor, product, scratch)
        if i < last and key_modes[keys[i]] != key_modes[keys[i + 1]]:  # a switch
            old, new = keys[i], keys[i + 1]
            e = -1
            for candidate in range(exit_counts[old]):
                if next_modes[old, candidate] == key_modes[new]:
                    e = candidate
                    break
            if e < 0:
                return NO_EXIT
            w_before, w_after = rows[i, :size], rows[i + 1, :size]
            # f- = A_old w-, f+ = A_new w+ (A = the first Taylor matrix, stored transposed)
            for r in range(size):
                total_before, total_after = 0.0, 0.0
                for k in range(size):
                    total_before += taylor[old, k, width + r] * w_before[k]
                    total_after += taylor[new, k, width + r] * w_after[k]
                before[r], after[r] = total_before, total_after
            # M f-: the reset rows replace their targets (the bottom's kept where the reset would lower it)
            for r in range(size):
                jump[r] = after[r] - before[r]
            c_before = 0.0
            for k in range(size):
                c_before += readout[old, k, size + 2 + e] * before[k]
            for c in range(product.shape[1]):
                total = 0.0
                for k in range(size):
                    total += readout[old, k, size + 2 + e] * product[k, c]
                c_product[c] = total
            _copy(product, scratch)
            for j in range(reset_counts[old, e]):
                target = reset_targets[old, e, j]
                row = reset_rows[old, e, j]
                if target == monotone:
                    raised = 0.0
                    for k in range(size):
                        raised += row[k] * w_before[k]
                    if raised < w_before[target]:
                        continue  # the bottom keeps its row
                reset_before = 0.0
                for k in range(size):
                    reset_before += row[k] * before[k]
                jump[target] = after[target] - reset_before
                for c in range(product.shape[1]):
                    total = 0.0
                    for k in range(size):
                        total += row[k] * product[k, c]
                    scratch[target, c] = total
            for r in range(size):
                for c in range(product.shape[1]):
                    product[r, c] = scratch[r, c] + jump[r] / c_before * c_product[c]
        start = i + 1
    return OK
