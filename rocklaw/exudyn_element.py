"""The rock law as an Exudyn element: a coordinate spring-damper from ground to the bit.

The force is an Exudyn *symbolic* user function recorded from :meth:`JenkinsRock.force`
(compiled expression tree, no Python call per evaluation; ``symbolic=False`` gives the same
law as a Python callback, for benchmarks). The borehole bottom x_n is the
connector's ``offset`` (so the function sees penetration = displacement - offset) and is
updated once per accepted step, before the step, by the return mapping of Eq. 2.
"""

from __future__ import annotations

from typing import Any

import exudyn as exu
from exudyn.advancedUtilities import CreateSymbolicUserFunction
from exudyn.itemInterface import ObjectConnectorCoordinateSpringDamper

from rocklaw.backends import SCALAR, SymbolicBackend
from rocklaw.jenkins import JenkinsRock


def attach_user_function(mbs: Any, item: Any, parameter: str, function: Any, symbolic: bool) -> Any:
    """Set ``function`` as the item's user function: recorded as symbolic (compiled) or as a
    plain Python callback (for comparison). Returns what must be kept alive with the system."""
    if symbolic:
        function = CreateSymbolicUserFunction(mbs, function, parameter, item)
    if item.GetTypeString() == "LoadIndex":
        mbs.SetLoadParameter(item, parameter, function)
    else:
        mbs.SetObjectParameter(item, parameter, function)
    return function


class ExudynRockContact:
    """Paper rock law between a ground coordinate marker and the bit's coordinate marker."""

    def __init__(
        self,
        mbs: Any,
        ground_marker: Any,
        bit_marker: Any,
        bit_node: Any,
        rock: JenkinsRock,
        initial_bottom_m: float = 0.0,
        symbolic: bool = True,
    ) -> None:
        self.rock = rock
        self._bit_node = bit_node
        self.bottom_m = initial_bottom_m
        # (time, x_n) each time the bottom moved; x_n(t) is the step function through these.
        self.bottom_history: list[tuple[float, float]] = [(0.0, initial_bottom_m)]
        self._step_start_s = 0.0
        self.object = mbs.AddObject(
            ObjectConnectorCoordinateSpringDamper(
                markerNumbers=[ground_marker, bit_marker],
                stiffness=rock.stiffness_n_per_m,
                damping=rock.damping_n_s_per_m,
                offset=initial_bottom_m,
            )
        )
        backend = SymbolicBackend() if symbolic else SCALAR

        def rock_force(mbs, t, itemNumber, displacement, velocity, stiffness, damping, offset):
            return rock.force(displacement - offset, velocity, backend)

        # Exudyn keeps only a raw pointer to a symbolic expression tree: hold the reference here.
        self._user_function = attach_user_function(
            mbs, self.object, "springForceUserFunction", rock_force, symbolic
        )
        self._coordinate = exu.OutputVariableType.Coordinates

    def update_bottom(self, mbs: Any, t: float) -> bool:
        """Return mapping x_n <- max(x_n, x_bit - F_th/k_n), called once before each step.

        Exudyn passes the pre-step function the time at the *end* of the coming step while the
        state is still that of its start; the history is stamped with the start time.
        """
        candidate = mbs.GetNodeOutput(self._bit_node, self._coordinate) - self.rock.crushing_penetration_m
        if candidate > self.bottom_m:
            self.bottom_m = candidate
            mbs.SetObjectParameter(self.object, "offset", candidate)
            self.bottom_history.append((self._step_start_s, candidate))
        self._step_start_s = t
        return True  # as an Exudyn pre-step function: go on
