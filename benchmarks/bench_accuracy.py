"""What accuracy costs: CPU seconds per simulated second of each accuracy preset (Exudyn), and the
CPU-time ratio Exudyn model : ODE formulation at equal error.

Usage: python benchmarks/bench_accuracy.py [STUDY.yaml] [--level 1e-4 1e-6 1e-8] [--repeats N] [--seconds S]

Everything is measured in this one run (the machine is shared): each preset runs the study's
base scene for ``--seconds`` simulated seconds; the ratio interpolates (log-log) the Pareto fronts
of the study's Exudyn families (all fixed-step and automatic Exudyn solvers) and of its DOP853 ODE
family at each penetration-rate error ``--level``, on the study's window against its reference.
"""

from __future__ import annotations

import argparse
import itertools
import math
import statistics
import warnings
from dataclasses import replace
from pathlib import Path

from rpdrill.models.definition.scene import Scene
from rpdrill.models.evaluation.solver_settings import EXUDYN_PRESETS
from rpdrill.models.evaluation.workprecision import errors, pareto_front
from rpdrill.models.runs.scene_run import run as run_simulation
from rpdrill.models.solvers.simulation import prepare
from rpdrill.studies.accuracy.accuracy_study import load_accuracy_study, reference_signature, run_setting

ROOT = Path(__file__).resolve().parents[1]
MEASURE = "penetration_rate_error_rel"


def cost_at_error(cost: list[float], error: list[float], level: float) -> float:
    """CPU cost at which the Pareto front of (cost, error) reaches ``level``, log-log interpolated
    between the neighbouring front points; NaN if the front does not bracket ``level``."""
    front = pareto_front(cost, error)
    points = [(math.log(error[i]), math.log(cost[i])) for i in front if error[i] > 0 and cost[i] > 0]
    target = math.log(level)
    for (e0, c0), (e1, c1) in itertools.pairwise(points):
        if e1 <= target <= e0:
            return math.exp(c0 + (c1 - c0) * (target - e0) / (e1 - e0)) if e0 != e1 else math.exp(c0)
    return math.nan


def preset_cost(base: Scene, preset: str, seconds: float, repeats: int) -> tuple[float, float]:
    """(CPU s per simulated s, step) of the base scene run with ``preset`` for ``seconds``."""
    simulation = prepare(base.with_({"solver": {"formulation": "exudyn", "preset": preset, "end_time_s": seconds},
                                     "outputs": {"metrics": ["penetration_rate_m_per_s"],
                                                 "timeseries": ["borehole_bottom_m"]}}))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        runs = [run_simulation(simulation).raw.cpu_time_s for _ in range(repeats)]
    return statistics.median(runs) / seconds, simulation.settings.step_s


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("study", nargs="?", default=ROOT / "studies" / "accuracy_studies" / "paper_base.yaml")
    parser.add_argument("--level", type=float, nargs="+", default=[1e-4, 1e-6, 1e-8],
                        help="penetration-rate errors at which the ratio is taken")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--seconds", type=float, default=1.0, help="simulated seconds per preset run")
    args = parser.parse_args()
    study = load_accuracy_study(args.study)
    reference = reference_signature(study, study.reference)
    print(f"study {study.spec.name}: {study.spec.blows} blows, reference {study.reference.solver}")

    print("\npreset     step [s]   CPU s / simulated s   penetration-rate error (window)")
    presets = [(p, r) for p, r in zip(study.points, study.runs) if r.solver.get("preset")]
    for _, run in presets:
        outcome = run_setting((study.scene, replace(run, repeats=args.repeats), study.spec.grid_interval_s,
                               study.spec.time_limit_s))
        error = errors(reference, outcome["signature"])[MEASURE] if outcome["status"] == "ok" else float("nan")
        per_second, step = preset_cost(study.base, run.solver["preset"], args.seconds, args.repeats)
        print(f"{run.solver['preset']:<10} {step:<10.3g} {per_second:<21.4g} {error:.3g}")
    missing = set(EXUDYN_PRESETS) - {r.solver["preset"] for _, r in presets}
    if missing:
        print(f"(presets not in the study: {', '.join(sorted(missing))})")

    groups = {"exudyn": [], "ode": []}
    for run in study.runs:
        if run.solver.get("preset") or (run.formulation == "ode" and run.solver.get("method") != "DOP853"):
            continue
        if run.formulation not in groups:
            continue
        outcome = run_setting((study.scene, replace(run, repeats=args.repeats), study.spec.grid_interval_s,
                               study.spec.time_limit_s))
        if outcome["status"] == "ok":
            groups[run.formulation].append((outcome["cpu_time_s"], errors(reference, outcome["signature"])[MEASURE]))
    print("\nCPU time of the window at equal penetration-rate error (Pareto fronts, log-log interpolated):")
    print("error level   Exudyn model [s]   ODE DOP853 [s]   ratio Exudyn : ODE")
    for level in args.level:
        cost = {name: cost_at_error([c for c, _ in pairs], [e for _, e in pairs], level)
                for name, pairs in groups.items()}
        print(f"{level:<13g} {cost['exudyn']:<18.4g} {cost['ode']:<16.4g} {cost['exudyn'] / cost['ode']:.3g}")

if __name__ == "__main__":
    main()
