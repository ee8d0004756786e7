"""What one run of an n-blow map gives (:class:`MapRun`) and how a run starts from a section state.

:func:`started_at` is the prepared simulation with its start moved to a section state y (models.steady.section:
positions, velocities, rock states, torsion angle and rate, an Exudyn scene's extension coordinates) and its end time to n blow periods: every
formulation starts from the simulation's initial fields (models.solvers.simulation), so the Exudyn model,
the ODE and the exact formulation all run it as they run a scene; :func:`end_state` and :func:`states_at` read y back
from a result.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..definition.scene import Metrics
from ..evaluation.results import SimulationResult
from ..solvers.exact_system import Modes
from ..solvers.simulation import Simulation
from .section import section_of


@dataclass(frozen=True)
class Switch:
    """One switch of a run: its time from the run's start and the modes it entered (the rock's first)."""

    time_s: float
    modes: Modes


@dataclass(frozen=True)
class MapRun:
    """One evaluation of the n-blow map from y0: the end state Y (before the next blow's resets), its
    Jacobian dY/dy0 (None when not asked for or not exact), and the switches on the way."""

    end_state: np.ndarray
    monodromy: np.ndarray | None
    switches: tuple[Switch, ...]


def started_at(simulation: Simulation, y: np.ndarray, blows: int, outputs: bool = True) -> Simulation:
    """``simulation`` from the section state ``y`` at t = 0 for ``blows`` blow periods, its metrics'
    window those blows (no transient); ``outputs`` False: no metrics or series asked for (a run that only
    gives its end state records nothing it does not need)."""
    section = section_of(simulation)
    n, states = section.bodies, section.rock_states
    end_s = blows * simulation.impact.period_s
    scene = simulation.scene
    scene = scene.model_copy(update={
        "solver": scene.solver.model_copy(update={"end_time_s": end_s}),
        "metrics": Metrics.model_construct(transient_blows=0, block_blows=blows)})
    tail = 2 * n + states + 2 * section.torsion
    torsion = y[2 * n + states:tail] if section.torsion else (simulation.initial_torsion_angle_rad, 0.0)
    followed = simulation.extension_coordinates  # an Exudyn scene's extensions' coordinates, their start
    followed = followed if followed is None else replace(followed, start=tuple(float(v) for v in y[tail:]))
    changed = replace(
        simulation, scene=scene, settings=replace(simulation.settings, end_time_s=end_s),
        initial_positions_m=np.array(y[:n]), initial_velocities_m_per_s=np.array(y[n:2 * n]),
        initial_rock_state=tuple(float(v) for v in y[2 * n:2 * n + states]),
        initial_torsion_angle_rad=float(torsion[0]), initial_torsion_rate_rad_per_s=float(torsion[1]),
        extension_coordinates=followed)
    if not outputs:
        changed = replace(changed, outputs=simulation.outputs.model_copy(update={"metrics": [], "timeseries": []}))
    return changed


def end_state(result: SimulationResult) -> np.ndarray:
    """y at a run's last sample."""
    y = _state_table(result)[-1].copy()
    y[2 * result.simulation.chain.size + result.simulation.rock.bottom_index] = \
        result.bottom_at(result.time_s[-1:])[0]
    return y


def states_at(result: SimulationResult, times_s: np.ndarray) -> list[np.ndarray]:
    """y of a run at each of ``times_s`` (between samples interpolated, the rock states taken by the law's
    return map to the bit there: SimulationResult.bottom_at)."""
    table, times = _state_table(result), np.asarray(times_s, dtype=float)
    states = np.column_stack([np.interp(times, result.time_s, column) for column in table.T])
    states[:, 2 * result.simulation.chain.size + result.simulation.rock.bottom_index] = result.bottom_at(times)
    return list(states)


def _state_table(result: SimulationResult) -> np.ndarray:
    """y at every sample of a run (one row a sample; the bottom's column as recorded)."""
    columns = [result.position_m, result.velocity_m_per_s, np.column_stack(result.rock_states())]
    if result.torsion_angle_rad is not None:
        columns += [result.torsion_angle_rad[:, None], result.torsion_rate_rad_per_s[:, None]]
    columns += [result.extension_state] if result.extension_state is not None else []
    return np.hstack(columns)
