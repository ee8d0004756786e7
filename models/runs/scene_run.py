"""The run a scene asks for, the one path from a prepared scene to its :class:`Result`: its time run, or
with ``solver.steady_state: periodic`` its steady state.

A periodic run finds the regime (models.steady.regimes). With a stable orbit of n blows, the result is the
scene's own formulation run over that orbit, from its section state for n blow periods, with the metrics'
window the whole orbit (no transient): every metric a time run gives (penetration rate, peaks, RMS, the
energy account), of the settled drill, without the transient a time run still carries after its
``transient_blows``. Where no stable orbit is found, the result is the time run, as with ``steady_state:
time``, and says why; a scene that cannot have an orbit relative to the bottom (a drill held to ground, wave
rods, an extension's coordinates the section cannot hold) is the time run too, its regime ``refused`` with
the reason.

The result's ``steady_state`` (models.evaluation.run_record.SteadyStateRecord) holds the regime, the orbit
(period, Floquet multipliers as complex numbers, event sequence, section state with its labels, Newton's
iterations, the Jacobian's source, the residual of the run over it), the unstable orbits met and the note.
"""

from __future__ import annotations

import contextlib
import time
import warnings
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np

from ..definition.own_code import blame
from ..definition.validation import InputError
from ..evaluation.results import SimulationResult
from ..evaluation.run_record import OrbitRecord, Regime, StartRecord, SteadyStateRecord
from ..evaluation.run_result import Result
from ..evaluation.stability import SimulationFailed
from ..solvers.simulation import Simulation
from ..solvers.time_run import time_run
from ..steady.section import section_of
from ..steady.shooting import Orbit, scales
from ..steady.start_check import coexisting_note
from ..steady.steady_state import NONE_FOUND, SteadyState, SteadyStateUnavailable

OrbitGuess = tuple[np.ndarray, int]  # a section state and the orbit's blows


def run(simulation: Simulation, progress: Callable[[float], None] | None = None, *, guess: OrbitGuess | None = None,
        cold_newton: bool = True, solution_file: Path | None = None, source: str = "", start_check: bool = True
        ) -> Result:
    """The run ``simulation``'s scene asks for (module doc), as ``rpdrill.Result``. ``progress(t)`` as simulated
    time advances. ``guess``: the section state and period of an orbit to start Newton from (a neighbour's,
    predicted: models.steady.continuation); without one, ``cold_newton`` False goes straight to the time run
    and the period it repeats (a neighbour had no periodic orbit: models.steady.regimes, step 2).
    ``solution_file``: a time run of the Exudyn formulation writes Exudyn's coordinates solution file there.
    ``start_check``: with an orbit, where the drill goes from the scene's start too (models.steady.start_check:
    the record's ``start``, and a note where it is another attractor); a scan that reads only its curve's optima
    leaves it out.
    ``source``: where the scene came from, as the result records it. The warnings shown while it runs (as
    the caller's filters let them through) are also kept in the result's ``warnings``. An error raised in the
    code of one's own the scene names (an extension, a rock law) is a SimulationFailed naming it and the user's
    line (models.definition.own_code.blame)."""
    with kept_warnings() as kept:
        try:
            raw = _raw(simulation, progress, guess, cold_newton, solution_file, start_check)
        except Exception as error:
            why = blame(error, simulation.scene)  # the user's code raised it: a failed run, not rpdrill's error
            if why is None or isinstance(error, (InputError, SimulationFailed)):
                raise
            raise SimulationFailed(f"scene '{simulation.name}': {why}") from None
    return Result(simulation.scene, raw, source=source, code=simulation.code_records(),
                  warnings=tuple(dict.fromkeys(kept)))


@contextlib.contextmanager
def kept_warnings() -> Iterator[list[str]]:
    """The text of every warning shown inside the block, in order; each is shown as before (``warnings.showwarning``
    wrapped for the block's duration only: the caller's filters and display are left as they were)."""
    kept: list[str] = []
    shown = warnings.showwarning

    def keep(message: Warning | str, category: type[Warning], filename: str, lineno: int, file: Any = None,
             line: str | None = None) -> None:
        kept.append(str(message))
        shown(message, category, filename, lineno, file, line)

    warnings.showwarning = keep
    try:
        yield kept
    finally:
        warnings.showwarning = shown


def _raw(simulation: Simulation, progress: Callable[[float], None] | None, guess: OrbitGuess | None,
         cold_newton: bool, solution_file: Path | None, start_check: bool) -> SimulationResult:
    if simulation.scene.solver.steady_state != "periodic":
        return time_run(simulation, progress, solution_file)
    if simulation.dynamic_chain.waves:  # the waves in flight: blows run until they settle
        from ..steady.wave_settling import settled_run
        return settled_run(simulation, progress)
    from ..solvers.exact_model import BLAS  # numba's kernels: loaded for a periodic run only
    from ..steady.regimes import RegimeFinder

    start = time.process_time()
    finder = None
    time_run_result = None
    regime = Regime.NOT_FOUND
    try:
        finder = RegimeFinder(simulation)
        with BLAS.limit(limits=1, user_api="blas"):  # small matrices: threads cost more than they give
            state = finder.find(*(guess or (None, 1))) if guess is not None or cold_newton else \
                SteadyState(NONE_FOUND, None)
            if state.orbit is None:  # step 2: the period its time run repeats (models.steady.regimes)
                time_run_result = time_run(finder.simulation, progress)  # (an extension's coordinates recorded)
                state = finder.settled(time_run_result, state)
        if state.orbit is not None and start_check:  # where the drill goes from its start (models.steady.start_check)
            state = finder.check_start(state)
    except SteadyStateUnavailable as why:
        state, regime = SteadyState(NONE_FOUND, None, note=str(why)), Regime.REFUSED
    orbit = None
    if state.orbit is not None and finder is not None:
        result, end = finder.result(state.orbit, start)
        if progress is not None:
            progress(simulation.settings.end_time_s)
        labels = section_of(finder.simulation).state_labels(finder.simulation)
        orbit = orbit_record(state.orbit, labels, orbit_residual(finder.simulation, state.orbit, end))
        regime = Regime.PERIODIC
    else:
        result = time_run_result or time_run(simulation, progress)
    result.cpu_time_s = time.process_time() - start
    unstable = tuple(orbit_record(o) for o in state.unstable)
    note = state.note if orbit is None else "; ".join(
        f"unstable period-{o.period_blows} orbit: |mu|max {o.floquet_max_abs:.4g}, advance per blow "
        f"{o.advance_per_blow_m:.6g} m (not the drill's rate)" for o in unstable)
    start = None
    if orbit is not None and state.start is not None:  # models.steady.start_check
        check = state.start
        start = StartRecord(check.regime, check.reaches_orbit, check.blows, check.advance_per_blow_m)
        note = "; ".join(part for part in (coexisting_note(check, state.orbit), note) if part)
    result.steady_state = SteadyStateRecord("periodic", regime, orbit, unstable, start, note=note,
                                            map_runs=state.map_runs, cpu_time_s=state.cpu_time_s)
    return result


def orbit_record(orbit: Orbit, labels: tuple[str, ...] = (), residual: float = float("nan")) -> OrbitRecord:
    """An orbit of the shooting (models.steady.shooting.Orbit) as a run reports it."""
    return OrbitRecord(orbit.periods, tuple(complex(mu) for mu in orbit.multipliers), orbit.advance_per_blow_m,
                       orbit.event_sequence, orbit.state.copy(), tuple(labels), orbit.iterations, orbit.jacobian,
                       residual)


def orbit_residual(simulation: Simulation, orbit: Orbit, end: np.ndarray) -> float:
    """max_i |z_i(end) - z_i(start)| / s_i of the run over the orbit ending in ``end`` (models.steady.shooting
    .scales): how closely the run from the orbit's state returns to it."""
    section = section_of(simulation)
    start = section.reduce(orbit.state)[0]
    return float(np.max(np.abs(section.reduce(end)[0] - start) / scales(simulation, section, start)))
