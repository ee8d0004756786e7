"""What a user of rpdrill writes for their rig (the tests name it by import path, ``user_rig:NAME``, and allow the
module, ``allow_code=["user_rig"]``: a scene runs no code unasked; each extension marked ``@rpdrill.extension``,
each law a subclass of rocklaw.base.RockLaw, through the built-in law it derives from):
extensions (the clamps of examples/clamp_extension.py: a mass on its own Node1D held on a body by a
coordinate spring-damper, one with a spring-force user function and its declared energy terms, one joined by a
constraint; a constant load; sensors of one's own; an oscillator on ground; a loose mass, a step counter and an
anchor to ground, which a steady state cannot follow) and
rock laws of one's own (the paper's law under another name; one without a mode table)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import exudyn
from exudyn.itemInterface import (
    LoadCoordinate,
    MarkerNodeCoordinate,
    Node1D,
    NodePointGround,
    ObjectConnectorCoordinateSpringDamper,
    ObjectMass1D,
    SensorNode,
)

import rpdrill
from examples.clamp_extension import (  # the checkout's examples: a user's module
    add_clamp,
    add_friction_clamp,
    add_rigid_clamp,
)
from rpdrill.rocklaw import JenkinsRock

__all__ = ["ForceOnlyRock", "RenamedJenkins", "add_anchor", "add_clamp", "add_friction_clamp", "add_ground_oscillator",
           "add_load", "add_loose_mass", "add_rigid_clamp", "add_sensors", "add_step_counter"]


@rpdrill.extension
def add_sensors(model, body: str = "bit") -> None:
    """A sensor of one's own on a body's velocity, ``<body>_speed_sensor``; nothing else (it changes no motion)."""
    model.mbs.AddSensor(SensorNode(nodeNumber=model.bodies[body].node, storeInternal=True, name=f"{body}_speed_sensor",
                                   outputVariableType=exudyn.OutputVariableType.Coordinates_t))


add_sensors.changes_motion = False  # rpdrill: the exact and ODE formulations may run a scene with it


@rpdrill.extension
def add_load(model, force_n: float, body: str = "pipe") -> None:
    """A constant ``LoadCoordinate`` of ``force_n`` on ``body`` (on the pipe of paper_base: as much more feed)."""
    model.mbs.AddLoad(LoadCoordinate(markerNumber=model.bodies[body].marker_coordinate, load=force_n))


@rpdrill.extension
def add_loose_mass(model, mass_kg: float = 50.0) -> None:
    """A Mass1D on its own Node1D, ``loose_mass``, that no spring holds (a free coordinate of one's own)."""
    node = model.mbs.AddNode(Node1D(referenceCoordinates=[0.0], initialCoordinates=[0.0], initialVelocities=[0.0]))
    model.mbs.AddObject(ObjectMass1D(nodeNumber=node, mass=mass_kg, name="loose_mass"))


@rpdrill.extension
def add_step_counter(model) -> None:
    """A per-step function of one's own (``model.add_pre_step``) that counts the steps: a state outside Exudyn's."""
    steps = []
    model.add_pre_step(lambda mbs, t: steps.append(t) is None)


@rpdrill.extension(changes_motion=False)  # the exact formulation may run a scene with it
def add_ground_oscillator(model, mass_kg: float = 10.0, stiffness_n_per_m: float = 1.0e4,
                          damping_n_s_per_m: float = 100.0) -> None:
    """A Mass1D, ``oscillator``, on a spring-damper to ground, tied to nothing of the drill (a reference of
    one's own): coordinates that change no motion of the drill and do not move with it."""
    mbs = model.mbs
    node = mbs.AddNode(Node1D(referenceCoordinates=[0.0], initialCoordinates=[1e-3], initialVelocities=[0.0]))
    mbs.AddObject(ObjectMass1D(nodeNumber=node, mass=mass_kg, name="oscillator"))
    ground = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=mbs.AddNode(NodePointGround()), coordinate=0))
    mbs.AddObject(ObjectConnectorCoordinateSpringDamper(
        markerNumbers=[ground, mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node, coordinate=0))],
        stiffness=stiffness_n_per_m, damping=damping_n_s_per_m, name="oscillator_spring"))



@rpdrill.extension
def add_anchor(model, stiffness_n_per_m: float, body: str = "collar") -> None:
    """A coordinate spring, ``anchor``, from ground to ``body`` (no coordinates of its own)."""
    mbs = model.mbs
    ground = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=mbs.AddNode(NodePointGround()), coordinate=0))
    mbs.AddObject(ObjectConnectorCoordinateSpringDamper(markerNumbers=[ground, model.bodies[body].marker_coordinate],
                                                        stiffness=stiffness_n_per_m, name="anchor"))


@dataclass(frozen=True)
class RenamedJenkins(JenkinsRock):
    """The paper's law under another name, named by import path (``user_rig:RenamedJenkins``)."""

    name: ClassVar[str] = "renamed_jenkins"


@dataclass(frozen=True)
class ForceOnlyRock(JenkinsRock):
    """The paper's law without its mode table: enough for the Exudyn formulation, not for the exact one."""

    name: ClassVar[str] = "force_only"

    def modes(self):
        raise NotImplementedError("no mode table")
