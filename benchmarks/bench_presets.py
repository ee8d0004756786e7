"""The Exudyn accuracy presets against their targets, measured in one run.

Usage: python benchmarks/bench_presets.py [--repeats N] [--presets fast,standard,reference]
Prints, for each preset of models.solver_settings: its solver and step on the shipped paper scene,
the CPU seconds per simulated second there (1 s simulated, every output, median of N runs after a
warm-up, results dropped between runs), and on the paper scene and every hard scene of
tests/stability/hard_scenes.py (the frozen test drill varied) the penetration-rate error against the
exact formulation and the energy-balance error; then the largest errors over the scenes against
what the preset states, and the cost against the issue's targets (fast 0.05, standard 0.1).
"""

from __future__ import annotations

import os

# one BLAS thread, as in a study's workers (studies.runners.SINGLE_THREAD): set before NumPy loads
for _variable in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_variable, "1")

import argparse
import statistics
import sys
import warnings
from pathlib import Path

from rpdrill.models.metrics import summary_metrics
from rpdrill.models.scene import Scene
from rpdrill.models.simulation import prepare
from rpdrill.models.solver_settings import EXUDYN_PRESETS
from rpdrill.studies.loading import load_scene

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))  # the hard scenes of the stability suite
from stability.hard_scenes import HARD_SCENES, hard_scene

COST_TARGETS = {"fast": 0.05, "standard": 0.1}


def rate_error(metrics: dict[str, float], exact: dict[str, float]) -> float:
    reference = exact["penetration_rate_m_per_s"]
    return abs(metrics["penetration_rate_m_per_s"] - reference) / max(abs(reference), 1e-9)


def cost(scene: Scene, repeats: int) -> float:
    simulation = prepare(scene)
    simulation.run()  # warm-up
    runs = []
    for _ in range(repeats):
        runs.append(simulation.run().cpu_time_s)  # the result is dropped at once
    return statistics.median(runs) / scene.solver.end_time_s


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--presets", default=",".join(EXUDYN_PRESETS))
    args = parser.parse_args()
    warnings.simplefilter("ignore")  # step-limit warnings of the explicit solvers: errors are measured
    scenes = {"paper_base": load_scene(ROOT / "studies" / "scenes" / "paper_base.yaml")}
    scenes.update({name: hard_scene(overrides) for name, overrides in HARD_SCENES.items()})
    exact = {name: summary_metrics(prepare(scene.with_solver("exact")).run()) for name, scene in scenes.items()}
    for preset in args.presets.split(","):
        stated = EXUDYN_PRESETS[preset]
        paper = scenes["paper_base"].with_solver("exudyn", preset=preset)
        settings = prepare(paper).settings
        per_second = cost(paper, args.repeats)
        print(f"\npreset {preset}: {settings.type}, step {settings.step_s:.3g} s on paper_base; "
              f"{per_second:.4f} CPU s per simulated s (median of {args.repeats})"
              + (f", target {COST_TARGETS[preset]}: ratio {per_second / COST_TARGETS[preset]:.2f}"
                 if preset in COST_TARGETS else ""))
        print(f"  {'scene':<28}{'step [s]':<12}{'rate error':<14}{'energy error':<14}CPU s / sim s")
        worst = {"rate": 0.0, "energy": 0.0}
        for name, scene in scenes.items():
            simulation = prepare(scene.with_solver("exudyn", preset=preset))
            result = simulation.run()
            metrics = summary_metrics(result)
            error, energy = rate_error(metrics, exact[name]), metrics["energy_balance_relative_error"]
            worst = {"rate": max(worst["rate"], error), "energy": max(worst["energy"], energy)}
            print(f"  {name:<28}{simulation.settings.step_s:<12.3g}{error:<14.2e}{energy:<14.2e}"
                  f"{result.cpu_time_s / scene.solver.end_time_s:.4f}")
        print(f"  largest: rate {worst['rate']:.2e} (stated {stated.penetration_rate_error:g}), energy "
              f"{worst['energy']:.2e} (stated {stated.energy_balance_error:g})")


if __name__ == "__main__":
    main()
