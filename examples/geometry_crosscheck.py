"""
A changed geometry, checked between Exudyn and the exact formulation
====================================================================

``Scene.with_`` edits a scene by the key paths of its file (a validated copy: a bad value raises
``rpdrill.InputError`` naming the key); the same scene run by two formulations (the Exudyn multibody model
at its ``reference`` preset, and the exact piecewise-linear propagation) gives the same penetration rate
and bit velocity, to the stated error of the preset (docs/stability.md). The bit's velocity over the last
blows is drawn from both runs, with their difference. ::

    python examples/geometry_crosscheck.py [--end-time-s 1.0] [--figure geometry_crosscheck.png]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import rpdrill


def main() -> dict[str, float]:
    parser = argparse.ArgumentParser(description="A changed geometry, checked between Exudyn and the exact "
                                                 "formulation")
    parser.add_argument("--end-time-s", type=float, default=1.0)
    parser.add_argument("--figure", type=Path, default=Path("geometry_crosscheck.png"))
    args = parser.parse_args()
    scene = rpdrill.load_scene("paper_base").with_({  # a shipped scene
        "drill_string.bodies.collar.mass_kg": 2400.0,          # a longer collar
        "drill_string.connectors.collar_bit_joint.stiffness_n_per_m": 5.0e9,  # a softer joint
        "solver.end_time_s": args.end_time_s,
    })
    try:
        scene.with_({"drill_string.bodies.collar.mass_kg": -1.0})
    except rpdrill.InputError as error:
        print(f"refused as it should be: {error}")
    exact = rpdrill.simulate(scene, formulation="exact")
    exudyn = rpdrill.simulate(scene.with_({"solver.preset": "reference"}), formulation="exudyn")
    rates = {name: r.metrics["penetration_rate_m_per_s"] for name, r in (("exact", exact), ("exudyn", exudyn))}
    velocity = {name: r.timeseries["bit_velocity_m_per_s"].to_numpy() for name, r in (("exact", exact),
                                                                                          ("exudyn", exudyn))}
    difference = float(np.max(np.abs(velocity["exact"] - velocity["exudyn"])) / np.max(np.abs(velocity["exact"])))
    relative = abs(rates["exudyn"] - rates["exact"]) / rates["exact"]
    print(f"penetration rate: exact {1e3 * rates['exact']:.4f} mm/s, Exudyn {1e3 * rates['exudyn']:.4f} mm/s "
          f"(relative difference {relative:.1e}); bit velocity: largest difference {difference:.1e} of its peak")
    time_s = exact.timeseries["time_s"].to_numpy()
    last = time_s >= time_s[-1] - 3 * scene.impact.period_s  # the last three blows
    figure, (top, bottom) = plt.subplots(2, 1, figsize=(7, 5), sharex=True, layout="constrained")
    top.plot(time_s[last], velocity["exact"][last], label="exact")
    top.plot(time_s[last], velocity["exudyn"][last], "--", label="Exudyn (reference preset)")
    top.set_ylabel("bit velocity (m/s)")
    top.set_title("collar 2400 kg, collar-bit joint 5e9 N/m: the last three blows")
    top.legend()
    bottom.plot(time_s[last], velocity["exudyn"][last] - velocity["exact"][last])
    bottom.set_xlabel("time (s)")
    bottom.set_ylabel("Exudyn - exact (m/s)")
    figure.savefig(args.figure)
    print(f"wrote {args.figure}")
    return {"rate_relative_difference": relative, "velocity_difference": difference}


if __name__ == "__main__":
    main()
