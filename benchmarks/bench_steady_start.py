"""Where the drill goes from its scene's start beside the orbits continuation follows (models.steady.start_check).

Usage: python benchmarks/bench_steady_start.py [--parts window,cost] [--repeats 3] [--formulation exact|exudyn]

* window: the test drill of docs/steady_state.md (tests/test_drill.yaml at 400 kN on a 2 kN s/m shock absorber,
  exact) every 0.25 Hz from 28.5 to 31.5 Hz: the regime the continuation finds up and down the axis
  (models.steady.continuation through models.runs.scene_run.run) and where the drill goes from its
  start (``start_regime``), then at 30.25-31.25 Hz what exact time runs of 400 and 1000 blows from the start show:
  the period that repeats best over their last 13 blow starts (and its scaled distance) and the advance and peak
  rock force of their last 6 blows.
* cost: the paper's frequency scan (studies/paper/frequency_scan.yaml's scene and metrics, ``--formulation``
  (exact; exudyn: the check runs on the exact model that guides it), 10-120 Hz every 1 Hz, by continuation up the axis as a continuation study's chain runs it: studies.runtime.point_runs.run_followed)
  with the check and without it: CPU seconds (median of ``--repeats``), the check's own CPU and the blows it ran.
  (The scans of calibrate, sensitivity, advise and reproduce, read for their optima, leave the check out.)
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
from pathlib import Path

import numpy as np

import rpdrill
from rpdrill.models.runs.scene_run import run
from rpdrill.models.solvers.simulation import prepare
from rpdrill.models.steady import regimes
from rpdrill.models.steady.continuation import Continuation, branch_point
from rpdrill.models.steady.exact_map import exact_period_map
from rpdrill.models.steady.regimes import MAX_PERIOD_BLOWS, repeating_period, start_state
from rpdrill.studies.runtime.point_runs import run_followed
from rpdrill.studies.scan.bifurcation_diagram import _scene, blow_figures

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
from scenes import scene  # the frozen test drill

TEST_DRILL = scene().with_solver("exact").with_({"impact.amplitude_n": 400e3, "solver.end_time_s": 1.5,
                                                 "drill_string.connectors.shock_absorber.damping_n_s_per_m": 2e3})


def window() -> None:
    values = [float(f) for f in np.arange(28.5, 31.5 + 1e-9, 0.25)]
    passes = {}
    for label, order in (("up", values), ("down", values[::-1])):
        branch, found = Continuation(), {}
        for value in order:
            simulation = prepare(_scene(TEST_DRILL, "impact.frequency_hz", value, steady_state="periodic"))
            result = run(simulation, guess=branch.guess(value), cold_newton=branch.cold_newton)
            branch.add(branch_point(value, result.steady_state, math.nan))
            start = result.steady_state.start
            found[value] = (result.steady_state.regime_name, "-" if start is None else start.regime)
        passes[label] = found
    print("frequency [Hz] | continuation up | continuation down | from the start (the check)")
    for value in values:
        (up, start_up), (down, start_down) = passes["up"][value], passes["down"][value]
        start = start_up if start_up == start_down or start_down == "-" else \
            start_down if start_up == "-" else f"{start_up} / {start_down}"
        print(f"{value:g} | {up} | {down} | {start}")
    for value in (30.25, 30.5, 30.75, 31.0, 31.25):
        simulation = prepare(_scene(TEST_DRILL, "impact.frequency_hz", value, steady_state="periodic"))
        blow_map = exact_period_map(simulation)
        for blows in (400, 1000):
            states = blow_map.blow_states(start_state(simulation), blows)
            period, distance = repeating_period(simulation, states, MAX_PERIOD_BLOWS)
            run_ = run(prepare(_scene(TEST_DRILL, "impact.frequency_hz", value, end_time_s=blows / value,
                                 steady_state="time"))).raw
            last = blow_figures(run_, 6, value)
            print(f"{value:g} Hz, {blows} blows from the start: period {period} repeats best (scaled distance "
                  f"{distance:.2g}); last 6 blows' advance [um] {np.round(np.array(last.advance_m) * 1e6, 2).tolist()}, "
                  f"peak rock force [kN] {np.round(np.array(last.peak_rock_force_n) / 1e3, 1).tolist()}")


def cost(repeats: int, formulation: str) -> None:
    study = rpdrill.load_study(ROOT / "studies" / "paper" / "frequency_scan.yaml")
    frequencies = [float(f) for f in np.arange(10.0, 120.0 + 1e-9, 1.0)]
    base = study.points[0].simulation.scene.with_solver(formulation, steady_state="periodic")
    points = [(f, prepare(base.with_({"impact.frequency_hz": f}))) for f in frequencies]
    checks: list = []
    original = regimes.RegimeFinder.check_start

    def recorded(self, state):
        checked = original(self, state)
        checks.append(checked.start)
        return checked

    def scan(start_check: bool) -> float:
        branch = Continuation()
        begin = time.process_time()
        for value, simulation in points:
            run_followed(branch, value, simulation, start_check)
        return time.process_time() - begin

    scan(False)  # kernels and caches loaded first
    regimes.RegimeFinder.check_start = recorded
    cpu = {}
    try:
        for label, start_check in (("with the check", True), ("without it", False)):
            times = []
            for _ in range(repeats):
                checks.clear()
                times.append(scan(start_check))
            cpu[label] = statistics.median(times)
            print(f"{label}: {len(frequencies)} points, CPU {cpu[label]:.3f} s (median of {repeats}: "
                  f"{', '.join(f'{t:.3f}' for t in times)})")
            done = [c for c in checks if c is not None]
            if done:
                blows = [c.blows for c in done]
                print(f"  the check: {len(done)} points, CPU {sum(c.cpu_time_s for c in done):.3f} s, blows run "
                      f"median {statistics.median(blows):g}, largest {max(blows)}; the start reaches the orbit at "
                      f"{sum(c.reaches_orbit for c in done)} of {len(done)}")
    finally:
        regimes.RegimeFinder.check_start = original
    print(f"CPU ratio with / without: {cpu['with the check'] / cpu['without it']:.2f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--parts", default="window,cost")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--formulation", default="exact", choices=("exact", "exudyn"))
    args = parser.parse_args()
    for part in args.parts.split(","):
        window() if part == "window" else cost(args.repeats, args.formulation)


if __name__ == "__main__":
    main()
