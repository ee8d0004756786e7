"""What simulating only the needed effects saves: the full model against what a
penetration-rate scan needs (no torsion, no force sensors, storage at the output interval only).

Usage: python benchmarks/bench_effects.py [SCENE.yaml] [--repeats N] [--end-time S]
Prints medians of N repeats, coordinate counts, the ratio, and the penetration rate of both.
"""

from __future__ import annotations

import argparse
import statistics
from pathlib import Path

from rpdrill.models.definition.scene import Scene
from rpdrill.models.evaluation.metrics import summary_metrics
from rpdrill.models.runs.scene_run import run as run_simulation
from rpdrill.models.solvers.exudyn_model import build_exudyn
from rpdrill.models.solvers.simulation import prepare
from rpdrill.studies.inputs.reading import read_yaml

ROOT = Path(__file__).resolve().parents[1]
RATE_ONLY = {"effects": {"rock_damping": True, "joint_damping": True},
             "outputs": {"metrics": ["penetration_rate_m_per_s"]}}


def measure(data: dict, repeats: int) -> tuple[int, float, float]:
    simulation = prepare(Scene.model_validate(data))
    runs = [run_simulation(simulation).raw for _ in range(repeats)]
    rate = summary_metrics(runs[0])["penetration_rate_m_per_s"]
    return build_exudyn(simulation).coordinate_count, statistics.median(r.cpu_time_s for r in runs), rate


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", nargs="?", default=ROOT / "studies" / "scenes" / "paper_base.yaml")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--end-time", type=float, default=1.0)
    args = parser.parse_args()
    full = read_yaml(args.scene)
    full.pop("effects", None)
    full.pop("outputs", None)
    full["solver"] = {**full.get("solver", {}), "end_time_s": args.end_time}
    lean = {**full, **RATE_ONLY}
    (n_full, cpu_full, rate_full), (n_lean, cpu_lean, rate_lean) = measure(full, args.repeats), measure(lean, args.repeats)
    print(f"scene {args.scene}, {args.end_time:g} s simulated, median of {args.repeats}")
    print("model                       coordinates  CPU s   CPU s per sim s  penetration rate [mm/s]")
    for label, n, cpu, rate in (("everything on", n_full, cpu_full, rate_full),
                                ("penetration-rate scan only", n_lean, cpu_lean, rate_lean)):
        print(f"{label:<28}{n:<13}{cpu:<8.3f}{cpu / args.end_time:<17.3f}{rate * 1e3:.9g}")
    print(f"CPU ratio full / lean: {cpu_full / cpu_lean:.2f}; "
          f"penetration rates differ by {abs(rate_full - rate_lean) / max(abs(rate_full), 1e-30):.1e} (relative)")


if __name__ == "__main__":
    main()
