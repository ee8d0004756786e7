"""The run-cost estimate of models.solvers.cost against measurement: steps, CPU time and memory.

Usage: python benchmarks/bench_budgets.py [--repeats N]

Prints (1) for the shipped scenes (paper_base 4 bodies, four_rod_string 19, wave_rod 64) with every
formulation that runs them: steps and CPU seconds, estimated and measured (the median of N runs
after a warm-up, one BLAS thread), and their ratio; the CPU cost per step a + b n^p (models.solvers.cost.CPU_S_PER_STEP) fitted to the
measurements of each formulation, and DOP853's steps per radian (steps / (r T), r the fastest
element's rate), the constants of models.solvers.cost; (2) for runs that store much (every step, or fine samples), the memory
estimate against the growth of the peak resident set during the run, each in a fresh process;
(3) what a command holds besides its runs (studies.runtime.budgets): a prepared study point (tracemalloc)
and the CPU time to prepare it, and a calibration's evaluation record of the shipped calibration.
"""

from __future__ import annotations

import os

# one BLAS thread, as in a study's workers (studies.runtime.pools.SINGLE_THREAD): set before NumPy loads
for _variable in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_variable, "1")

import argparse
import json
import statistics
import subprocess
import sys
import time
import tracemalloc
from pathlib import Path

import numpy as np
import pandas as pd

from rpdrill.models.definition.scene import Scene
from rpdrill.models.runs.scene_run import run as run_simulation
from rpdrill.models.solvers.cost import CPU_S_PER_STEP, Cause, cost_key, run_cost
from rpdrill.models.solvers.simulation import prepare, unsupported
from rpdrill.studies.calibration.calibration_search import target_result
from rpdrill.studies.calibration.calibration_spec import load_calibration
from rpdrill.studies.inputs.reading import load_scene
from rpdrill.studies.runtime.point_runs import prepare_point
from rpdrill.studies.scan.curves import CurveRun

ROOT = Path(__file__).resolve().parents[1]
SCENES = ROOT / "studies" / "scenes"
RATE_ONLY = {"metrics": ["penetration_rate_m_per_s"]}  # a scan's outputs: no energy works
# (scene, formulation, outputs): every output, and the exact formulation also as a scan runs it
RUNS = [(scene, formulation, outputs) for scene in ("paper_base", "four_rod_string", "wave_rod")
        for formulation, outputs in (("exudyn", None), ("exact", None), ("exact", RATE_ONLY), ("ode", None))]
# (scene, formulation, solver options): runs whose stored histories dominate their memory
MEMORY_RUNS = [
    ("paper_base", "exudyn", {"end_time_s": 8.0, "output_interval_s": 1e-5}),
    ("paper_base", "exact", {"end_time_s": 8.0, "output_interval_s": 1e-6}),
    ("paper_base", "ode", {"end_time_s": 2.0, "sample_interval_s": 2e-7}),
]


def simulation(scene: str, formulation: str, options: dict | None = None, outputs: dict | None = None):
    base = load_scene(SCENES / f"{scene}.yaml")
    return prepare((base.with_({"outputs": outputs}) if outputs else base).with_solver(formulation, **(options or {})))


def measured_steps(result) -> float:
    """Integration steps a run took: Exudyn's fixed steps, the exact sub-grid, the ODE's steps."""
    solver, end = result.solver, result.simulation.settings.end_time_s
    if result.formulation == "exact":
        return end / solver.sub_step_s
    if result.formulation == "ode":
        return solver.solver_steps
    return round(end / result.simulation.settings.step_s)


def cpu_table(repeats: int) -> None:
    print("scene            formulation           bodies  steps est / run       CPU s est / run")
    fits: dict[str, list[tuple[int, float]]] = {}
    radians = []
    measured = set()
    for scene, formulation, outputs in RUNS:
        if outputs is RATE_ONLY and (scene, "exact without energy") in measured:
            continue  # the scene's own outputs need no energy: its exact run was this one
        run = simulation(scene, formulation, outputs=outputs)
        key = cost_key(run)
        if unsupported(formulation, run):
            continue
        measured.add((scene, key))
        try:
            first = run_simulation(run).raw  # warm-up: the exact kernels compile, Exudyn loads
        except Exception as err:  # noqa: BLE001 - a formulation that fails on a scene is reported, not measured
            print(f"{scene:<17}{key:<22}{run.chain.size:<8}failed: {type(err).__name__}: {err}")
            continue
        steps = measured_steps(first)
        del first  # each result is dropped before the next run, as in a study
        cpu = statistics.median(run_simulation(run).raw.cpu_time_s for _ in range(repeats))
        cost, n = run_cost(run), run.chain.size
        fits.setdefault(key, []).append((n, cpu / steps))
        if formulation == "ode":
            radians.append(steps / (run.fastest.rate_per_s * run.settings.end_time_s))
        print(f"{scene:<17}{key:<22}{n:<8}{cost.steps:<9.3g}/ {steps:<9.3g}({cost.steps / steps:<5.2f})"
              f"{cost.cpu_s:<9.3g}/ {cpu:<9.3g}({cost.cpu_s / cpu:.2f})")
    for formulation, points in fits.items():
        bodies, per_step = np.array(points, dtype=float).T
        power = CPU_S_PER_STEP[formulation][2]
        slope, intercept = np.polyfit(bodies**power, per_step, 1) if len(points) > 1 else (0.0, per_step[0])
        print(f"{formulation}: CPU s per step = {intercept:.3g} + {slope:.3g} n" + (f"^{power}" if power != 1 else ""))
    if radians:
        print(f"ode: DOP853 steps per radian (r T) = {statistics.median(radians):.3g} "
              f"(range {min(radians):.3g} .. {max(radians):.3g})")


def peak_resident_bytes() -> int:
    """This process's peak resident set (VmHWM; ru_maxrss would carry the parent's peak across exec)."""
    line = next(line for line in Path("/proc/self/status").read_text().splitlines() if line.startswith("VmHWM:"))
    return int(line.split()[1]) * 1024


def child(scene: str, formulation: str, options: dict) -> None:
    """One run in this fresh process, its histories resampled and stacked as ``rpdrill simulate`` writes
    them: the memory estimate and the growth of the peak resident set."""
    run = simulation(scene, formulation, options)
    estimate = run_cost(run, Cause("solver.output_interval_s", run.settings.output_interval_s)).memory_bytes
    before = peak_resident_bytes()
    result = run_simulation(run).raw
    table = np.column_stack(list(result.resampled(run.settings.output_interval_s).values()))  # as rpdrill simulate
    grown = peak_resident_bytes() - before
    del table
    print(json.dumps({"estimate": estimate, "measured": grown, "samples": len(result.time_s)}))


def memory_table() -> None:
    print("\nscene            formulation  options                                           memory est / run [MB]")
    for scene, formulation, options in MEMORY_RUNS:
        warm = [sys.executable, __file__, "--child", scene, formulation, json.dumps({"end_time_s": 0.3})]
        subprocess.run(warm, check=True, capture_output=True)  # compiles and caches the kernels first
        done = subprocess.run([*warm[:-1], json.dumps(options)], check=True, capture_output=True, text=True)
        figures = json.loads(done.stdout)
        print(f"{scene:<17}{formulation:<13}{json.dumps(options):<50}{figures['estimate'] / 1e6:<8.0f}/ "
              f"{figures['measured'] / 1e6:<8.0f}({figures['estimate'] / figures['measured']:.2f})")


def held(make, count: int) -> tuple[float, float]:
    """(bytes held per object, CPU seconds to make one) of ``count`` objects ``make(i)``."""
    start = time.process_time()
    for i in range(count):
        make(i)
    cpu = (time.process_time() - start) / count
    tracemalloc.start()
    kept = [make(i) for i in range(count)]
    size = tracemalloc.get_traced_memory()[0] / count
    tracemalloc.stop()
    del kept
    return size, cpu


def held_table(count: int = 200) -> None:
    print("\nheld by a command                             kB each   CPU ms to make")
    for name in ("paper_base", "four_rod_string"):
        base = load_scene(SCENES / f"{name}.yaml")

        def point(i: int, base: Scene = base, name: str = name) -> object:
            return prepare_point(base, {"impact.frequency_hz": 40.0 + 0.01 * i}, name)

        size, cpu = held(point, count)
        print(f"prepared study point of {name:<22}{size / 1e3:<10.3g}{cpu * 1e3:.3g}")
    calibration = load_calibration(ROOT / "studies" / "paper" / "calibration.yaml")
    frequencies = list(calibration.frequencies_hz)
    curve = [float(np.exp(-((f - 60.0) / 15.0) ** 2)) for f in frequencies]

    metrics = sorted({calibration.metric(t) for t in range(len(calibration.labels))})
    table = pd.DataFrame({"impact.frequency_hz": frequencies, "status": "ok", "error": "", "wall_time_s": 0.0,
                          **dict.fromkeys(metrics, curve)})
    run = CurveRun(0, "impact.frequency_hz", table, 60.0, 0.0)

    def record(i: int) -> dict:
        unit = np.full(len(calibration.names), 0.5 + 1e-4 * i)
        return {"unit": list(unit), "parameters": calibration.values(unit),
                "targets": [target_result(calibration, t, run) for t in range(len(calibration.labels))]}

    size, _ = held(record, count)
    print(f"evaluation record of the shipped calibration  {size / 1e3:<10.3g}"
          f"({len(calibration.names)} parameters, {len(calibration.labels)} targets)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--child", nargs=3, metavar=("SCENE", "FORMULATION", "OPTIONS"), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        child(args.child[0], args.child[1], json.loads(args.child[2]))
        return
    cpu_table(args.repeats)
    memory_table()
    held_table()


if __name__ == "__main__":
    main()
