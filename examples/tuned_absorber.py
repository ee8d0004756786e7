"""A tuned mass absorber on the drill collar, added with Exudyn items of one's own.

Shows: ``rpdrill.build_exudyn`` gives the drill as an Exudyn system before it runs; the user adds a mass
point (200 kg) and a spring-damper tuned to the blow frequency (10 % of critical damping) between it
and the collar's position marker, then runs the model with the scene's solver settings. The
penetration rate with and without the absorber is printed.

    python examples/tuned_absorber.py [--end-time-s 0.5]
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from exudyn.itemInterface import MarkerNodePosition, NodePoint, ObjectConnectorSpringDamper, ObjectMassPoint

import rpdrill

SCENE = Path(__file__).resolve().parents[1] / "studies" / "scenes" / "paper_base.yaml"


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
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--end-time-s", type=float, default=1.0)
    args = parser.parse_args()
    scene = rpdrill.load_scene(SCENE).with_({"solver.end_time_s": args.end_time_s})
    plain = rpdrill.build_exudyn(scene).run()
    model = rpdrill.build_exudyn(scene)
    add_absorber(model, "collar", mass_kg=200.0, frequency_hz=scene.impact.frequency_hz, damping_ratio=0.1)
    damped = model.run()
    rates = {"without": plain.metrics["penetration_rate_m_per_s"], "with": damped.metrics["penetration_rate_m_per_s"]}
    print(f"penetration rate without the absorber {1e3 * rates['without']:.3f} mm/s, "
          f"with it {1e3 * rates['with']:.3f} mm/s")
    return rates


if __name__ == "__main__":
    main()
