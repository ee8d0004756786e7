"""
A rock law of one's own: a crushing threshold that rises with the crushing speed
================================================================================

A law named in a scene by its import path and run in the Exudyn and the exact formulations. The law
(written against the documented interface, docs/extending.md "A rock law of one's own"): the rock spring
k_n in series with a slider whose threshold rises with its speed, F_th = F_0 + c_r x_n' (a Bingham slider;
c_r = 0 is the paper's Eq. 1, 2). Off the bottom there is no force; in contact F = k_n (x - x_n); the
bottom advances only while the spring force exceeds F_0, at the rate x_n' = (k_n (x - x_n) - F_0) / c_r.
It is linear between switches, so it declares its modes (free, contact, crushing) and the exact and ODE
formulations run it; the Exudyn formulation records its force symbolically and advances the slider once per
step (``step_update``: backward Euler over the step).

The class subclasses ``rpdrill.RockLaw`` (a scene names no other class as its law). The scene names it by
import path, its keys under ``rock.parameters``::

    rock: {law: "rate_dependent_rock:RateDependentRock",
           parameters: {stiffness_n_per_m: 5.0e8, threshold_n: 138.0e3, rate_n_s_per_m: 1.0e5}}

and runs it only where its reader allows the module (a scene is data: ``allow_code=["rate_dependent_rock"]``,
``--allow-code rate_dependent_rock``), or, installed as a package that registers it under the entry point
group ``rpdrill.rock_laws`` as ``rate_dependent``, by that name (docs/extending.md, "Security"). The module
must be importable where the scene runs (this folder, the script's, on ``sys.path``; or the module in an
installed package). Printed: the penetration rate on the paper's base scene of the Exudyn and the exact
formulations with this law, and of the paper's law at the same static threshold F_0; drawn: the borehole
bottom of the three runs. ::

    python examples/rate_dependent_rock.py [--end-time-s 0.5] [--rate-n-s-per-m 1e5] [--figure rate_dependent_rock.png]
"""

from __future__ import annotations

import argparse
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from rpdrill.rocklaw.backends import NUMERIC, Backend
from rpdrill.rocklaw.base import POSITION, RockLaw, State, trapezoidal_plastic_work_j
from rpdrill.rocklaw.modes import ONE, Mode, ModeTable, Switch

BOTTOM = "bottom_m"


@dataclass(frozen=True)
class RateDependentRock(RockLaw):
    """k_n in series with a slider of threshold F_0 + c_r x_n' (module doc); a rocklaw.base.RockLaw."""

    stiffness_n_per_m: float
    threshold_n: float
    rate_n_s_per_m: float

    name: ClassVar[str] = "rate_dependent"
    state_names: ClassVar[tuple[str, ...]] = (BOTTOM,)
    bottom_index: ClassVar[int] = 0
    crushes: ClassVar[bool] = True
    damping_n_s_per_m: ClassVar[float] = 0.0  # no rock damper: the slider's speed term is the loss
    fresh_fraction: ClassVar[float] = 1.0  # no indexing model
    modes_follow_fresh_fraction: ClassVar[bool] = False
    resets_at_blows: ClassVar[bool] = False

    def __post_init__(self) -> None:
        if min(self.stiffness_n_per_m, self.threshold_n, self.rate_n_s_per_m) <= 0:
            raise ValueError("stiffness_n_per_m, threshold_n and rate_n_s_per_m must be positive")

    @property
    def loading_stiffness_n_per_m(self) -> float:
        return self.stiffness_n_per_m

    @property
    def unloading_stiffness_n_per_m(self) -> float:
        return self.stiffness_n_per_m

    @property
    def crushing_penetration_m(self) -> float:
        """F_0 / k_n: the penetration at which the slider starts to move."""
        return self.threshold_n / self.stiffness_n_per_m

    def initial_state(self) -> State:
        return (0.0,)

    def spring_force(self, bit_position_m: Any, state: Sequence[Any], backend: Backend = NUMERIC,
                     fresh_fraction: Any = None) -> Any:
        """k_n (x - x_n) in contact, 0 off the bottom (branching with backend.where only: Exudyn records it)."""
        elastic = self.stiffness_n_per_m * (bit_position_m - state[0])
        return backend.where(elastic > 0, elastic, 0.0)

    def force(self, bit_position_m: Any, bit_velocity_m_per_s: Any, state: Sequence[Any],
              backend: Backend = NUMERIC, fresh_fraction: Any = None) -> Any:
        return self.spring_force(bit_position_m, state, backend)

    def return_map(self, bit_position_m: float, state: State) -> State:
        """No time passes: a slider of finite speed stays where it is."""
        return state

    def step_update(self, bit_position_m: float, bit_velocity_m_per_s: float, state: State, step_s: float) -> State:
        """x_n after a step h of the slider, backward Euler: x_n' = (k_n (x - x_n') - F_0) / c_r where positive."""
        k, bottom = self.stiffness_n_per_m, state[0]
        if k * (bit_position_m - bottom) <= self.threshold_n:
            return state
        rate = step_s / self.rate_n_s_per_m
        return ((bottom + rate * (k * bit_position_m - self.threshold_n)) / (1.0 + rate * k),)

    def start_blow(self, bit_position_m: float, state: State) -> State:
        return state

    def plastic_work_j(self, spring_force_n: np.ndarray, bottom_m: np.ndarray) -> np.ndarray:
        """int F_spring d(x_n): the slider's friction and viscous work together."""
        return trapezoidal_plastic_work_j(spring_force_n, bottom_m)

    def modes(self) -> ModeTable:
        """free (no force), contact (F = k_n (x - x_n)), crushing (the same force, x_n moving at its rate)."""
        k, threshold, rate = self.stiffness_n_per_m, self.threshold_n, self.rate_n_s_per_m
        penetration = {POSITION: 1.0, BOTTOM: -1.0}
        spring = {POSITION: k, BOTTOM: -k}
        excess = {POSITION: k, BOTTOM: -k, ONE: -threshold}  # k_n (x - x_n) - F_0
        return {
            "free": Mode({}, (Switch(penetration, 1, "contact"),)),
            "contact": Mode(spring, (Switch(penetration, -1, "free"), Switch(excess, 1, "crushing"))),
            "crushing": Mode(spring, (Switch(excess, -1, "contact"),),
                             rates={BOTTOM: {name: value / rate for name, value in excess.items()}}),
        }

    def initial_mode(self, values: Mapping[str, float]) -> str:
        penetration = values[POSITION] - values[BOTTOM]
        if penetration <= 0:
            return "free"
        return "crushing" if self.stiffness_n_per_m * penetration > self.threshold_n else "contact"


def main() -> None:
    parser = argparse.ArgumentParser(description="A rock law of one's own: a crushing threshold that rises "
                                                 "with the crushing speed")
    parser.add_argument("--end-time-s", type=float, default=0.5)
    parser.add_argument("--rate-n-s-per-m", type=float, default=1e5)
    parser.add_argument("--figure", type=Path, default=Path("rate_dependent_rock.png"))
    args = parser.parse_args()
    import matplotlib.pyplot as plt

    import rpdrill

    base = rpdrill.load_scene("paper_base").with_({"solver.end_time_s": args.end_time_s})  # a shipped scene
    rock = base.rock.completed()
    own = base.with_({"rock": {"law": "rate_dependent_rock:RateDependentRock", "parameters": {
        "stiffness_n_per_m": rock.stiffness_n_per_m, "threshold_n": rock.threshold_n,
        "rate_n_s_per_m": args.rate_n_s_per_m}}}, allow_code=["rate_dependent_rock"])  # the module this script allows
    runs = {name: rpdrill.simulate(own, formulation=name) for name in ("exudyn", "exact")}
    rates = {name: result.metrics["penetration_rate_m_per_s"] for name, result in runs.items()}
    paper = rpdrill.simulate(base, formulation="exact")
    print(f"rate-dependent threshold (c_r {args.rate_n_s_per_m:g} N s/m), Exudyn: {rates['exudyn'] * 1e3:.4f} mm/s")
    print(f"rate-dependent threshold (c_r {args.rate_n_s_per_m:g} N s/m), exact: {rates['exact'] * 1e3:.4f} mm/s "
          f"(relative difference {abs(rates['exudyn'] / rates['exact'] - 1):.2e})")
    print(f"the paper's law at the same F_0, exact: {paper.metrics['penetration_rate_m_per_s'] * 1e3:.4f} mm/s")
    figure, axes = plt.subplots(figsize=(7, 3.5), layout="constrained")
    for label, result, style in ((f"c_r {args.rate_n_s_per_m:g} N s/m, Exudyn", runs["exudyn"], "-"),
                                 (f"c_r {args.rate_n_s_per_m:g} N s/m, exact", runs["exact"], "--"),
                                 ("the paper's law (c_r = 0), exact", paper, "-")):
        axes.plot(result.timeseries["time_s"], 1e3 * result.timeseries["borehole_bottom_m"], style, label=label)
    axes.set_xlabel("time (s)")
    axes.set_ylabel("borehole bottom x_n (mm)")
    axes.set_title(f"{base.name}: the bottom under a rate-dependent crushing threshold")
    axes.legend()
    figure.savefig(args.figure)
    print(f"wrote {args.figure}")


if __name__ == "__main__":
    main()
