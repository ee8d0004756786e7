"""The n-blow map of any formulation, by its own time run from a given state
(models.steady.map_runs.started_at): the Exudyn model (with whatever the scene adds to it), the ODE and the
exact formulation run it as they run a scene. It has no Jacobian of its own (models.steady.shooting takes
one by forward differences, or the exact model's as its Newton matrix)."""

from __future__ import annotations

import numpy as np

from ..solvers.simulation import Simulation
from ..solvers.time_run import time_run
from .map_runs import MapRun, end_state, started_at, states_at
from .section import Section, section_of


class FormulationMap:
    """Y(y0) over ``periods`` blows by the simulation's own formulation (module doc)."""

    has_exact_jacobian = False

    def __init__(self, simulation: Simulation, periods: int) -> None:
        self.simulation, self.periods = simulation, periods
        self.period_s = simulation.impact.period_s
        self.section: Section = section_of(simulation)

    def __call__(self, y0: np.ndarray, jacobian: bool = False) -> MapRun:
        """Y(y0) (no Jacobian, no switches: this formulation does not report its events)."""
        result = time_run(started_at(self.simulation, y0, self.periods, outputs=False))
        return MapRun(end_state(result), None, ())

    def blow_states(self, y0: np.ndarray, blows: int) -> list[np.ndarray]:
        """y at every blow start of a run of ``blows`` periods from y0 (the last one its end)."""
        result = time_run(started_at(self.simulation, y0, blows, outputs=False))
        return states_at(result, np.arange(1, blows + 1) * self.period_s)
