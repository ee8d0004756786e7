"""The run a scene asks for: its time run, or with ``solver.steady_state: periodic`` its steady state.

A periodic run finds the regime (models.steady.regimes). With a stable orbit of n blows, the result is the
scene's own formulation run over that orbit, from its section state for n blow periods, with the metrics'
window the whole orbit (no transient): every metric a time run gives (penetration rate, peaks, RMS, the
energy account), of the settled drill, without the transient a time run still carries after its
``transient_blows``. Where no stable orbit is found (or the scene cannot have one: a drill held to ground),
the result is the time run, as with ``steady_state: time``, and says why.

Every result's ``info`` then holds ``steady_state`` (what the scene asked for), ``regime`` (``period-1``,
``period-n``, ``no periodic orbit found``, or ``time run``), ``period_blows`` (n, or None),
``floquet_max_abs`` (max |mu| of the orbit; NaN without one), and with an orbit its ``floquet_multipliers``
([re, im] each), ``event_sequence`` (the modes entered over one orbit), ``orbit_state`` (its section state:
a neighbour's Newton guess; an Exudyn scene's extension coordinates last) and ``orbit_state_labels`` (a name
for each entry), ``newton_iterations``, ``map_runs``, ``jacobian``, ``start_regime`` (where the drill goes from the scene's
start: ``period-m`` or ``irregular``; models.steady.start_check) and ``start_reaches_orbit`` (whether that is
the orbit found), and
``steady_state_note`` (coexisting regimes where the start reaches another attractor, the unstable orbits met,
or why none was found). :func:`regime_columns` gives the first four as a results
table's columns.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from ..evaluation.results import SimulationResult
from ..solvers.simulation import Simulation
from ..solvers.solution_file import solve_with_solution
from .section import section_of
from .shooting import Orbit, scales
from .start_check import coexisting_note
from .steady_state import NONE_FOUND, SteadyState

OrbitGuess = tuple[np.ndarray, int]  # a section state and the orbit's blows

TIME_RUN = "time run"
REGIME_COLUMNS = ("steady_state", "regime", "period_blows", "floquet_max_abs")


def regime_columns(result: SimulationResult | None) -> dict[str, Any]:
    """The steady-state columns of a results table for one run (None: a failed run)."""
    info = {} if result is None else result.info
    return {"steady_state": info.get("steady_state", ""), "regime": info.get("regime", ""),
            "period_blows": info.get("period_blows"), "floquet_max_abs": info.get("floquet_max_abs", math.nan)}


def orbit_info(state: SteadyState) -> dict[str, Any]:
    """The run info of a regime (module doc)."""
    orbit = state.orbit
    info: dict[str, Any] = {"regime": state.regime, "period_blows": state.period_blows,
                            "floquet_max_abs": state.floquet_max_abs, "map_runs": state.map_runs,
                            "steady_state_cpu_time_s": state.cpu_time_s}
    if orbit is not None:
        info.update(floquet_multipliers=[[float(mu.real), float(mu.imag)] for mu in orbit.multipliers],
                    event_sequence=list(orbit.event_sequence), orbit_state=orbit.state.tolist(),
                    newton_iterations=orbit.iterations, jacobian=orbit.jacobian)
    unstable = "; ".join(f"unstable period-{o.periods} orbit: |mu|max {o.floquet_max_abs:.4g}, advance per blow "
                         f"{o.advance_per_blow_m:.6g} m (not the drill's rate)" for o in state.unstable)
    info["steady_state_note"] = state.note if orbit is None else unstable
    if orbit is not None and state.start is not None:  # models.steady.start_check
        info["start_regime"], info["start_reaches_orbit"] = state.start.regime, state.start.reaches_orbit
        info["steady_state_note"] = "; ".join(part for part in (coexisting_note(state.start, orbit), unstable) if part)
    return info


def run_scene(simulation: Simulation, guess: OrbitGuess | None = None,
              progress: Callable[[float], None] | None = None, cold_newton: bool = True,
              solution: Path | None = None, start_check: bool = True) -> SimulationResult:
    """The run ``simulation``'s scene asks for (module doc). ``guess``: the section state and period of
    an orbit to start Newton from (a neighbour's, predicted: models.steady.continuation); without one,
    ``cold_newton`` False goes straight to the time run and the period it repeats (a neighbour had no
    periodic orbit: models.steady.regimes, step 2). ``solution``: a time run of the Exudyn formulation
    writes Exudyn's coordinates solution file there (models.solvers.solution_file). ``start_check``: with an
    orbit, where the drill goes from the scene's start too (models.steady.start_check: ``start_regime``, and a
    note where it is another attractor); a scan that reads only its curve's optima leaves it out."""
    if simulation.scene.solver.steady_state != "periodic":
        result = solve_with_solution(simulation, progress, solution)
        result.info.update(steady_state="time", regime=TIME_RUN, period_blows=None, floquet_max_abs=math.nan)
        return result
    from ..solvers.exact_model import BLAS  # numba's kernels: loaded for a periodic run only
    from .regimes import RegimeFinder, SteadyStateUnavailable

    start = time.process_time()
    finder = None
    time_run = None
    try:
        finder = RegimeFinder(simulation)
        with BLAS.limit(limits=1, user_api="blas"):  # small matrices: threads cost more than they give
            state = finder.find(*(guess or (None, 1))) if guess is not None or cold_newton else \
                SteadyState(NONE_FOUND, None)
            if state.orbit is None:  # step 2: the period its time run repeats (models.steady.regimes)
                time_run = finder.simulation.solve(progress)  # (an extension's coordinates recorded)
                state = finder.settled(time_run, state)
        if state.orbit is not None and start_check:  # where the drill goes from its start (models.steady.start_check)
            state = finder.check_start(state)
    except SteadyStateUnavailable as why:
        state = SteadyState(NONE_FOUND, None, note=str(why))
    if state.orbit is not None and finder is not None:
        result, end = finder.result(state.orbit, start)
        if progress is not None:
            progress(simulation.settings.end_time_s)
    if state.orbit is None:
        result = time_run or simulation.solve(progress)
    result.cpu_time_s = time.process_time() - start
    result.info.update(steady_state="periodic", **orbit_info(state))
    if state.orbit is not None:
        result.info["orbit_residual"] = orbit_residual(finder.simulation, state.orbit, end)
        result.info["orbit_state_labels"] = section_of(finder.simulation).state_labels(finder.simulation)
    return result


def orbit_residual(simulation: Simulation, orbit: Orbit, end: np.ndarray) -> float:
    """max_i |z_i(end) - z_i(start)| / s_i of the run over the orbit ending in ``end`` (models.steady.shooting
    .scales): how closely the run from the orbit's state returns to it."""
    section = section_of(simulation)
    start = section.reduce(orbit.state)[0]
    return float(np.max(np.abs(section.reduce(end)[0] - start) / scales(simulation, section, start)))
