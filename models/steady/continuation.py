"""Continuation along a scan axis: each orbit's Newton starts from its neighbours', and what changes from
one orbit to the next is read as a bifurcation.

Natural-parameter continuation with a secant predictor: the section state at the next axis value is
extrapolated linearly from the last two orbits of the same period (from the last one alone after a change
of period or a gap), z(p) = z_1 + (p - p_1) (z_1 - z_0) / (p_1 - p_0). Newton (models.steady.shooting)
corrects it in one or two steps where the branch is smooth. (A parabola through three orbits predicts no
better on the paper's frequency scan: the orbit's section state is only piecewise smooth in the frequency,
its median error 2.8e-3 of the coordinates' scales against 3.9e-3 for the line, at 1 Hz steps.)

Between two neighbouring orbits of a branch (:func:`changes`):

* ``period doubling``: a real multiplier crosses -1 (or the regime goes from period n to period 2n);
* ``fold``: a real multiplier crosses +1, or the branch ends (Newton finds no orbit past the last point:
  with natural continuation a fold shows as the end of the branch, the coexisting branch beyond it found
  by the other regimes or from the other end of the scan);
* ``torus``: a complex pair leaves the unit circle (Neimark-Sacker);
* ``grazing``: the orbit's event sequence changes (a contact that appears or vanishes);
* ``regime``: the attractor found changes (period n to m, or to no periodic orbit).

Coexisting orbits (hysteresis) show when the same axis is followed from both ends (:func:`hysteresis`):
where the two passes end on different orbits at one value, both are stable there. And where an orbit a pass
follows is not where the drill goes from the scene's start (models.steady.start_check: another orbit, or an
irregular response), the two coexist too (:func:`coexisting`).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field

import numpy as np

from ..evaluation.run_record import SteadyStateRecord
from .steady_state import NONE_FOUND

UNIT_CIRCLE_MARGIN = 1e-9  # |mu| within this of 1 counts as on the circle


@dataclass(frozen=True)
class BranchPoint:
    """One orbit of a continuation: the axis ``value``, the regime, the orbit's blows, advance per blow,
    section state, multipliers and event sequence (a run's steady state: :func:`branch_point`)."""

    value: float
    regime: str
    period_blows: int | None
    advance_per_blow_m: float
    state: np.ndarray | None
    multipliers: np.ndarray
    events: tuple[str, ...]
    start_regime: str = ""  # where the drill goes from the scene's start (models.steady.start_check; '': unchecked)
    start_reaches_orbit: bool | None = None

    @property
    def floquet_max_abs(self) -> float:
        return float(np.max(np.abs(self.multipliers))) if len(self.multipliers) else float("nan")


def branch_point(value: float, steady: SteadyStateRecord | None, advance_per_blow_m: float) -> BranchPoint:
    """A branch point from a run's steady state (None: the run failed)."""
    orbit = None if steady is None else steady.orbit
    if orbit is None:
        return BranchPoint(value, "" if steady is None else steady.regime_name, None, advance_per_blow_m, None,
                           np.array([], dtype=complex), ())
    start = steady.start
    return BranchPoint(value, steady.regime_name, orbit.period_blows, advance_per_blow_m, orbit.state,
                       np.array(orbit.multipliers, dtype=complex), orbit.event_sequence,
                       "" if start is None else start.regime, None if start is None else start.reaches_orbit)


@dataclass
class Continuation:
    """The orbits met so far along one axis, in order; :meth:`guess` predicts the next (module doc)."""

    points: list[BranchPoint] = field(default_factory=list)

    def guess(self, value: float) -> tuple[np.ndarray, int] | None:
        """(section state, blows) to start Newton from at ``value``, None without an orbit before."""
        if not self.points or self.points[-1].state is None:
            return None
        last = self.points[-1]
        if len(self.points) > 1:
            before = self.points[-2]
            if before.state is not None and before.period_blows == last.period_blows and before.value != last.value:
                slope = (last.state - before.state) / (last.value - before.value)
                return last.state + (value - last.value) * slope, int(last.period_blows)
        return last.state, int(last.period_blows)

    def add(self, point: BranchPoint) -> None:
        self.points.append(point)

    @property
    def cold_newton(self) -> bool:
        """Whether a point without a guess tries Newton from its own start: not after a neighbour where none
        was found (models.runs.scene_run.run)."""
        return not self.points or self.points[-1].regime != NONE_FOUND


@dataclass(frozen=True)
class Change:
    """A bifurcation or a change of regime between two neighbouring axis values (module doc)."""

    kind: str
    low: float
    high: float
    detail: str


def _real_near(multipliers: np.ndarray, sign: float) -> float:
    """The real multiplier nearest to ``sign`` (+1 or -1), NaN if none is real."""
    real = multipliers[np.abs(multipliers.imag) <= 1e-9 * np.maximum(1.0, np.abs(multipliers))].real
    return float(real[np.argmin(np.abs(real - sign))]) if len(real) else float("nan")


def _outside(value: float) -> bool:
    return abs(value) > 1.0 + UNIT_CIRCLE_MARGIN


def changes(points: list[BranchPoint]) -> list[Change]:
    """The bifurcations and changes of regime between neighbouring points of a branch (module doc)."""
    found = []
    for a, b in itertools.pairwise(points):
        span = (min(a.value, b.value), max(a.value, b.value))
        if a.regime != b.regime:
            kind = "period doubling" if (a.period_blows and b.period_blows and b.period_blows in (
                2 * a.period_blows, a.period_blows // 2)) else "regime"
            found.append(Change(kind, *span, f"{a.regime} -> {b.regime}"))
        if a.state is None or b.state is None or a.period_blows != b.period_blows:
            continue
        minus = _real_near(a.multipliers, -1.0), _real_near(b.multipliers, -1.0)
        plus = _real_near(a.multipliers, 1.0), _real_near(b.multipliers, 1.0)
        if all(np.isfinite(minus)) and _outside(minus[0]) != _outside(minus[1]):
            found.append(Change("period doubling", *span, f"multiplier {minus[0]:.4g} -> {minus[1]:.4g}"))
        if all(np.isfinite(plus)) and _outside(plus[0]) != _outside(plus[1]):
            found.append(Change("fold", *span, f"multiplier {plus[0]:.4g} -> {plus[1]:.4g}"))
        pairs = [max((abs(m) for m in p.multipliers if abs(m.imag) > 1e-9 * max(1.0, abs(m))), default=0.0)
                 for p in (a, b)]
        if _outside(pairs[0]) != _outside(pairs[1]):
            found.append(Change("torus", *span, f"complex pair |mu| {pairs[0]:.4g} -> {pairs[1]:.4g}"))
        if a.events and b.events and a.events != b.events:
            found.append(Change("grazing", *span, f"events {' '.join(a.events)} -> {' '.join(b.events)}"))
    return found


def hysteresis(forward: list[BranchPoint], backward: list[BranchPoint], relative: float = 1e-6) -> list[float]:
    """The axis values where a pass up and a pass down the axis both found a stable orbit and they differ
    (other blows, or advance per blow differing by more than ``relative``, or other section states):
    coexisting attractors. (Where one pass found none, its time run may still be settling: not counted.)"""
    down = {p.value: p for p in backward}
    both = [(p, down[p.value]) for p in forward if p.value in down and p.state is not None
            and down[p.value].state is not None]
    return [a.value for a, b in both if a.period_blows != b.period_blows
            or abs(a.advance_per_blow_m - b.advance_per_blow_m)
            > relative * max(abs(a.advance_per_blow_m), abs(b.advance_per_blow_m), 1e-12)
            or (a.period_blows == 1 and not np.allclose(a.state, b.state, rtol=1e-6, atol=1e-9))]


def coexisting(points: list[BranchPoint]) -> list[Change]:
    """The points of a pass whose orbit the drill does not reach from the scene's start (module doc): what the
    start reaches instead."""
    def reached(p: BranchPoint) -> str:
        if p.start_regime == "irregular":
            return "an irregular response (no period up to 6 blows)"
        return f"{'another' if p.start_regime == p.regime else 'a'} stable {p.start_regime} orbit"

    return [Change("coexisting", p.value, p.value, f"{p.regime} orbit of the pass; from the scene's start the drill "
                   f"reaches {reached(p)}") for p in points if p.state is not None and p.start_reaches_orbit is False]
