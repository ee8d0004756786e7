"""The steady-state solver against settled time runs on every point of the three paper scans.

Usage: python benchmarks/bench_steady_accuracy.py [--settle 1e-9] [--exudyn [PRESET ...]] [--no-exact]

For every point of studies/paper/frequency_scan.yaml, impulse_scan.yaml and stiffness_scan.yaml (the
exact formulation): the regime (models.steady.regimes.steady_state) and, at every stable period-1 point, the
orbit's advance per blow against the last blow of an exact time run from the scene's start whose advance
per blow has settled to ``--settle`` (relative change between its last two blows; the run doubles from
400 blows until it has). Prints the regimes found, the largest relative difference and where, and the
CPU seconds of both. ``--exudyn``: also shoots every point of the frequency scan with the Exudyn formulation
at each PRESET (default standard) and prints the largest relative difference of its orbit's rate from the
exact orbit's, and of its 1.5 s time run's rate from the exact 1.5 s run's (the preset's own error on this
scene), against the preset's stated error. ``--no-exact``: the Exudyn part only.
"""

from __future__ import annotations

import argparse
import time
from collections import Counter
from pathlib import Path

import numpy as np

import rpdrill
from rpdrill.models.evaluation.metrics import summary_metrics
from rpdrill.models.evaluation.solver_settings import EXUDYN_PRESETS
from rpdrill.models.runs.scene_run import run as run_simulation
from rpdrill.models.solvers.simulation import prepare
from rpdrill.models.steady.regimes import steady_state

ROOT = Path(__file__).resolve().parents[1]
SCANS = ("frequency_scan", "impulse_scan", "stiffness_scan")


def settled_advance(scene: rpdrill.Scene, settle: float) -> tuple[float, int]:
    """(advance per blow of the last blow, blows run) of an exact time run settled to ``settle``."""
    frequency = scene.impact.frequency_hz
    blows = 400
    while True:
        run = run_simulation(prepare(scene.with_({"solver.end_time_s": blows / frequency, "solver.steady_state": "time",
                                   "outputs": {"metrics": ["penetration_rate_m_per_s"]}}))).raw
        advances = np.diff(run.bottom_at(np.arange(blows - 2, blows + 1) / frequency))
        if abs(advances[-1] - advances[-2]) <= settle * abs(advances[-1]) or blows >= 25600:
            return float(advances[-1]), blows
        blows *= 2


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--settle", type=float, default=1e-9)
    parser.add_argument("--exudyn", nargs="*", choices=tuple(EXUDYN_PRESETS), default=None)
    parser.add_argument("--no-exact", action="store_true")
    args = parser.parse_args()
    if not args.no_exact:
        exact_points(args.settle)
    for preset in ([] if args.exudyn is None else args.exudyn or ["standard"]):
        exudyn_points(preset)


def exact_points(settle: float) -> None:
    """The exact formulation's orbits against settled time runs (module doc)."""
    worst, regimes, cpu_steady, cpu_long, drilling = (0.0, ""), Counter(), 0.0, 0.0, 0
    for name in SCANS:
        study = rpdrill.load_study(ROOT / "studies" / "paper" / f"{name}.yaml", formulation="exact")
        for point in study.points:
            scene = point.simulation.scene
            start = time.process_time()
            state = steady_state(prepare(scene))
            cpu_steady += time.process_time() - start
            regimes[state.regime] += 1
            if state.regime != "period-1":
                print(f"{name} {point.parameters}: {state.regime} ({state.note})")
                continue
            start = time.process_time()
            limit, blows = settled_advance(scene, settle)
            cpu_long += time.process_time() - start
            advance = state.orbit.advance_per_blow_m
            if limit == 0.0 and advance == 0.0:
                continue
            drilling += 1
            difference = abs(advance - limit) / abs(limit)
            if difference > worst[0]:
                worst = (difference, f"{name} {point.parameters} ({blows} blows)")
    print(f"regimes: {dict(regimes)}; {drilling} drilling period-1 points")
    print(f"largest relative difference, steady-state advance per blow against a time run settled to "
          f"{settle:g}: {worst[0]:.3g} at {worst[1]}")
    print(f"CPU: steady states {cpu_steady:.2f} s, settled time runs {cpu_long:.2f} s")


def exudyn_points(preset: str) -> None:
    """The Exudyn formulation's shooting at ``preset`` against the exact orbits (module doc)."""
    stated = EXUDYN_PRESETS[preset].penetration_rate_error
    largest, where, own = 0.0, "", 0.0
    study = rpdrill.load_study(ROOT / "studies" / "paper" / "frequency_scan.yaml")
    for point in study.points:
        scene = point.simulation.scene.with_({"solver.preset": preset,
                                              "outputs": {"metrics": ["penetration_rate_m_per_s"]}})
        periodic = scene.with_({"solver.steady_state": "periodic"})
        exudyn = run_simulation(prepare(periodic)).metrics["penetration_rate_m_per_s"]
        exact = run_simulation(prepare(periodic.with_solver("exact"))).metrics["penetration_rate_m_per_s"]
        difference = abs(exudyn - exact) / abs(exact)
        if difference > largest:
            largest, where = difference, str(point.parameters)
        runs = [summary_metrics(run_simulation(prepare(s)).raw)["penetration_rate_m_per_s"] for s in (scene, scene.with_solver("exact"))]
        own = max(own, abs(runs[0] - runs[1]) / abs(runs[1]))
    print(f"Exudyn ({preset} preset) shooting against the exact orbit, frequency scan: largest relative difference "
          f"in the rate {largest:.3g} at {where}; its 1.5 s time runs against the exact ones: {own:.3g} (stated "
          f"error of the preset: {stated:g})")

if __name__ == "__main__":
    main()
