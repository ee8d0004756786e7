"""
Extensions of one's own: a clamp on the collar, its sensor and an energy term
=============================================================================

A Python extension is a function ``f(model, **parameters)`` marked ``@rpdrill.extension`` that adds Exudyn
items to the built model (``rpdrill.build_exudyn``); a scene names it by import path with its parameters
and runs it where its reader allows the module (``allow_code=["clamp_extension"]``, ``--allow-code
clamp_extension``: a scene is data, docs/extending.md "Security"), so every run builds it, a worker process
too, and a study can scan its parameters (``extensions.clamp.parameters.mass_kg``). The clamp (a Mass1D on
its own Node1D and a coordinate spring-damper to the collar) is stepped as the assembled system needs,
enters the energy account by itself, and its sensor comes back in the time series. The friction clamp has a
spring-force user function the energy account cannot see into, so it declares its own energy terms.
Printed: the step each run got, the penetration rate of the clamped collar against the collar made heavier
by the clamp's mass (the exact formulation), the energy balance and the sensor; drawn: the collar of both
and the clamp's sensor over the last blows. ::

    python examples/clamp_extension.py [--end-time-s 0.3] [--stiffness-n-per-m 1e12] [--figure clamp_extension.png]

The extensions are importable as ``clamp_extension:add_clamp`` with this folder on ``sys.path`` (the
script's folder is, when it runs), or as ``examples.clamp_extension:add_clamp`` from the root of the
checkout (docs/extending.md).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import exudyn
import matplotlib.pyplot as plt
import numpy as np
from exudyn.itemInterface import (
    MarkerNodeCoordinate,
    Node1D,
    ObjectConnectorCoordinate,
    ObjectConnectorCoordinateSpringDamper,
    ObjectMass1D,
    SensorNode,
    SensorObject,
)

import rpdrill


def _clamp_node(model, body: str, mass_kg: float, name: str) -> tuple:
    """A Mass1D of ``mass_kg`` on its own Node1D where ``body`` is (its place, its initial displacement)."""
    mbs, anchor = model.mbs, model.bodies[body]
    start = mbs.GetNodeParameter(anchor.node, "initialCoordinates")[0]
    node = mbs.AddNode(Node1D(referenceCoordinates=[0.0], initialCoordinates=[start], initialVelocities=[0.0]))
    mbs.AddObject(ObjectMass1D(nodeNumber=node, mass=mass_kg, name=name,
                               referencePosition=list(mbs.GetObject(anchor.object)["referencePosition"])))
    return node, mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node, coordinate=0))


@rpdrill.extension
def add_clamp(model, mass_kg: float, stiffness_n_per_m: float, damping_n_s_per_m: float = 0.0,
              body: str = "collar") -> None:
    """A clamp of ``mass_kg`` held on ``body`` by a coordinate spring-damper; a sensor of its velocity,
    ``clamp_velocity`` (it comes back in the result's time series under that name)."""
    node, marker = _clamp_node(model, body, mass_kg, "clamp")
    model.mbs.AddObject(ObjectConnectorCoordinateSpringDamper(
        markerNumbers=[model.bodies[body].marker_coordinate, marker], stiffness=stiffness_n_per_m,
        damping=damping_n_s_per_m, name="clamp_joint"))
    model.mbs.AddSensor(SensorNode(nodeNumber=node, storeInternal=True, name="clamp_velocity",
                                   outputVariableType=exudyn.OutputVariableType.Coordinates_t))


@rpdrill.extension
def add_rigid_clamp(model, mass_kg: float, body: str = "collar") -> None:
    """A clamp of ``mass_kg`` joined rigidly to ``body`` by a coordinate constraint (``ObjectConnectorCoordinate``,
    ``rigid_joint``): an algebraic equation, which only Exudyn's implicit solvers integrate (a scene names
    ``solver.type: generalized_alpha`` with it; docs/extending.md)."""
    _node, marker = _clamp_node(model, body, mass_kg, "rigid_clamp")
    model.mbs.AddObject(ObjectConnectorCoordinate(markerNumbers=[model.bodies[body].marker_coordinate, marker],
                                                  name="rigid_joint"))


@rpdrill.extension
def add_friction_clamp(model, mass_kg: float, stiffness_n_per_m: float, damping_n_s_per_m: float,
                       body: str = "collar", declare: bool = True) -> None:
    """A clamp whose joint computes its force in Python (a spring-force user function): the energy account
    cannot see into it, so this extension declares what the joint stores and dissipates, from sensors
    (without ``declare`` the energy balance is not a number, and the result's info names the joint)."""
    _node, marker = _clamp_node(model, body, mass_kg, "friction_clamp")

    def force(mbs, t, item, displacement, velocity, stiffness, damping, offset):
        return stiffness * displacement + damping * velocity

    joint = model.mbs.AddObject(ObjectConnectorCoordinateSpringDamper(
        markerNumbers=[model.bodies[body].marker_coordinate, marker], stiffness=stiffness_n_per_m,
        damping=damping_n_s_per_m, springForceUserFunction=force, name="friction_joint"))
    if not declare:
        return
    sensors = {output: model.mbs.AddSensor(SensorObject(objectNumber=joint, storeInternal=True,
                                                        outputVariableType=output))
               for output in (exudyn.OutputVariableType.Displacement, exudyn.OutputVariableType.Velocity)}

    def read(output, time_s):
        data = model.mbs.GetSensorStoredData(sensors[output])
        return np.interp(time_s, data[:, 0], data[:, 1])

    def stored(model, time_s):  # k stretch^2 / 2, held at each time
        return 0.5 * stiffness_n_per_m * read(exudyn.OutputVariableType.Displacement, time_s) ** 2

    def dissipated(model, time_s):  # int c rate^2 dt, cumulative
        power = damping_n_s_per_m * read(exudyn.OutputVariableType.Velocity, time_s) ** 2
        return np.concatenate(([0.0], np.cumsum(0.5 * (power[1:] + power[:-1]) * np.diff(time_s))))

    model.add_energy_term("friction joint, stored", "stored", stored, items=[joint])
    model.add_energy_term("friction joint, dissipated", "dissipated", dissipated, items=[joint])


def main() -> None:
    parser = argparse.ArgumentParser(description="Extensions of one's own: a clamp on the collar, its sensor and "
                                                 "an energy term")
    parser.add_argument("--end-time-s", type=float, default=0.3)
    parser.add_argument("--stiffness-n-per-m", type=float, default=1e12)
    parser.add_argument("--figure", type=Path, default=Path("clamp_extension.png"))
    args = parser.parse_args()
    allowed = ["clamp_extension"]  # the module of one's own the scenes below may run (this script's)
    base = rpdrill.load_scene("paper_base").with_({"solver.end_time_s": args.end_time_s})  # a shipped scene
    clamped = base.with_({"extensions": {"clamp": {"function": "clamp_extension:add_clamp", "parameters": {
        "mass_kg": 300.0, "stiffness_n_per_m": args.stiffness_n_per_m, "damping_n_s_per_m": 1e3}}}}, allow_code=allowed)
    result = rpdrill.simulate(clamped)
    heavier = rpdrill.simulate(base.with_({"drill_string.bodies.collar.mass_kg":
                                           base.drill_string.bodies["collar"].mass_kg + 300.0}), formulation="exact")
    rate, reference = result.metrics["penetration_rate_m_per_s"], heavier.metrics["penetration_rate_m_per_s"]
    print(f"step: {rpdrill.build_exudyn(base).simulation.settings.step_s:.3g} s without the clamp, "
          f"{result.raw.simulation.settings.step_s:.3g} s with it")
    print(f"clamped collar (Exudyn): {rate * 1e3:.4f} mm/s; collar 300 kg heavier (exact): {reference * 1e3:.4f} mm/s "
          f"(relative difference {abs(rate / reference - 1):.2e})")
    print(f"energy balance with the clamp: {result.metrics['energy_balance_relative_error']:.2e} "
          f"({', '.join(result.user_energy.accounted)})")
    print(f"clamp_velocity sensor: peak {result.timeseries['clamp_velocity'].abs().max():.4f} m/s")
    friction = base.with_({"extensions": {"friction": {"function": "clamp_extension:add_friction_clamp", "parameters": {
        "mass_kg": 300.0, "stiffness_n_per_m": 1e9, "damping_n_s_per_m": 2e4}}}}, allow_code=allowed)
    declared = rpdrill.simulate(friction)
    print(f"energy balance with the friction clamp and its declared terms: "
          f"{declared.metrics['energy_balance_relative_error']:.2e} ({', '.join(declared.user_energy.declared)})")
    figure, axes = plt.subplots(figsize=(7, 3.5), layout="constrained")
    start = args.end_time_s - 3 * base.impact.period_s  # the last three blows
    for label, series, column, style in (
            ("collar with the clamp (Exudyn)", result.timeseries, "collar_velocity_m_per_s", "-"),
            ("clamp_velocity sensor (Exudyn)", result.timeseries, "clamp_velocity", ":"),
            ("collar 300 kg heavier (exact)", heavier.timeseries, "collar_velocity_m_per_s", "--")):
        shown = series[series["time_s"] >= start]
        axes.plot(shown["time_s"], shown[column], style, label=label)
    axes.set_xlabel("time (s)")
    axes.set_ylabel("velocity (m/s)")
    axes.set_title(f"{base.name}: a 300 kg clamp on the collar, k {args.stiffness_n_per_m:g} N/m")
    axes.legend()
    figure.savefig(args.figure)
    print(f"wrote {args.figure}")


if __name__ == "__main__":
    main()
