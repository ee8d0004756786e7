"""The Exudyn items of the drill's bodies and links (models.solvers.exudyn_model): what a built model hands a
user (``ExudynBody``, ``ExudynConnector``), how a body and a link's law are added, and the solver types by
their scene names."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from ...rocklaw.exudyn_module import exu  # first: it chooses Exudyn's compiled module

# isort: split
from exudyn.itemInterface import MarkerBodyPosition, MarkerNodeCoordinate, Node1D

from ..drill.chain import Link

SOLVER_TYPES = {
    "rk67": exu.DynamicSolverType.RK67,
    "rk44": exu.DynamicSolverType.RK44,
    "rk33": exu.DynamicSolverType.RK33,
    "explicit_midpoint": exu.DynamicSolverType.ExplicitMidpoint,
    "explicit_euler": exu.DynamicSolverType.ExplicitEuler,
    "generalized_alpha": exu.DynamicSolverType.GeneralizedAlpha,
    "trapezoidal_index2": exu.DynamicSolverType.TrapezoidalIndex2,
    "dopri5": exu.DynamicSolverType.DOPRI5,
    "ode23": exu.DynamicSolverType.ODE23,
}

@dataclass(frozen=True)
class ExudynBody:
    """One axial body (a rod segment ``rod[0]`` too), or the torsion line, as Exudyn items."""

    name: str
    node: Any  # Node1D: the body's axial displacement (the torsion line: its angle)
    object: Any  # ObjectMass1D (torsion: ObjectRotationalMass1D)
    marker_coordinate: Any  # MarkerNodeCoordinate: for coordinate connectors and loads
    marker_position: Any  # MarkerBodyPosition at the body's centre: a 3-D point for Exudyn's spatial connectors


@dataclass(frozen=True)
class ExudynConnector:
    """One link of the chain (a scene connector, a rod's inner link ``rod[0-1]``) as its Exudyn object."""

    name: str
    object: Any  # ObjectConnectorCoordinateSpringDamper
    link: Link



def add_body(mbs: Any, name: str, make_object: Callable[[Any], Any], initial: float = 0.0,
              velocity: float = 0.0) -> ExudynBody:
    node = mbs.AddNode(Node1D(referenceCoordinates=[0.0], initialCoordinates=[initial], initialVelocities=[velocity]))
    body = make_object(node)
    return ExudynBody(name, node, body, mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node, coordinate=0)),
                      mbs.AddMarker(MarkerBodyPosition(bodyNumber=body, localPosition=[0.0, 0.0, 0.0])))


def link_force_function(link: Link, backend: Any) -> Callable[..., Any]:
    """A connector's spring-force user function carrying the link's own law (:meth:`Link.force_n`)."""
    def link_force(mbs, t, itemNumber, displacement, velocity, stiffness, damping, offset):
        return link.force_n(displacement, velocity, backend)
    return link_force


