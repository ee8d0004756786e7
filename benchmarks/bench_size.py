"""Cost against the size of the drill string, for the Exudyn model and the exact formulation.

Usage: python benchmarks/bench_size.py [--segments 2,4,8,16,32] [--times 0.1,0.2,0.4] [--preset standard]
The four-rod top-hammer string (studies/scenes/four_rod_string.yaml) with every rod split into
``segments`` lumped masses (4 rods: 8 to 128 rod segments), crushing its rock at 50 Hz, only the
penetration rate asked for. For each string and simulated time: the bodies, the mode switches of
the exact solution, the CPU seconds of each formulation (one run after a warm-up run of the same
string; results dropped) and per simulated second, Exudyn's step and steps, the exact solver's
sub-step, operator keys (mode combination and pulse phase) and the memory of its operator arrays
(built from scratch in every run: the process's propagator cache is emptied first).
Then the growth exponents: the log-log slope of CPU per simulated second against the bodies.
"""

from __future__ import annotations

import os

# one BLAS thread, as in a study's workers (studies.runtime.pools.WORKER_ENVIRONMENT): set before NumPy loads
for _variable in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_variable, "1")

import argparse
import time
import warnings
from pathlib import Path

import numpy as np

from rpdrill.models.definition.scene import Scene
from rpdrill.models.runs.scene_run import run as run_simulation
from rpdrill.models.solvers.exact_model import BLAS, OPERATOR_CACHE, ExactSolver
from rpdrill.models.solvers.simulation import prepare
from rpdrill.studies.inputs.reading import read_yaml

SCENE = Path(__file__).resolve().parents[1] / "studies" / "scenes" / "four_rod_string.yaml"
RODS = ("rod1", "rod2", "rod3", "rod4")
OPERATOR_ARRAYS = ("taylor", "one_step", "anchors", "readout", "reset_rows")


def string_scene(segments: int, end_time_s: float, solver: dict[str, object]) -> Scene:
    data = read_yaml(SCENE)
    for rod in RODS:
        data["drill_string"]["bodies"][rod]["segments"] = segments
    data["metrics"] = {"transient_blows": 0, "block_blows": 1}
    data["outputs"] = {"metrics": ["penetration_rate_m_per_s"], "timeseries": []}
    data["solver"] = {"end_time_s": end_time_s, **solver}
    return Scene.model_validate(data)


def exact_run(scene: Scene) -> dict[str, float]:
    """The exact solution, with its operator arrays measured (the solver object kept for it); built from
    scratch (the process's propagator cache emptied: a run of a string, not a scan's later point)."""
    simulation = prepare(scene)
    OPERATOR_CACHE.clear()
    start = time.process_time()
    with BLAS.limit(limits=1, user_api="blas"):
        solver = ExactSolver(simulation)
        _, _, switch_times, _ = solver.run()
    cpu = time.process_time() - start
    operators = solver.operators
    cache = sum(getattr(operators, name)[:operators.built].nbytes for name in OPERATOR_ARRAYS)
    return {"cpu_s": cpu, "switches": len(switch_times), "sub_step_s": solver.step_s, "keys": operators.built,
            "cache_mb": cache / 1e6}


def exudyn_run(scene: Scene) -> dict[str, float]:
    simulation = prepare(scene)
    result = run_simulation(simulation).raw
    return {"cpu_s": result.cpu_time_s, "step_s": simulation.settings.step_s,
            "steps": round(scene.solver.end_time_s / simulation.settings.step_s)}


def slope(bodies: list[int], cost: list[float]) -> float:
    return float(np.polyfit(np.log(bodies), np.log(cost), 1)[0])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--segments", default="2,4,8,16,32", help="segments per rod (4 rods)")
    parser.add_argument("--times", default="0.1,0.2,0.4", help="simulated seconds")
    parser.add_argument("--preset", default="standard", help="Exudyn accuracy preset")
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    per_second: dict[str, dict[int, list[float]]] = {"exudyn": {}, "exact": {}}
    print(f"{'rod segs':<10}{'bodies':<8}{'sim s':<7}{'switches':<10}{'exact CPU s':<13}{'/ sim s':<10}"
          f"{'sub-step':<11}{'keys':<6}{'cache MB':<10}{'Exudyn CPU s':<14}{'/ sim s':<10}{'step':<11}steps")
    for segments in (int(s) for s in args.segments.split(",")):
        times = [float(t) for t in args.times.split(",")]
        exudyn_run(string_scene(segments, times[0], {"preset": args.preset}))  # warm-up
        exact_run(string_scene(segments, times[0], {"formulation": "exact"}))
        for end_time_s in times:
            exact = exact_run(string_scene(segments, end_time_s, {"formulation": "exact"}))
            exudyn = exudyn_run(string_scene(segments, end_time_s, {"preset": args.preset}))
            bodies = prepare(string_scene(segments, end_time_s, {"formulation": "exact"})).chain.size
            per_second["exact"].setdefault(bodies, []).append(exact["cpu_s"] / end_time_s)
            per_second["exudyn"].setdefault(bodies, []).append(exudyn["cpu_s"] / end_time_s)
            print(f"{4 * segments:<10}{bodies:<8}{end_time_s:<7g}{exact['switches']:<10}{exact['cpu_s']:<13.3f}"
                  f"{exact['cpu_s'] / end_time_s:<10.3f}{exact['sub_step_s']:<11.3g}{exact['keys']:<6}"
                  f"{exact['cache_mb']:<10.1f}{exudyn['cpu_s']:<14.3f}{exudyn['cpu_s'] / end_time_s:<10.3f}"
                  f"{exudyn['step_s']:<11.3g}{exudyn['steps']}")
    for formulation, costs in per_second.items():
        bodies = sorted(costs)
        longest = [costs[b][-1] for b in bodies]  # the longest simulated time: start-up costs amortized
        print(f"{formulation}: CPU per simulated second grows as bodies^{slope(bodies, longest):.2f} "
              f"(log-log slope over {bodies[0]}..{bodies[-1]} bodies, longest run)")
    ratio = [per_second["exudyn"][b][-1] / per_second["exact"][b][-1] for b in sorted(per_second["exact"])]
    print("Exudyn / exact CPU per simulated second: " + ", ".join(
        f"{b} bodies {r:.2g}" for b, r in zip(sorted(per_second["exact"]), ratio, strict=True)))
    crossing = [b for b, r in zip(sorted(per_second["exact"]), ratio, strict=True) if r < 1]
    print(f"Exudyn cheaper than exact from {crossing[0]} bodies on" if crossing else
          "exact cheaper at every size measured")


if __name__ == "__main__":
    main()
