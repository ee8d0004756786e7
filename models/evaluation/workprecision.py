"""Work-precision numerics: error measures against a reference, Pareto fronts.

Formulation independent: a run is reduced to a :class:`Signature` (what the errors are measured
on) by :func:`signature`, and two signatures give the errors of :func:`errors`:

* ``bottom_end_error_m`` / ``bottom_end_error_rel``: |x_n(end) - x_n,ref(end)| over the window,
  absolute and relative to max(|x_n,ref(end)|, F_th / k_n) (the scale of models.evaluation.compare: the
  crushing penetration keeps the figure meaningful when little is crushed);
* ``penetration_rate_error_rel``: |r - r_ref| / |r_ref| of the mean penetration rate
  (models.evaluation.metrics, the scene's averaging window);
* ``bit_velocity_rms_error_rel``: RMS over a uniform grid of [0, end] of the bit-velocity
  difference (each history linearly interpolated onto the grid), relative to the reference's range.

Knows nothing of YAML or of how a run was made.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .metrics import summary_metrics
from .results import SimulationResult

ERROR_MEASURES = ("bottom_end_error_rel", "penetration_rate_error_rel", "bit_velocity_rms_error_rel")
ERROR_LABELS = {
    "bottom_end_error_rel": "x_n(end) error / max(|x_n|, F_th/k_n)",
    "penetration_rate_error_rel": "penetration-rate error (relative)",
    "bit_velocity_rms_error_rel": "bit-velocity RMS error / range",
}


@dataclass(frozen=True)
class Signature:
    """What a run's errors are measured on: x_n at the end, the mean penetration rate, the bit
    velocity on the common grid, and the rock law's length scale F_th / k_n."""

    bottom_end_m: float
    penetration_rate_m_per_s: float
    bit_velocity_m_per_s: np.ndarray
    crushing_depth_m: float
    cpu_time_s: float


def uniform_grid_s(end_s: float, interval_s: float) -> np.ndarray:
    """0, interval, 2 interval, ... up to ``end_s``: whole multiples of ``interval_s``, so that a run
    sampled at that interval (the exact formulation's output grid) is compared without interpolation."""
    return np.arange(math.floor(end_s / interval_s * (1 + 1e-12)) + 1) * interval_s


def signature(result: SimulationResult, grid_s: np.ndarray) -> Signature:
    """Reduce a run to its :class:`Signature` (the penetration rate only if the scene asks for it);
    x_n is taken at the scene's end time."""
    metrics = summary_metrics(result) if "penetration_rate_m_per_s" in result.simulation.outputs.metrics else {}
    return Signature(
        bottom_end_m=float(result.bottom_at(np.array([result.scene.solver.end_time_s]))[0]),
        penetration_rate_m_per_s=float(metrics.get("penetration_rate_m_per_s", math.nan)),
        bit_velocity_m_per_s=np.interp(grid_s, result.time_s, result.bit_velocity_m_per_s),
        crushing_depth_m=result.scene.rock.build().crushing_penetration_m,
        cpu_time_s=float(result.cpu_time_s),
    )


def _relative(difference: float, scale: float) -> float:
    return difference / scale if scale > 0 else (0.0 if difference == 0 else math.inf)


def rms_error_rel_to_range(reference: np.ndarray, other: np.ndarray) -> float:
    """RMS of ``other - reference`` (same grid) relative to the reference's range."""
    return _relative(float(np.sqrt(np.mean((other - reference) ** 2))), float(np.ptp(reference)))


def errors(reference: Signature, other: Signature) -> dict[str, float]:
    """The error measures of the module doc (absolute end-point error in m as well)."""
    bottom = abs(other.bottom_end_m - reference.bottom_end_m)
    scale = max(abs(reference.bottom_end_m), reference.crushing_depth_m)
    return {
        "bottom_end_error_m": bottom,
        "bottom_end_error_rel": _relative(bottom, scale),
        "penetration_rate_error_rel": _relative(
            abs(other.penetration_rate_m_per_s - reference.penetration_rate_m_per_s),
            abs(reference.penetration_rate_m_per_s)),
        "bit_velocity_rms_error_rel": rms_error_rel_to_range(reference.bit_velocity_m_per_s,
                                                             other.bit_velocity_m_per_s),
    }


def non_dominated(points: Sequence[Sequence[float]]) -> list[int]:
    """Indices of the rows of ``points`` (one cost per column, lower is better) that no other row
    dominates (at most as large in every column and smaller in one): the Pareto front, in row order."""
    table = np.asarray(points, dtype=float)
    return [i for i, point in enumerate(table)
            if not (np.all(table <= point, axis=1) & np.any(table < point, axis=1)).any()]


def pareto_front(cost: Sequence[float], error: Sequence[float]) -> list[int]:
    """Indices of the non-dominated points of (cost, error) (:func:`non_dominated`; of equal points the
    first), by increasing cost and so decreasing error; NaN or infinite points are left out."""
    finite = [i for i in range(len(cost)) if math.isfinite(cost[i]) and math.isfinite(error[i])]
    front = [finite[j] for j in non_dominated([(cost[i], error[i]) for i in finite])]
    unique = {(cost[i], error[i]): i for i in reversed(front)}  # of equal points the first
    return sorted(unique.values(), key=lambda i: (cost[i], error[i]))
