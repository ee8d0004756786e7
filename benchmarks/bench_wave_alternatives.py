"""The two ways Exudyn could carry waves that models.waves does not take, measured (docs/model.md, "Rods as
waves"):

* Smith's method: the rod as a lumped chain of cells of equal transit time h = dx / c, integrated by
  central differences (Exudyn's VelocityVerlet) at that transit time, exact for the wave equation in the
  rod's interior. Here a NumPy version of that scheme (the same update) on Lundberg's check: a rectangular
  pulse of T = 200 us into a rod on a bilinear rock (through the end cell's half segment, which keeps a
  rigid unloading stable), the efficiency against eta (1 - k_l / k_u) at 50, 200 and 800 cells per pulse,
  k_u = 10 k_l and 1e4 k_l.
* A rod's face as an Exudyn node of zero mass (an ``ObjectMass1D`` of mass 0 is accepted by the implicit
  generalized-alpha solver): a face with its impedance Z = 6.5e4 N s/m as a dashpot to ground and a
  spring of 1e9 N/m, loaded by a force step of 100 kN from rest (what a front does to a face), against the
  exact displacement F / k (1 - exp(-k t / Z)), started at rest and at its consistent velocity F / Z.

    python benchmarks/bench_wave_alternatives.py
"""

from __future__ import annotations

import math
import sys

import numpy as np

E_PA, RHO = 2.1e11, 7850.0
AREA = math.pi * 0.045**2 / 4
Z = AREA * math.sqrt(E_PA * RHO)
C = math.sqrt(E_PA / RHO)


def smith_lundberg(alpha: float, cells_per_pulse: int, ratio: float) -> float:
    """eta - eta (1 - 1/ratio) of the central-difference chain (module doc); NaN if it blew up."""
    pulse = 200e-6
    h = pulse / cells_per_pulse
    dx = C * h
    n = round(1.6 * C * pulse / dx)
    k, mass = E_PA * AREA / dx, RHO * AREA * dx
    loading, amplitude = alpha * Z / pulse, 1e5
    unloading = ratio * loading
    surface = bottom = 0.0

    def rock(position: float) -> tuple[float, float]:
        """(face force, face position): the law in series with the end cell's half segment 2 k."""
        force = max(0.0, min(stiffness * (position - offset) / (1 + stiffness / (2 * k))
                             for stiffness, offset in ((loading, surface), (unloading, bottom))))
        return force, position - force / (2 * k)

    def acceleration(x: np.ndarray, t: float) -> np.ndarray:
        force = np.zeros(n)
        pull = np.diff(x) * k
        force[:-1] += pull
        force[1:] -= pull
        force[0] += amplitude if t < pulse * (1 - 1e-12) else 0.0
        force[-1] -= rock(x[-1])[0]
        return force / mass

    x, v = np.zeros(n), np.zeros(n)
    a = acceleration(x, 0.0)
    work, last_force, last_face = 0.0, 0.0, 0.0
    for step in range(round(3 * pulse / h)):
        x = x + h * v + 0.5 * h * h * a
        following = acceleration(x, (step + 1) * h)
        v = v + 0.5 * h * (a + following)
        a = following
        force, face = rock(x[-1])
        work += 0.5 * (force + last_force) * (face - last_face)
        last_force, last_face = force, face
        if loading * (face - surface) <= unloading * (face - bottom):
            bottom = face - loading * (face - surface) / unloading
        if not math.isfinite(work) or abs(x[-1]) > 1.0:
            return math.nan
    eta = 2 * (1 - math.exp(-alpha)) ** 2 / alpha * (1 - 1 / ratio)
    return work / (amplitude**2 * pulse / Z) - eta


def zero_mass_face(consistent: bool) -> float:
    """The face's displacement at 10 us over the exact one, less 1 (module doc)."""
    import exudyn as exu
    from exudyn.itemInterface import (
        LoadCoordinate,
        MarkerNodeCoordinate,
        Node1D,
        NodePointGround,
        ObjectConnectorCoordinateSpringDamper,
        ObjectMass1D,
        SensorNode,
    )
    force, stiffness = 1e5, 1e9
    container = exu.SystemContainer()
    mbs = container.AddSystem()
    ground = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=mbs.AddNode(NodePointGround()), coordinate=0))
    node = mbs.AddNode(Node1D(referenceCoordinates=[0.0], initialCoordinates=[0.0],
                              initialVelocities=[force / Z if consistent else 0.0]))
    mbs.AddObject(ObjectMass1D(nodeNumber=node, physicsMass=0.0))
    marker = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node, coordinate=0))
    mbs.AddObject(ObjectConnectorCoordinateSpringDamper(markerNumbers=[ground, marker], stiffness=stiffness, damping=Z))
    mbs.AddLoad(LoadCoordinate(markerNumber=marker, load=force))
    sensor = mbs.AddSensor(SensorNode(nodeNumber=node, storeInternal=True,
                                      outputVariableType=exu.OutputVariableType.Coordinates))
    mbs.Assemble()
    settings = exu.SimulationSettings()
    settings.timeIntegration.endTime, settings.timeIntegration.numberOfSteps = 1e-4, 100
    settings.timeIntegration.verboseMode = 0
    settings.timeIntegration.generalizedAlpha.spectralRadius = 1.0
    settings.solution.file.write = False
    settings.solution.sensors.writePeriod = 1e-6
    mbs.SolveDynamic(settings, solverType=exu.DynamicSolverType.GeneralizedAlpha)
    t, x = mbs.GetSensorStoredData(sensor).T
    at = int(np.argmin(np.abs(t - 1e-5)))
    return x[at] / (force / stiffness * (1 - math.exp(-stiffness * t[at] / Z))) - 1


def main() -> None:
    print("Smith's central-difference chain on Lundberg's check, eta - closed form:")
    print("| k_u / k_l | cells per pulse | alpha 0.3 | alpha 1.256 | alpha 4 |")
    print("|---|---|---|---|---|")
    for ratio in (10.0, 1e4):
        for cells in (50, 200, 800):
            errors = " | ".join(f"{smith_lundberg(alpha, cells, ratio):+.1e}" for alpha in (0.3, 1.256, 4.0))
            print(f"| {ratio:g} | {cells} | {errors} |", flush=True)
    print(f"a zero-mass face under generalized-alpha, h = 1 us, displacement at 10 us against the exact: "
          f"{zero_mass_face(False):+.2%} started at rest, {zero_mass_face(True):+.1e} at its consistent velocity")


if __name__ == "__main__":
    sys.exit(main())
