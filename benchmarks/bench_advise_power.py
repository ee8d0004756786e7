"""``rpdrill advise --power-kw`` against brute force on the shipped top-hammer scene
(studies/scenes/top_hammer_piston.yaml): the optimum of advise at a fixed hammer power (blow energy
P / f at every point; studies.advice.advice_search) and the metric on a grid over the frequency, every
``--step-hz``, at the same power and the optimum's feed force; the largest margin by which a grid
point beats the optimum (the issue's criterion: at most 1 %).

Usage: python benchmarks/bench_advise_power.py [--power-kw 15] [--frequency-hz 30 90] [--feed-kn 5 25]
       [--step-hz 1] [--workers 2]
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse
import time
from pathlib import Path

import numpy as np

from rpdrill.studies.advice.advice_search import (
    FEED,
    FREQUENCY,
    AdviceEvaluator,
    Request,
    runnable_scene,
    search_advice,
)
from rpdrill.studies.inputs.reading import load_scene
from rpdrill.studies.runtime.pools import process_pool

SCENE = Path(__file__).resolve().parents[1] / "studies" / "scenes" / "top_hammer_piston.yaml"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--power-kw", type=float, default=15.0)
    parser.add_argument("--frequency-hz", type=float, nargs=2, default=(30.0, 90.0))
    parser.add_argument("--feed-kn", type=float, nargs=2, default=(5.0, 25.0))
    parser.add_argument("--step-hz", type=float, default=1.0)
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    bounds = {FREQUENCY: tuple(args.frequency_hz), FEED: tuple(1e3 * f for f in args.feed_kn)}
    request = Request("penetration_rate_m_per_s", bounds, power_w=1e3 * args.power_kw)
    scene = load_scene(SCENE)
    data = runnable_scene(scene, None, request, str(SCENE))
    with process_pool(args.workers) as runner:
        start = time.perf_counter()
        advice = search_advice(data, None, request, runner)
        advise_s = time.perf_counter() - start
        frequencies = np.arange(args.frequency_hz[0], args.frequency_hz[1] + 1e-9, args.step_hz)
        grid = AdviceEvaluator(data, request, runner)([{FREQUENCY: float(f), FEED: advice.best[FEED]}
                                                      for f in frequencies]).values
    best_grid = int(np.nanargmax(grid))
    margin = grid[best_grid] / advice.best_value - 1
    print(f"advise --power-kw {args.power_kw:g}: {advice.best_value * 1e3:.4g} mm/s at "
          f"{advice.best[FREQUENCY]:.4g} Hz (blow energy {request.power_w / advice.best[FREQUENCY]:.4g} J), feed "
          f"{advice.best[FEED] / 1e3:.4g} kN; {advice.runs} runs, {advise_s:.0f} s on {args.workers} workers")
    print(f"grid every {args.step_hz:g} Hz at that feed: best {grid[best_grid] * 1e3:.4g} mm/s at "
          f"{frequencies[best_grid]:.4g} Hz; it beats the optimum by {margin:+.2%} (criterion: at most +1 %)")


if __name__ == "__main__":
    main()
