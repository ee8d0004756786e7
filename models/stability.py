"""Detection of runs whose numbers must not be reported (diverged or stopped early)."""

from __future__ import annotations

import numpy as np

from models.results import SimulationResult

# Positions beyond this are not drilling: the solver has blown up (states near 1e300 seen with
# explicit solvers at too large a step, reported as success by the solver).
POSITION_LIMIT_M = 1e3


class SimulationFailed(RuntimeError):
    """A run that diverged or did not reach its end time."""


def check_finite(result: SimulationResult, solver_ok: bool) -> None:
    """Raise :class:`SimulationFailed` naming scene, solver, time and a remedy if the run is unusable."""
    scene, solver = result.scene, result.scene.solver
    states = np.column_stack([result.position_m, result.velocity_m_per_s])
    bad = ~np.isfinite(states).all(axis=1) | (np.abs(result.position_m) > POSITION_LIMIT_M).any(axis=1)
    setting = f"solver {solver.type} with step_s {solver.step_s:g}"
    remedy = f"try solver.step_s {solver.step_s / 4:g} or solver.type generalized_alpha"
    if bad.any():
        when = result.time_s[np.argmax(bad)]
        raise SimulationFailed(f"scene '{scene.name}': {setting} diverged at t = {when:.6g} s; {remedy}")
    reached = result.time_s[-1] if len(result.time_s) else 0.0
    if not solver_ok or reached < solver.end_time_s * (1 - 1e-9):
        raise SimulationFailed(
            f"scene '{scene.name}': {setting} stopped at t = {reached:.6g} s before end_time_s "
            f"{solver.end_time_s:g}; {remedy}"
        )
