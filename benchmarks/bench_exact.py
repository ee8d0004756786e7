"""Cost and x_n accuracy of the three formulations, measured in one run.

For each scene: CPU seconds per simulated second and the x_n error of the exact event-driven
solution (models.exact_model, default settings), the Exudyn model at the scene's solver setting
and the SciPy ODE formulation (DOP853, rtol 1e-8), all against the exact solution on a finer grid
(samples and sub-step 1e-6 s instead of 1e-4 s and 1.4e-5 s; the exact run's own difference to it
is round-off). The error is max |x_n - x_n,ref| over the blow starts divided by |x_n,ref| at the
end, and absolute.

Usage: python benchmarks/bench_exact.py [--end-time-s 0.5] [--repeats 3]
BLAS is limited to one thread before NumPy is imported: the exact model's few 11 x 11 expm calls
take milliseconds each with a threaded OpenBLAS on a shared 2-core machine instead of ~0.05 ms.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse
import math
import statistics
from collections.abc import Callable
from pathlib import Path

import numpy as np
import yaml

from models.exact_model import simulate_exact
from models.exudyn_model import simulate_exudyn
from models.ode_model import simulate_ode
from models.results import SimulationResult
from models.scene import Scene

BASE = Path(__file__).resolve().parents[1] / "studies" / "scenes" / "paper_base.yaml"
CRUSHING = {"amplitude_n": 400e3, "frequency_hz": 45.0}


def scenes(end_time_s: float) -> dict[str, Scene]:
    """paper_base and its crushing variant (400 kN at 45 Hz), ``end_time_s`` long."""
    base = yaml.safe_load(BASE.read_text(encoding="utf-8"))
    base["solver"]["end_time_s"] = end_time_s
    base["metrics"] = {"transient_blows": 0, "block_blows": 1}
    crushing = yaml.safe_load(yaml.safe_dump(base)) | {"name": "paper_base_crushing"}
    crushing["impact"].update(CRUSHING)
    return {data["name"]: Scene.model_validate(data) for data in (base, crushing)}


def blow_start_error(result: SimulationResult, reference: SimulationResult) -> float:
    """max over blow starts of |x_n - x_n,ref|, relative to |x_n,ref(end)|."""
    period = reference.scene.impact.period_s
    times = np.arange(1, math.floor(reference.time_s[-1] / period + 1e-9) + 1) * period

    def held(r: SimulationResult) -> np.ndarray:
        index = np.searchsorted(r.time_s, times + 1e-12, side="right") - 1
        return r.bottom_m[index]

    return float(np.max(np.abs(held(result) - held(reference))) / abs(reference.bottom_m[-1]))


def timed(run: Callable[[], SimulationResult], repeats: int) -> tuple[SimulationResult, float]:
    """The last result and the median CPU time of ``repeats`` runs."""
    results = [run() for _ in range(repeats)]
    return results[-1], statistics.median(r.cpu_time_s for r in results)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--end-time-s", type=float, default=0.5)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    print("scene                 formulation                  CPU s / sim s   x_n rel. error   abs. [m]   x_n(end) [mm]")
    for name, scene in scenes(args.end_time_s).items():
        reference = simulate_exact(scene, sample_interval_s=scene.solver.output_interval_s / 100)
        runs = {
            "exact (default)": lambda scene=scene: simulate_exact(scene),
            f"exudyn {scene.solver.type} {scene.solver.step_s:g} s": lambda scene=scene: simulate_exudyn(scene),
            "ode DOP853 rtol 1e-8": lambda scene=scene: simulate_ode(scene, rtol=1e-8, atol=1e-11),
        }
        for label, run in runs.items():
            result, cpu = timed(run, args.repeats if label.startswith("exact") else 1)
            error = blow_start_error(result, reference)
            print(f"{name:<21} {label:<28} {cpu / args.end_time_s:<15.4f} {error:<16.2e} "
                  f"{error * abs(reference.bottom_m[-1]):<10.1e} {result.bottom_m[-1] * 1e3:.9f}")
        print(f"{name:<21} reference: exact, sub-step {reference.info['sub_step_s']:.3g} s, "
              f"{reference.info['mode_switches']} switches")


if __name__ == "__main__":
    main()
