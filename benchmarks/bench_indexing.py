"""What bit indexing costs: the same scene with the indexing effect off and on (a prescribed rotation
speed; the DTH bit of studies/rotation/), per formulation. With indexing on, every blow start stops
the event loop (exact), splits a segment (ODE) or runs a reset in the pre-step hook (Exudyn).

Usage: python benchmarks/bench_indexing.py [SCENE.yaml] [--repeats N] [--end-time S] [--rpm N]
                                           [--formulations exact,exudyn,ode]
Prints medians of N repeats (CPU s, measured in one run), the ratio on / off, and both penetration rates.
"""

from __future__ import annotations

import argparse
import statistics
from pathlib import Path

from rpdrill.models.definition.scene import Scene
from rpdrill.models.evaluation.metrics import summary_metrics
from rpdrill.models.runs.scene_run import run as run_simulation
from rpdrill.models.solvers.simulation import prepare
from rpdrill.studies.inputs.reading import read_yaml

ROOT = Path(__file__).resolve().parents[1]
BIT = {"diameter_m": 0.216, "gauge_button_diameter_m": 0.019, "gauge_buttons": 12}
RATE_ONLY = {"outputs": {"metrics": ["penetration_rate_m_per_s"]}}


def measure(data: dict, repeats: int) -> tuple[float, float]:
    """(median CPU s, penetration rate) of ``repeats`` runs."""
    simulation = prepare(Scene.model_validate(data))
    runs = [run_simulation(simulation).raw for _ in range(repeats)]
    return statistics.median(r.cpu_time_s for r in runs), summary_metrics(runs[0])["penetration_rate_m_per_s"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", nargs="?", default=ROOT / "studies" / "scenes" / "paper_base.yaml")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--end-time", type=float, default=1.0)
    parser.add_argument("--rpm", type=float, default=45.0)
    parser.add_argument("--formulations", default="exact,exudyn")
    args = parser.parse_args()
    base = read_yaml(args.scene)
    base.pop("effects", None)
    base.update(RATE_ONLY, bit=BIT, rotation={"speed_rpm": args.rpm})
    print(f"scene {args.scene}, {args.end_time:g} s simulated, {args.rpm:g} rpm, median of {args.repeats}")
    print("formulation  CPU s off  CPU s on  on / off  rate off [mm/s]  rate on [mm/s]")
    for formulation in args.formulations.split(","):
        solver = {"formulation": formulation, "end_time_s": args.end_time}
        cases = [{**base, "solver": solver, "effects": {"rock_damping": True, "joint_damping": True, "indexing": on}}
                 for on in (False, True)]
        (cpu_off, rate_off), (cpu_on, rate_on) = (measure(case, args.repeats) for case in cases)
        print(f"{formulation:<13}{cpu_off:<11.4f}{cpu_on:<10.4f}{cpu_on / cpu_off:<10.2f}{rate_off * 1e3:<17.6g}"
              f"{rate_on * 1e3:.6g}")


if __name__ == "__main__":
    main()
