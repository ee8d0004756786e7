"""What a user of rpdrill writes for their rig (the tests name it by import path, ``user_rig:NAME``):
extensions (a clamp on a body: a mass on its own Node1D and a coordinate spring-damper to the body;
sensors of one's own; an item the energy account cannot take, with the energy term that accounts for it)
and rock laws of one's own (the paper's law under another name; one without a mode table)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import exudyn
import numpy as np
from exudyn.itemInterface import (
    MarkerNodeCoordinate,
    Node1D,
    ObjectConnectorCoordinateSpringDamper,
    ObjectMass1D,
    SensorNode,
    SensorObject,
)

from rpdrill.rocklaw import JenkinsRock


def add_clamp(model, mass_kg: float, stiffness_n_per_m: float, damping_n_s_per_m: float = 0.0,
              body: str = "collar") -> None:
    """A clamp of ``mass_kg`` on ``body``: a Mass1D on its own Node1D at the body's place, joined to it by a
    coordinate spring-damper; a sensor ``clamp_velocity`` on its node."""
    mbs, anchor = model.mbs, model.bodies[body]
    place = mbs.GetObject(anchor.object)["referencePosition"]
    start = mbs.GetNodeParameter(anchor.node, "initialCoordinates")[0]
    node = mbs.AddNode(Node1D(referenceCoordinates=[0.0], initialCoordinates=[start], initialVelocities=[0.0]))
    mbs.AddObject(ObjectMass1D(nodeNumber=node, mass=mass_kg, referencePosition=list(place), name="clamp"))
    marker = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node, coordinate=0))
    mbs.AddObject(ObjectConnectorCoordinateSpringDamper(markerNumbers=[anchor.marker_coordinate, marker],
                                                        stiffness=stiffness_n_per_m, damping=damping_n_s_per_m,
                                                        name="clamp_joint"))
    mbs.AddSensor(SensorNode(nodeNumber=node, storeInternal=True, name="clamp_velocity",
                             outputVariableType=exudyn.OutputVariableType.Coordinates_t))


def add_sensors(model, body: str = "bit") -> None:
    """A sensor of one's own on a body's velocity, ``<body>_speed_sensor``; nothing else (it changes no motion)."""
    model.mbs.AddSensor(SensorNode(nodeNumber=model.bodies[body].node, storeInternal=True, name=f"{body}_speed_sensor",
                                   outputVariableType=exudyn.OutputVariableType.Coordinates_t))


add_sensors.changes_motion = False  # rpdrill: the exact and ODE formulations may run a scene with it


def add_friction_clamp(model, mass_kg: float, stiffness_n_per_m: float, damping_n_s_per_m: float,
                       declare: bool = True, body: str = "collar") -> None:
    """A clamp whose joint has a spring-force user function (c rate + k stretch, as Python): the energy
    account cannot see into it; with ``declare`` an energy term gives what it stores and dissipates."""
    mbs, anchor = model.mbs, model.bodies[body]
    start = mbs.GetNodeParameter(anchor.node, "initialCoordinates")[0]
    node = mbs.AddNode(Node1D(referenceCoordinates=[0.0], initialCoordinates=[start], initialVelocities=[0.0]))
    mbs.AddObject(ObjectMass1D(nodeNumber=node, mass=mass_kg, name="friction_clamp"))
    marker = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node, coordinate=0))

    def force(mbs, t, item, displacement, velocity, stiffness, damping, offset):
        return stiffness * displacement + damping * velocity

    joint = mbs.AddObject(ObjectConnectorCoordinateSpringDamper(
        markerNumbers=[anchor.marker_coordinate, marker], stiffness=stiffness_n_per_m, damping=damping_n_s_per_m,
        springForceUserFunction=force, name="friction_joint"))
    if not declare:
        return
    stretch = mbs.AddSensor(SensorObject(objectNumber=joint, storeInternal=True, name="friction_joint_stretch",
                                         outputVariableType=exudyn.OutputVariableType.Displacement))
    rate = mbs.AddSensor(SensorObject(objectNumber=joint, storeInternal=True, name="friction_joint_rate",
                                      outputVariableType=exudyn.OutputVariableType.Velocity))

    def read(sensor, time_s):
        data = model.mbs.GetSensorStoredData(sensor)
        return np.interp(time_s, data[:, 0], data[:, 1])

    def stored(model, time_s):
        return 0.5 * stiffness_n_per_m * read(stretch, time_s) ** 2

    def dissipated(model, time_s):
        power = damping_n_s_per_m * read(rate, time_s) ** 2
        return np.concatenate(([0.0], np.cumsum(0.5 * (power[1:] + power[:-1]) * np.diff(time_s))))

    model.add_energy_term("friction joint, stored", "stored", stored, items=[joint])
    model.add_energy_term("friction joint, dissipated", "dissipated", dissipated, items=[joint])


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
