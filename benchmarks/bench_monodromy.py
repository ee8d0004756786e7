"""Cost of the exact one-blow map of the paper drill with and without its Jacobian (the monodromy product,
models.steady.monodromy_kernel), on its period-1 orbit.

Usage: python benchmarks/bench_monodromy.py [--frequency HZ] [--repeats N]
Prints medians over N batches of 200 map runs each, CPU ms per run, and their difference: the Jacobian's cost.
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

from rpdrill.models.solvers.exact_model import BLAS
from rpdrill.models.solvers.simulation import prepare
from rpdrill.models.steady.regimes import RegimeFinder
from rpdrill.studies.inputs.reading import load_scene

ROOT = Path(__file__).resolve().parents[1]
BATCH = 200


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frequency", type=float, default=65.0)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    scene = load_scene(ROOT / "studies" / "scenes" / "paper_base.yaml").with_(
        {"solver.formulation": "exact", "impact.frequency_hz": args.frequency})
    with BLAS.limit(limits=1, user_api="blas"):
        finder = RegimeFinder(prepare(scene))
        orbit = finder.find().orbit
        period_map = finder.map(1)
        period_map(orbit.state)  # compiled kernels loaded
        cost = {}
        for jacobian in (False, True):
            batches = []
            for _ in range(args.repeats):
                start = time.process_time()
                for _ in range(BATCH):
                    period_map(orbit.state, jacobian=jacobian)
                batches.append((time.process_time() - start) / BATCH * 1e3)
            cost[jacobian] = statistics.median(batches)
    print(f"paper drill at {args.frequency:g} Hz, one blow from its orbit, CPU ms per run (median of {args.repeats}):")
    print(f"  the map alone {cost[False]:.3f}, with its Jacobian {cost[True]:.3f}: the Jacobian "
          f"{cost[True] - cost[False]:.3f}")


if __name__ == "__main__":
    main()
