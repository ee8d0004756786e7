"""What a user of rpdrill writes for their rig (the tests name it by import path, ``user_rig:NAME``):
extensions (the clamps of examples/clamp_extension.py: a mass on its own Node1D held on a body by a
coordinate spring-damper, and one with a spring-force user function and its declared energy terms; sensors
of one's own) and rock laws of one's own (the paper's law under another name; one without a mode table)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import exudyn
from exudyn.itemInterface import SensorNode

from examples.clamp_extension import add_clamp, add_friction_clamp  # the checkout's examples: a user's module
from rpdrill.rocklaw import JenkinsRock

__all__ = ["ForceOnlyRock", "RenamedJenkins", "add_clamp", "add_friction_clamp", "add_sensors"]


def add_sensors(model, body: str = "bit") -> None:
    """A sensor of one's own on a body's velocity, ``<body>_speed_sensor``; nothing else (it changes no motion)."""
    model.mbs.AddSensor(SensorNode(nodeNumber=model.bodies[body].node, storeInternal=True, name=f"{body}_speed_sensor",
                                   outputVariableType=exudyn.OutputVariableType.Coordinates_t))


add_sensors.changes_motion = False  # rpdrill: the exact and ODE formulations may run a scene with it


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
