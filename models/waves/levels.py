"""A key's propagators over dyadic fractions of the wave step, and the first switch located on them.

For a key (models.waves.system) and the step h, level j holds E_j = expm(A h / 2^j), j = 0 .. LEVELS:
the levels with ||A|| h / 2^j <= 1/2 each from its own matrix exponential (cheap there: a low-order Pade
approximant), the coarser ones by squaring the first of those (E_{j-1} = E_j^2, as a scaling and
squaring exponential does). The first switch in a piece (the first exit function to cross zero in its
direction) is found greedily on this grid: from the piece's start, take the largest level step that
keeps every exit function on its side and whose ends' slopes show no maximum between them (a crossing
and its return), down to the finest level; the switch lies within one finest step (h / 2^LEVELS, 5e-20 s
at a step of 2 us) after the point reached. No matrix exponential per trial point.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.linalg import expm

from .system import Key

LEVELS = 48


class KeyLevels:
    """The levels of one key (module doc)."""

    def __init__(self, matrix: np.ndarray, step_s: float) -> None:
        self.step_s = step_s
        norm = np.linalg.norm(matrix, 1) * step_s
        first = min(LEVELS, max(0, math.ceil(math.log2(max(norm / 0.5, 1.0)))))
        steps = {j: expm(matrix * (step_s / 2**j)) for j in range(first, LEVELS + 1)}
        for j in range(first, 0, -1):
            steps[j - 1] = steps[j] @ steps[j]
        self.steps = [steps[j] for j in range(LEVELS + 1)]

    def propagate(self, w: np.ndarray, span_s: float) -> np.ndarray:
        """w after ``span_s`` (<= h): the levels of the binary digits of span / h."""
        return self.propagate_units(w, round(float(span_s) / self.step_s * 2**LEVELS))

    def first_switch(self, rows: np.ndarray, slopes: np.ndarray, w0: np.ndarray, span_s: float,
                     candidates: np.ndarray) -> tuple[float, int] | None:
        """(time into the piece, exit) of the first crossing of ``rows`` . w > 0 in (0, span] among the
        exits ``candidates`` (a mask: those on their crossed side at the piece's end or with a maximum
        inside), to one finest step (module doc); None when there is none (a maximum that stays below)."""
        rows, slopes = rows[candidates], slopes[candidates]
        exits = np.flatnonzero(candidates)
        span = round(float(span_s) / self.step_s * 2**LEVELS)  # in finest steps: exact integer arithmetic
        w = self.steps[LEVELS] @ w0
        crossed = rows @ w
        if np.any(crossed > 0.0):  # on its crossed side already at the start: a switch there
            return self.step_s / 2**LEVELS, int(exits[np.argmax(crossed)])
        reached = 1
        while reached < span:  # bisection on the grid; a maximum that stays below zero restarts after it
            limit, point = span, w
            for j in range(1, LEVELS + 1):
                length = 1 << (LEVELS - j)
                while reached + length <= limit:
                    trial = self.steps[j] @ point
                    if np.any(rows @ trial > 0.0) or np.any((slopes @ point > 0.0) & (slopes @ trial < 0.0)
                                                            & (rows @ point < 0.0)):
                        limit = reached + length
                        break
                    point, reached = trial, reached + length
            ahead = rows @ (self.steps[LEVELS] @ point)
            if np.any(ahead > 0.0):
                return (reached + 1) * self.step_s / 2**LEVELS, int(exits[np.argmax(ahead)])
            if limit >= span:
                return None
            w = self.propagate_units(w0, limit)  # past the maximum: search on from there
            reached = limit
        return None

    def propagate_units(self, w: np.ndarray, units: int) -> np.ndarray:
        """w after ``units`` finest steps."""
        for j in range(LEVELS + 1):
            if units >> (LEVELS - j) & 1:
                w = self.steps[j] @ w
        return w


def key_levels(stepper, key: Key) -> KeyLevels:
    """The levels of ``key`` on the stepper's step, built on first use."""
    if "levels" not in key.cache:
        key.cache["levels"] = KeyLevels(key.matrix, stepper.step_s)
    return key.cache["levels"]
