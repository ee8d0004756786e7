"""``rpdrill advise`` against brute force, and what it costs, measured in one run.

First the cost of one run of each advise metric on the exact path, in this process (median over
nine frequencies at 75 kN on sandstone): the penetration per impact energy needs the impact work,
so the samples are every 1e-5 s instead of the output interval. Then for each Table 1 rock on
the shipped scene: the best point of advise (differential evolution, studies.advice.advice_search) and the best
point of a fine grid over the same bounds (every ``--step-hz`` and ``--step-kn``, the same runs
and thrust limit), the ratio of the two best values, and the wall time of advise per rock
(search, curves and map) on a process pool of ``--workers``. The pool is started (and its
workers load the compiled kernels) before the timing.

Usage: python benchmarks/bench_advise.py [--workers 2] [--step-hz 1] [--step-kn 1]
       [--metric penetration_rate_m_per_s] [--frequency-hz 20 120] [--feed-kn 20 100]
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse
import statistics
import time
from pathlib import Path

import numpy as np

from rpdrill.rocklaw.catalog import TABLE_1
from rpdrill.studies.advice.advice_search import (
    FEED,
    FREQUENCY,
    METRICS,
    AdviceEvaluator,
    Request,
    runnable_scene,
    search_advice,
)
from rpdrill.studies.inputs.reading import load_scene
from rpdrill.studies.runtime.pools import process_pool, sequential

SCENE = Path(__file__).resolve().parents[1] / "studies" / "scenes" / "paper_base.yaml"


def grid_best(scene: dict, rock: str, request: Request, runner, step_hz: float, step_n: float) -> tuple[float, dict]:
    """The best value and point of the grid over the request's bounds."""
    data = runnable_scene(scene, rock, request, str(SCENE))
    (f_low, f_high), (feed_low, feed_high) = request.bounds[FREQUENCY], request.bounds[FEED]
    points = [{FREQUENCY: f, FEED: feed} for f in np.arange(f_low, f_high + 1e-9, step_hz)
              for feed in np.arange(feed_low, feed_high + 1e-9, step_n)]
    values = np.nan_to_num(AdviceEvaluator(data, request, runner)(points).values, nan=0.0)
    best = int(np.argmax(values))
    return float(values[best]), points[best]


def seconds_per_run(scene: dict, metric: str, request: Request) -> float:
    """Median wall time of one run in this process (after a first run that loads the kernels)."""
    evaluate = AdviceEvaluator(runnable_scene(scene, "sandstone", Request(metric, request.bounds), str(SCENE)),
                         Request(metric, request.bounds), sequential)
    evaluate([{FREQUENCY: 65.0, FEED: 75e3}])
    times = []
    for frequency in np.linspace(*request.bounds[FREQUENCY], 9):
        start = time.perf_counter()
        evaluate([{FREQUENCY: frequency, FEED: 75e3}])
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--step-hz", type=float, default=1.0)
    parser.add_argument("--step-kn", type=float, default=1.0)
    parser.add_argument("--metric", choices=METRICS, default=METRICS[0])
    parser.add_argument("--frequency-hz", type=float, nargs=2, default=(20.0, 120.0))
    parser.add_argument("--feed-kn", type=float, nargs=2, default=(20.0, 100.0))
    args = parser.parse_args()
    scene = load_scene(SCENE)
    request = Request(args.metric, {FREQUENCY: tuple(args.frequency_hz), FEED: tuple(v * 1e3 for v in args.feed_kn)})
    costs = {metric: seconds_per_run(scene, metric, request) for metric in METRICS}
    print("one run on the exact path [s]: " + ", ".join(f"{m} {t:.4f}" for m, t in costs.items())
          + f"; ratio {costs[METRICS[1]] / costs[METRICS[0]]:.2f}")
    print(f"{args.metric} over {args.frequency_hz} Hz x {args.feed_kn} kN; grid every {args.step_hz:g} Hz x "
          f"{args.step_kn:g} kN; {args.workers} workers")
    print("rock | advise best | at [Hz, kN] | advise wall time [s] | runs | grid best | at [Hz, kN] | advise / grid")
    with process_pool(args.workers) as runner:
        list(runner(abs, [-1.0] * args.workers * 4))  # start the workers
        AdviceEvaluator(runnable_scene(scene, "sandstone", request, str(SCENE)), request, runner)(
            [{FREQUENCY: 65.0, FEED: 75e3}] * args.workers * 2)  # load the compiled kernels in each worker
        for rock in TABLE_1:
            start = time.perf_counter()
            advice = search_advice(runnable_scene(scene, rock, request, str(SCENE)), rock, request, runner)
            wall = time.perf_counter() - start
            best, at = grid_best(scene, rock, request, runner, args.step_hz, args.step_kn * 1e3)
            print(f"{rock} | {advice.best_value:.5g} | {advice.best[FREQUENCY]:.4g}, {advice.best[FEED] / 1e3:.4g} | "
                  f"{wall:.1f} | {advice.runs} | {best:.5g} | {at[FREQUENCY]:.4g}, {at[FEED] / 1e3:.4g} | "
                  f"{advice.best_value / best:.4f}", flush=True)


if __name__ == "__main__":
    main()
