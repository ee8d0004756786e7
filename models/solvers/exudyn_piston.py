"""The piston's strikes and catches in the Exudyn model (models.drill.piston): a pre-step hook that sets the
piston's coordinates at the first step starting at or after each blow start (the strike) and at the
first step starting with the contact open and the piston moving back (the catch: at most one step
late, while the piston flies free and keeps its energy), and the piston's history after the run."""

from __future__ import annotations

from typing import Any

import numpy as np

from ...rocklaw.exudyn_module import exu
from ..drill.piston import PistonHistory, PistonJumps, PistonSetup, piston_history

CONFIGURATIONS = (exu.ConfigurationType.Current, exu.ConfigurationType.StartOfStep)


class ExudynPiston:
    """The pre-step hook (module doc) over the dynamic chain's nodes ``nodes``."""

    def __init__(self, setup: PistonSetup, nodes: list[Any], mbs: Any, blow_period_s: float) -> None:
        self.setup, self.period_s = setup, blow_period_s
        self.jumps = PistonJumps(setup)
        self.indices = np.array([mbs.GetNodeODE2Index(node) for node in nodes])
        self.blows, self.step_start_s = 0, 0.0

    def __call__(self, mbs: Any, t: float) -> bool:
        """Exudyn passes the time at the end of the coming step, the state still at its start."""
        start, self.step_start_s = self.step_start_s, t
        strike = start >= (self.blows - 1e-9) * self.period_s  # a round-off before a blow start is that blow start
        if not strike and self.jumps.caught:
            return True
        data = mbs.systemData
        coordinates, rates = np.array(data.GetODE2Coordinates()), np.array(data.GetODE2Coordinates_t())
        position, velocity = coordinates[self.indices], rates[self.indices]
        if strike:
            self.jumps.strike(start, position, velocity)
            self.blows += 1
        elif self.setup.caught(position, velocity):
            self.jumps.catch(start, position, velocity)
        else:
            return True
        coordinates[self.indices], rates[self.indices] = position, velocity
        for configuration in CONFIGURATIONS:
            data.SetODE2Coordinates(coordinates.tolist(), configuration=configuration)
            data.SetODE2Coordinates_t(rates.tolist(), configuration=configuration)
        return True

    def history(self, time_s: np.ndarray, position_m: np.ndarray, velocity_m_per_s: np.ndarray) -> PistonHistory:
        """The piston's history from the stored samples (each stored at a step's end, before the jumps
        of the step that starts there)."""
        return piston_history(self.setup, self.jumps, time_s - 1e-9 * self.period_s, position_m, velocity_m_per_s,
                              np.ones(len(time_s), dtype=bool))
