"""The steady state of a drill with wave rods: blows run until the per-blow figures settle.

A wave rod's state is the waves in flight (a history over each transit time), not a state vector a period
map could shoot on (models.steady.regimes). Its steady state is reached by running blows: the run goes on
until the advance per blow and the energy per blow reaching the rock change by less than
:data:`TOLERANCE` (relative) between consecutive blows for :data:`SETTLED_CHANGES` blows running (or, a drill
whose blows alternate, between each blow and the blow two before: settled with a period of 2 blows), or until
the scene's ``solver.end_time_s`` (the cap, checked by the run budget before the run). The exact formulation
stops at the blow start where the figures settled (:class:`_SettlingStepper`), or where they would settle only
far beyond the cap (:func:`projected_settling`: not settled, stopped early); another formulation runs to the cap and
the settled blows are read from its run. The exact formulation's figures are the
stepper's own at each blow start (the bottom by the rock law's return map to the bit there); read from the
run's samples (SimulationResult.bottom_at) they agree to about 1e-8 of the advance per blow.

The metrics are those of the settled blows: the run's metrics window is moved to them (``transient_blows``
the first settled blow, whole blocks of at most the scene's ``block_blows``, whole periods, to the run's last
blow). The
regime is ``settled`` with the blows run and the last change; where the cap is reached first it is ``no
periodic orbit found``, the metrics those of the scene's own window of the run, with the last change in the
note.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from ..definition.sections import Metrics
from ..evaluation.results import SimulationResult
from ..evaluation.rod_outputs import rock_energy_per_blow_j
from ..evaluation.run_record import Regime, SteadyStateRecord
from ..solvers.simulation import Simulation
from ..solvers.time_run import time_run
from ..waves.exact_waves import BLAS
from ..waves.exact_waves import result as wave_result
from ..waves.stepping import Stepper
from .section import drift_problem

TOLERANCE = 1e-6  # relative change between consecutive blows of the advance and the rock's energy per blow
SETTLED_CHANGES = 3  # consecutive blows whose change is below TOLERANCE
MAX_PERIOD_BLOWS = 2  # a drill whose blows alternate: each blow against the blow two before
# a run that will not settle within its cap is stopped early (:func:`projected_settling`): once three windows of
# WINDOW_BLOWS blows follow the scene's transient blows (:func:`projection_start`), when the changes, falling at their
# rate over those windows, would reach TOLERANCE only beyond MARGIN times the cap (docs/hole.md: the 30 m hole's
# projections, `python benchmarks/bench_hole.py --projections`)
PROJECTION_WINDOW_BLOWS = 10
PROJECTION_MARGIN = 2.0


@dataclass(frozen=True)
class Settling:
    """What the run of blows found: ``settled`` (with a period of ``period_blows``), the ``blows`` run, the first
    settled blow, the largest relative change over the last :data:`SETTLED_CHANGES` blows (NaN: too few blows;
    of the period that came nearest to settling where none settled)."""

    settled: bool
    blows: int
    first_settled_blow: int
    last_change: float
    period_blows: int = 1


def relative_changes(advance_m: np.ndarray, energy_j: np.ndarray, period: int = 1) -> np.ndarray:
    """Per pair of blows ``period`` apart, the larger relative change of the advance and of the rock's energy."""
    advance_m, energy_j = np.asarray(advance_m, dtype=float), np.asarray(energy_j, dtype=float)

    def change(values: np.ndarray) -> np.ndarray:  # none where the figure repeats exactly (a drill at rest too)
        step = np.abs(values[period:] - values[:-period]) if len(values) > period else np.zeros(0)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(step == 0.0, 0.0, step / np.abs(values[period:]))

    return np.maximum(change(advance_m), change(energy_j))


def settling(changes: np.ndarray, blows: int, period: int = 1) -> Settling:
    """The settled blows of a run of ``blows`` blows with these ``changes`` of blows ``period`` apart (change i:
    blow i to i + period; the first blow may be left out, the changes then end at the last blow)."""
    changes = np.asarray(changes, dtype=float)
    last = float(np.max(changes[-SETTLED_CHANGES:])) if len(changes) >= SETTLED_CHANGES else float("nan")
    above = np.flatnonzero(~(changes < TOLERANCE))
    below = len(changes) - (above[-1] + 1 if len(above) else 0)  # the trailing changes below the tolerance
    settled = below >= SETTLED_CHANGES + period - 1
    return Settling(settled, blows, blows - below - period if settled else blows, last, period)


def settled_of(advance_m: np.ndarray, energy_j: np.ndarray, blows: int) -> Settling:
    """The shortest period up to :data:`MAX_PERIOD_BLOWS` whose blows have settled, else the period that came
    nearest (its last change the smallest)."""
    found = [settling(relative_changes(advance_m, energy_j, n), blows, n) for n in range(1, MAX_PERIOD_BLOWS + 1)]
    return next((f for f in found if f.settled), None) or \
        min(found, key=lambda f: (np.nan_to_num(f.last_change, nan=np.inf), f.period_blows))


def projection_start(metrics: Metrics) -> int:
    """The first blow at which a run may be stopped as one that will not settle: the scene's transient blows and
    three windows of PROJECTION_WINDOW_BLOWS after them (at least a block of its metrics)."""
    return metrics.transient_blows + max(3 * PROJECTION_WINDOW_BLOWS, metrics.block_blows)


def projected_settling(changes: np.ndarray, blows: int) -> float:
    """The blow at which ``changes`` would fall below TOLERANCE at the geometric rate r of their largest value per
    window over the last three windows (W = PROJECTION_WINDOW_BLOWS): blows + log(TOL / m_last) / log(r),
    r = (m_last / m_first)^(1 / 2W); ``blows`` when they are below already, inf when they do not fall."""
    window = PROJECTION_WINDOW_BLOWS
    changes = np.asarray(changes, dtype=float)
    if len(changes) < 3 * window:
        return float("nan")
    first, last = float(np.max(changes[-3 * window:-2 * window])), float(np.max(changes[-window:]))
    if last < TOLERANCE:
        return float(blows)
    if not 0.0 < last < first:
        return float("inf")
    rate = (last / first) ** (1.0 / (2 * window))
    return blows + float(np.log(TOLERANCE / last) / np.log(rate))


def earliest_settling(advance_m: np.ndarray, energy_j: np.ndarray, blows: int) -> float:
    """The earliest :func:`projected_settling` over the periods up to MAX_PERIOD_BLOWS (NaN: too few blows)."""
    projected = [projected_settling(relative_changes(advance_m, energy_j, n), blows)
                 for n in range(1, MAX_PERIOD_BLOWS + 1)]
    return min((p for p in projected if not np.isnan(p)), default=float("nan"))


def per_blow(result: SimulationResult) -> tuple[np.ndarray, np.ndarray]:
    """(advance, rock's energy) of every whole blow of a run."""
    period = result.scene.impact.period_s
    blows = int(np.floor(result.time_s[-1] / period + 1e-9))
    advance = np.diff(result.bottom_at(np.arange(blows + 1) * period))
    return advance, rock_energy_per_blow_j(result)[:blows]


class _Watch:
    """The exact formulation's stop (:class:`_SettlingStepper`): at each blow start, the bottom
    and the rock's work of the blow just done; True once the changes have settled, or once they would settle only
    beyond PROJECTION_MARGIN times the cap (``projected``: the blow they would, inf: never)."""

    def __init__(self, simulation: Simulation) -> None:
        self.law, self.blows = simulation.rock, 0
        self.cap_blows = int(np.floor(simulation.settings.end_time_s / simulation.impact.period_s + 1e-9))
        self.start_blows = projection_start(simulation.scene.metrics)
        self.found: Settling | None = None  # where it stopped the run
        self.projected: float | None = None  # where it stopped a run that would not settle within its cap
        self.bottoms: list[float] = []
        self.energy: list[float] = []

    def __call__(self, stepper) -> bool:
        blows = len(stepper.statistics.rock_work_j)
        if blows == self.blows:  # this blow start was asked already
            return False
        self.blows, layout, w = blows, stepper.layout, stepper.w
        state = tuple(float(v) for v in w[layout.rock:layout.rock + layout.rock_states])
        self.bottoms.append(self.law.return_map(float(w[stepper.chain.bit_body]), state)[self.law.bottom_index])
        self.energy.append(stepper.statistics.rock_work_j[-1])
        found = settled_of(np.diff(self.bottoms), self.energy[1:], blows)
        self.found = found if found.settled else None
        if found.settled or blows < self.start_blows or blows >= self.cap_blows:
            return found.settled
        projected = earliest_settling(np.diff(self.bottoms), self.energy[1:], blows)
        if projected > PROJECTION_MARGIN * self.cap_blows:
            self.projected = projected
            return True
        return False


class _SettlingStepper(Stepper):
    """The exact formulation's stepper (models.waves.stepping) that asks ``stop`` at each blow start, the blows
    before it done, and ends the run there (its last sample at that instant) when it answers True."""

    def __init__(self, simulation: Simulation, stop: Callable[[Stepper], bool]) -> None:
        super().__init__(simulation, simulation.settings.wave_step_s, simulation.settings.sample_interval_s)
        self.stop = stop

    def advance(self) -> None:
        k = self.step_index
        if k and k % self.period_steps == 0 and self.stop(self):  # (a blow start is never a quiet step)
            self.steps = k
            if k % self.sample_every and not self.caught_at_end:
                self._record(k * self.step_s, self.w, self.key(), kept=False)
            return
        super().advance()


def _exact_run(simulation: Simulation, watch: _Watch, progress: Callable[[float], None] | None) -> SimulationResult:
    """The exact formulation's run of a scene with wave rods (models.waves.exact_waves), ended by ``watch``."""
    start = time.process_time()
    with BLAS.limit(limits=1, user_api="blas"):  # small matrices: threads cost more than they save
        stepper = _SettlingStepper(simulation, watch)
        stepper.run()
    if progress is not None:
        progress(stepper.steps * stepper.step_s)
    return wave_result(stepper, "exact", time.process_time() - start)


def settled_run(simulation: Simulation, progress: Callable[[float], None] | None = None) -> SimulationResult:
    """The steady state of a scene with wave rods (module doc), its record in the result's ``steady_state``."""
    start = time.process_time()
    problem = drift_problem(simulation)
    if problem:
        result = time_run(simulation, progress)
        result.steady_state = SteadyStateRecord("periodic", Regime.REFUSED, note=problem)
        return result
    watch = _Watch(simulation)
    if simulation.settings.formulation == "exact" and not simulation.scene.extensions:
        result = _exact_run(simulation, watch, progress)
    else:
        result = time_run(simulation, progress)
    found = watch.found or settled_of(*per_blow(result), int(np.floor(result.time_s[-1] / simulation.impact.period_s
                                                                      + 1e-9)))
    cap = simulation.settings.end_time_s
    if found.settled:
        result.simulation = settled_window(simulation, found)
        period = "" if found.period_blows == 1 else f" with a period of {found.period_blows} blows"
        note = (f"settled{period} after {found.blows} blows: the advance and the rock's energy per blow change by at "
                f"most {found.last_change:.3g} (relative, against the blow {found.period_blows} before) over the last "
                f"{SETTLED_CHANGES} blows; metrics over blows "
                f"{result.simulation.scene.metrics.transient_blows}..{found.blows}")
        regime = Regime.SETTLED
    elif watch.projected is not None:
        result.simulation = settled_window(simulation, replace(found, period_blows=1, first_settled_blow=min(
            found.blows, simulation.scene.metrics.transient_blows)))
        when = (f"would not fall below {TOLERANCE:g}" if np.isinf(watch.projected) else
                f"would fall below {TOLERANCE:g} only after about {watch.projected:.0f} blows, beyond "
                f"{PROJECTION_MARGIN:g} times the cap of {watch.cap_blows} blows (solver.end_time_s {cap:g} s)")
        note = (f"not settled, stopped after {found.blows} blows: the changes of the advance and the rock's energy per "
                f"blow (the last {found.last_change:.3g} against the blow {found.period_blows} before), at their rate "
                f"over the last {3 * PROJECTION_WINDOW_BLOWS} blows, {when}; "
                f"the time run's metrics over blows {result.simulation.scene.metrics.transient_blows}..{found.blows}")
        regime = Regime.NOT_FOUND
    else:
        note = (f"not settled within the cap of {found.blows} blows (solver.end_time_s {cap:g} s): the last change "
                f"of the advance or the rock's energy per blow (against the blow {found.period_blows} before) is "
                f"{found.last_change:.3g}, above {TOLERANCE:g}; "
                "the time run's metrics")
        regime = Regime.NOT_FOUND
    result.cpu_time_s = time.process_time() - start
    result.steady_state = SteadyStateRecord("periodic", regime, note=note, cpu_time_s=result.cpu_time_s,
                                            blows=found.blows, last_change=found.last_change,
                                            settled_period_blows=found.period_blows if found.settled else None)
    return result


def settled_window(simulation: Simulation, found: Settling) -> Simulation:
    """``simulation`` ending at the run's last blow, its metrics' window the settled blows: whole blocks of at
    most its ``block_blows`` that end at the last blow."""
    scene = simulation.scene
    settled, period = found.blows - found.first_settled_blow, found.period_blows
    block = period * max(1, min(scene.metrics.block_blows, settled) // period)  # whole periods
    first = found.blows - (settled // block) * block
    end_s = int(found.blows) * simulation.impact.period_s
    scene = scene.model_copy(update={
        "solver": scene.solver.model_copy(update={"end_time_s": end_s}),
        "metrics": Metrics.model_construct(transient_blows=int(first), block_blows=int(block))})
    return replace(simulation, scene=scene, settings=replace(simulation.settings, end_time_s=end_s))
