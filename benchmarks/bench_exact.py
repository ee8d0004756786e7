"""Cost and x_n accuracy of the three formulations, measured in one run.

For each scene: CPU seconds per simulated second and the x_n error of the exact event-driven
solution (models.solvers.exact_model, default settings: every output asked for, its works integrated
exactly from the propagators; and with only the penetration rate asked for; samples every 1e-4 s
either way), with the CPU seconds of the metrics of the last exact result, the
Exudyn model at the scene's solver setting and the SciPy ODE formulation (DOP853, rtol 1e-8), all
against the exact solution on a finer grid (samples and sub-step 1e-6 s; the exact run's own
difference to it is round-off). The error is max |x_n - x_n,ref| over the blow starts divided by
|x_n,ref| at the end, and absolute. The exact runs are timed after a warm-up call (median of
``--repeats`` runs), each with the propagator cache (models.solvers.exact_model.OPERATOR_CACHE) emptied first,
and again reusing the propagators of the run before (a scan's later points); the compile time of the numba kernels (models.solvers.exact_kernels) is measured
separately, in a fresh process with an empty numba cache, and the first call with a warm cache.

Usage: python benchmarks/bench_exact.py [--end-time-s 0.5] [--repeats 9]
BLAS is limited to one thread before NumPy is imported: the exact model's few small matrix
products and expm calls take milliseconds each with a threaded OpenBLAS on a shared 2-core machine.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse
import copy
import math
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from functools import partial
from pathlib import Path

import numpy as np

from rpdrill.models.definition.scene import Scene
from rpdrill.models.evaluation.metrics import summary_metrics
from rpdrill.models.evaluation.results import SimulationResult
from rpdrill.models.runs.scene_run import run as run_simulation
from rpdrill.models.solvers.exact_model import OPERATOR_CACHE
from rpdrill.models.solvers.simulation import prepare
from rpdrill.models.solvers.time_run import time_run
from rpdrill.studies.inputs.reading import read_yaml

ROOT = Path(__file__).resolve().parents[1]
BASE = ROOT / "studies" / "scenes" / "paper_base.yaml"
CRUSHING = {"amplitude_n": 400e3, "frequency_hz": 45.0}
RATE_ONLY = {"metrics": ["penetration_rate_m_per_s"]}
# First exact run in a fresh process: CPU seconds (compiling or loading the kernels).
FIRST_CALL = """
import os, sys, time
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
sys.path.insert(0, {benchmarks!r})
from bench_exact import scenes
from rpdrill.models.solvers.simulation import prepare
from rpdrill.models.runs.scene_run import run
simulation = prepare(scenes(0.5)["paper_base"].with_solver("exact"))
start = time.process_time()
run(simulation)
print(time.process_time() - start)
"""


def scenes(end_time_s: float, outputs: dict | None = None) -> dict[str, Scene]:
    """paper_base and its crushing variant (400 kN at 45 Hz), ``end_time_s`` long, with ``outputs``
    (None: the scene file's, every output)."""
    base = read_yaml(BASE)
    base["solver"]["end_time_s"] = end_time_s
    base["metrics"] = {"transient_blows": 0, "block_blows": 1}
    if outputs is not None:
        base["outputs"] = outputs
    crushing = copy.deepcopy(base) | {"name": "paper_base_crushing"}
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


def timed(run: Callable[[], SimulationResult], repeats: int, cold: bool = False) -> tuple[SimulationResult, float]:
    """The last result and the median CPU time of ``repeats`` runs, each result dropped before the next
    run as in a study (a kept result pins its sample arrays, and the next run's fresh memory costs
    page faults: ~20 ms for the 7 MB of a 0.5 s run at 1e-5 s samples on the shared VM). ``cold``: the
    exact solver's propagator cache emptied before each run (a run as a user starts it; otherwise each
    run reuses the propagators of the one before, as a scan's later points do)."""
    times = []
    for _ in range(repeats):
        if cold:
            OPERATOR_CACHE.clear()
        result = run()
        times.append(result.cpu_time_s)
    return result, statistics.median(times)


def first_call_cpu_s(cache_dir: str | None) -> float:
    """CPU seconds of the first exact run in a fresh process (``cache_dir``: an empty numba
    cache, so the kernels compile; None: the project's cache)."""
    env = os.environ | {"PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
    if cache_dir:
        env["NUMBA_CACHE_DIR"] = cache_dir
    code = FIRST_CALL.format(benchmarks=str(ROOT / "benchmarks"))
    output = subprocess.run([sys.executable, "-c", code], env=env, check=True, capture_output=True, text=True)
    return float(output.stdout.split()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--end-time-s", type=float, default=0.5)
    parser.add_argument("--repeats", type=int, default=9, help="timed runs of each exact setting (median)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as empty:
        compile_s = first_call_cpu_s(empty)
    warm_s = first_call_cpu_s(None)
    print(f"exact, first call in a fresh process: {compile_s:.1f} CPU s with an empty numba cache (compiling), "
          f"{warm_s:.2f} CPU s with the cache")
    print("scene                 formulation                  CPU s / sim s   x_n rel. error   abs. [m]   x_n(end) [mm]")
    lean = scenes(args.end_time_s, RATE_ONLY)
    for name, scene in scenes(args.end_time_s).items():
        reference = run_simulation(prepare(scene.with_solver("exact", sample_interval_s=scene.solver.output_interval_s / 100))).raw
        exudyn = prepare(scene)
        runs = {  # each the formulation's time run of its prepared scene (a SimulationResult)
            "exact (default)": partial(time_run, prepare(scene.with_solver("exact"))),
            "exact (rate only)": partial(time_run, prepare(lean[name].with_solver("exact"))),
            f"exudyn {exudyn.settings.type} {exudyn.settings.step_s:.3g} s": partial(time_run, exudyn),
            "ode DOP853 rtol 1e-8": partial(time_run, prepare(scene.with_solver("ode", relative_tolerance=1e-8,
                                                                               absolute_tolerance=1e-11))),
        }
        for label, run in runs.items():
            exact = label.startswith("exact")
            if exact:
                run()  # warm-up
                warm = timed(run, args.repeats)[1]
            result, cpu = timed(run, args.repeats if exact else 1, cold=exact)
            error = blow_start_error(result, reference)
            print(f"{name:<21} {label:<28} {cpu / args.end_time_s:<15.4f} {error:<16.2e} "
                  f"{error * abs(reference.bottom_m[-1]):<10.1e} {result.bottom_m[-1] * 1e3:.9f}")
            if exact:
                start = time.process_time()
                summary_metrics(result)
                metrics_s = (time.process_time() - start) / args.end_time_s
                print(f"{'':<24}({result.solver.mode_switches} switches, {result.solver.samples} samples, "
                      f"every {result.solver.sample_interval_s:.0e} s; its metrics: {metrics_s:.4f} CPU s / sim s; "
                      f"with the propagators of a run before: {warm / args.end_time_s:.4f} CPU s / sim s)")
            del result
        print(f"{name:<21} reference: exact, sub-step {reference.solver.sub_step_s:.3g} s")

if __name__ == "__main__":
    main()
