"""Stability limits of the fixed-step explicit solvers on the hard scenes (docs/stability.md).

Usage: python benchmarks/bench_stability.py [--solvers rk67,rk44,...] [--factors 0.1,0.2,...]
Runs every hard scene of tests/stability/hard_scenes.py (the frozen test drill varied) with each
solver at the fixed step h = factor / |lambda|_max (models.evaluation.stability.spectral_radius_per_s of the
scene) and prints (1) |lambda|_max of each scene; (2) per solver and scene the largest factor tried
up to which every factor ran without being rejected (models.evaluation.stability.check_result: non-finite or
runaway states or energy created, "diverged"; the end time not reached, "stopped"), and the first
rejected factor (steps above the suite's bound, pulse / 5 and period / 20, are not tried: such a
scene gives only a lower bound, ">=", and does not bound the limit over every hard scene); (3) the
energy-balance error of the undamped scene against the factor.
"""

from __future__ import annotations

import os

# one BLAS thread, as in a study's workers: set before NumPy loads
for _variable in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_variable, "1")

import argparse
import sys
import warnings
from pathlib import Path

from rpdrill.models.evaluation.metrics import summary_metrics
from rpdrill.models.evaluation.stability import SimulationFailed
from rpdrill.models.solvers.simulation import prepare

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))  # the hard scenes of the stability suite
from stability.hard_scenes import HARD_SCENES, hard_scene

from rpdrill.models.runs.scene_run import run as run_simulation

SOLVERS = ("rk67", "rk44", "rk33", "explicit_midpoint", "explicit_euler")
FACTORS = (0.05, 0.1, 0.2, 0.4, 0.8, 1.0, 1.2, 1.6, 2.0, 2.4, 2.8)
UNDAMPED = "no_damping"
BOUND = "step above pulse / 5 or period / 20"


def attempt(name: str, solver: str, factor: float, radius: float) -> tuple[bool, str, float]:
    """(stable, reason, energy-balance error) of one hard scene at step factor / radius."""
    base = hard_scene(HARD_SCENES[name])
    if factor / radius > min(base.impact.duration_s / 5, base.impact.period_s / 20):
        return False, BOUND, float("nan")  # as the suite: a step must resolve the pulse and the period
    scene = hard_scene(HARD_SCENES[name], {"type": solver, "step_s": factor / radius})
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # StepLimitWarning: the point is to go beyond the limit
            result = run_simulation(prepare(scene)).raw
    except SimulationFailed as failure:
        # "diverged": non-finite or runaway states, or energy created; "stopped": end time not reached
        return False, "stopped" if "stopped at" in str(failure) else "diverged", float("nan")
    return True, "", summary_metrics(result)["energy_balance_relative_error"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--solvers", default=",".join(SOLVERS))
    parser.add_argument("--factors", default=",".join(map(str, FACTORS)))
    args = parser.parse_args()
    solvers, factors = args.solvers.split(","), sorted(float(f) for f in args.factors.split(","))
    radius = {name: prepare(hard_scene(overrides)).spectral_radius_per_s
              for name, overrides in HARD_SCENES.items()}
    print("scene                        |lambda|_max [1/s]")
    for name, value in radius.items():
        print(f"{name:<29}{value:.0f}")
    print("\nlargest stable h |lambda|_max (every smaller factor stable too); first rejected factor")
    undamped: dict[str, dict[float, str]] = {}
    for solver in solvers:
        limits = []
        for name in HARD_SCENES:
            stable_up_to, first_bad = None, ""
            for factor in factors:
                ok, reason, energy = attempt(name, solver, factor, radius[name])
                if name == UNDAMPED:
                    undamped.setdefault(solver, {})[factor] = f"{energy:.1e}" if ok else reason
                if not ok:
                    first_bad = f"{factor:g} ({reason})"
                    break
                stable_up_to = factor
            rejected = bool(first_bad) and not first_bad.endswith(f"({BOUND})")
            if rejected:
                limits.append(stable_up_to)  # only a rejected run bounds the limit
            shown = ("none" if rejected else "-") if stable_up_to is None else \
                f"{stable_up_to:g}" if rejected else f">={stable_up_to:g}"
            print(f"{solver:<18}{name:<29}{shown:<7}{first_bad}", flush=True)
        bounded = [x if x is not None else 0.0 for x in limits]
        limit = "none" if 0.0 in bounded else f"{min(bounded):g}" if bounded else f">={factors[-1]:g}"
        print(f"{solver:<18}{'every hard scene':<29}{limit}\n", flush=True)
    print(f"energy-balance error on {UNDAMPED} against h |lambda|_max")
    print(f"{'solver':<18}" + "".join(f"{f:<10g}" for f in factors))
    for solver, row in undamped.items():
        print(f"{solver:<18}" + "".join(f"{row.get(f, ''):<10}" for f in factors))


if __name__ == "__main__":
    main()
