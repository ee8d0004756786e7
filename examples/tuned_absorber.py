"""
A tuned mass absorber on the drill collar
=========================================

Exudyn items of one's own added to the built drill: ``rpdrill.build_exudyn`` gives the drill as an Exudyn
system before it runs; the user adds a mass point (200 kg) and a spring-damper tuned to the blow frequency
(10 % of critical damping) between it and the collar's position marker, then runs the model with the
scene's solver settings. The penetration rate with and without the absorber is printed, and the collar's
velocity over the last blows of both runs drawn. ::

    python examples/tuned_absorber.py [--end-time-s 1.0] [--figure tuned_absorber.png]
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import matplotlib.pyplot as plt
from exudyn.itemInterface import MarkerNodePosition, NodePoint, ObjectConnectorSpringDamper, ObjectMassPoint

import rpdrill


def add_absorber(model: rpdrill.ExudynModel, body: str, mass_kg: float, frequency_hz: float,
                 damping_ratio: float) -> None:
    """A mass point joined to ``body`` by a spring of natural frequency ``frequency_hz`` with the mass
    (k = m (2 pi f)^2) and a damper of ``damping_ratio`` of critical (c = 2 zeta sqrt(k m))."""
    stiffness_n_per_m = mass_kg * (2.0 * math.pi * frequency_hz) ** 2
    damping_n_s_per_m = 2.0 * damping_ratio * math.sqrt(stiffness_n_per_m * mass_kg)
    anchor = model.bodies[body]
    x_m = model.mbs.GetObject(anchor.object)["referencePosition"][0]  # the body's centre on the drill axis
    node = model.mbs.AddNode(NodePoint(referenceCoordinates=[x_m + 1.0, 0.0, 0.0]))
    model.mbs.AddObject(ObjectMassPoint(mass=mass_kg, nodeNumber=node))
    marker = model.mbs.AddMarker(MarkerNodePosition(nodeNumber=node))
    model.mbs.AddObject(ObjectConnectorSpringDamper(markerNumbers=[anchor.marker_position, marker],
                                                    stiffness=stiffness_n_per_m, damping=damping_n_s_per_m,
                                                    referenceLength=1.0))


def main() -> dict[str, float]:
    parser = argparse.ArgumentParser(description="A tuned mass absorber on the drill collar")
    parser.add_argument("--end-time-s", type=float, default=1.0)
    parser.add_argument("--figure", type=Path, default=Path("tuned_absorber.png"))
    args = parser.parse_args()
    scene = rpdrill.load_scene("paper_base").with_({"solver.end_time_s": args.end_time_s})  # a shipped scene
    plain = rpdrill.build_exudyn(scene).run()
    model = rpdrill.build_exudyn(scene)
    add_absorber(model, "collar", mass_kg=200.0, frequency_hz=scene.impact.frequency_hz, damping_ratio=0.1)
    damped = model.run()
    rates = {"without": plain.metrics["penetration_rate_m_per_s"], "with": damped.metrics["penetration_rate_m_per_s"]}
    print(f"penetration rate without the absorber {1e3 * rates['without']:.3f} mm/s, "
          f"with it {1e3 * rates['with']:.3f} mm/s")
    figure, axes = plt.subplots(figsize=(7, 3.5), layout="constrained")
    last = 3 * scene.impact.period_s  # the last three blows
    for label, result in (("without the absorber", plain), ("with the absorber", damped)):
        series = result.timeseries[result.timeseries["time_s"] >= args.end_time_s - last]
        axes.plot(series["time_s"], series["collar_velocity_m_per_s"], label=label)
    axes.set_xlabel("time (s)")
    axes.set_ylabel("collar velocity (m/s)")
    axes.set_title(f"{scene.name}: the collar over the last three blows (Exudyn)")
    axes.legend()
    figure.savefig(args.figure)
    print(f"wrote {args.figure}")
    return rates


if __name__ == "__main__":
    main()
