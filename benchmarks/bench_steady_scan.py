"""The paper's frequency scan at 1 Hz steps: by continuation of periodic orbits against 1.5 s time runs.

Usage: python benchmarks/bench_steady_scan.py [--formulation exact|exudyn] [--step 1] [--repeats 3]

Side by side in one run (the machine is shared): studies/paper/frequency_scan.yaml's base scene and metrics,
its frequency axis (10-120 Hz) every ``--step`` Hz, scanned as the calibration and the reproduction scan
(studies.scan.curves.run_curve: one worker, each point made, prepared, run and its metrics taken) once
with ``solver.steady_state: time`` (the 1.5 s runs of the study) and once with ``periodic`` (each orbit's
Newton from its neighbours': models.steady.continuation). Prints the CPU seconds of each (the median of
``--repeats``), their ratio, each metric's main-lobe optimum (studies.scan.curve_optima) by both, and the
largest difference of the rate between the two (the time runs' transient).
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import numpy as np

import rpdrill
from rpdrill.studies.scan.curves import Curve, run_curve

ROOT = Path(__file__).resolve().parents[1]
OPTIMA = ("penetration_rate_m_per_s", "bit_velocity_peak_m_per_s", "collar_velocity_peak_m_per_s",
          "energy_transfer_efficiency")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--formulation", default="exact", choices=("exact", "exudyn"))
    parser.add_argument("--step", type=float, default=1.0)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    study = rpdrill.load_study(ROOT / "studies" / "paper" / "frequency_scan.yaml")
    metrics = list(study.spec.metrics)
    frequencies = [float(f) for f in np.arange(10.0, 120.0 + 1e-9, args.step)]
    scans, cpu = {}, {}
    for variant in ("time", "periodic"):
        scene = study.points[0].simulation.scene.with_solver(args.formulation, steady_state=variant)
        run_curve(Curve("warm", scene, {}, tuple(frequencies[:2]), tuple(metrics)))  # kernels and caches loaded first
        times = []
        for _ in range(args.repeats):
            start = time.process_time()
            scans[variant] = run_curve(Curve(variant, scene, {}, tuple(frequencies), tuple(metrics)))
            times.append(time.process_time() - start)
        cpu[variant] = statistics.median(times)
        print(f"{variant}: {len(frequencies)} points, CPU {cpu[variant]:.3f} s (median of {args.repeats}: "
              f"{', '.join(f'{t:.3f}' for t in times)}), failed runs {scans[variant].failed_runs}")
    print(f"CPU ratio time runs / continuation ({args.formulation}): {cpu['time'] / cpu['periodic']:.2f}")
    for metric in OPTIMA:
        optima = [scans[v].optimum(metric).optimum for v in ("time", "periodic")]
        shift = None if None in optima else optima[1] - optima[0]
        print(f"{metric}: main-lobe optimum {optima[0]} Hz by time runs, {optima[1]} Hz by continuation"
              + ("" if shift is None else f" ({shift:+.3f} Hz)"))
    rates = [np.array(scans[v].values("penetration_rate_m_per_s")) for v in ("time", "periodic")]
    drilling = rates[1] > 0
    moved = np.abs(rates[0][drilling] - rates[1][drilling]) / rates[1][drilling]
    worst = int(np.argmax(moved))
    print(f"penetration rate, time runs against the steady state: largest relative difference {moved[worst]:.3g} "
          f"at {np.array(frequencies)[drilling][worst]:g} Hz, median {np.median(moved):.3g}")


if __name__ == "__main__":
    main()
