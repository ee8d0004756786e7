"""Comparison of two runs of one scene (e.g. the Exudyn model against the ODE of Eq. 4) over a window.

Histories are compared on a common grid: the stored times, inside the window, of the run with
fewer samples there; the other run is linearly interpolated onto them (interpolating the coarser
run instead would add its interpolation error, (h omega)^2 / 8 of the amplitude, to the
difference). For a history s(t), with r the reference:

    abs = max |s(t) - r(t)|,   rel = abs / (max r - min r)   over the grid.

The borehole bottom at the window's end is compared relative to max(|x_n(end)|, the rock law's
crushing penetration, F_th / k_n for Jenkins): the law's length scale keeps the figure
meaningful when (almost) nothing was crushed. Summary metrics are compared as |a - r| and |a - r| / |r|.
"""

from __future__ import annotations

import math

import numpy as np

from .metrics import summary_metrics
from .results import SimulationResult

HISTORIES = {
    "borehole_bottom_m": lambda r: r.bottom_m,
    "bit_velocity_m_per_s": lambda r: r.bit_velocity_m_per_s,
    "rock_force_n": lambda r: r.rock_force_n,
}
NOT_COMPARED = ("cpu_time_s",)


def _inside(result: SimulationResult, end_s: float) -> np.ndarray:
    return result.time_s <= end_s * (1 + 1e-12)


def _relative(difference: float, scale: float) -> float:
    return difference / scale if scale > 0 else (0.0 if difference == 0 else math.inf)


def compare_histories(reference: SimulationResult, other: SimulationResult, end_s: float) -> dict[str, dict]:
    """Largest absolute and range-relative difference of each history over [0, end_s]."""
    coarse = min((reference, other), key=lambda r: int(_inside(r, end_s).sum()))
    grid = coarse.time_s[_inside(coarse, end_s)]
    out = {}
    histories = dict(HISTORIES)
    if reference.piston is not None and other.piston is not None:  # a piston scene: its blow too
        histories["piston_contact_force_n"] = lambda r: r.piston.contact_force_n
    for name, history in histories.items():
        r = np.interp(grid, reference.time_s, history(reference))
        a = np.interp(grid, other.time_s, history(other))
        difference = float(np.max(np.abs(a - r)))
        span = float(np.ptp(r))
        out[name] = {"max_abs": difference, "range": span, "max_rel_to_range": _relative(difference, span)}
    return out


def compare_bottom_at(reference: SimulationResult, other: SimulationResult, at_s: float) -> dict[str, float]:
    """x_n of both runs at ``at_s`` and their difference relative to max(|x_n|, crushing penetration)."""
    r = float(np.interp(at_s, reference.time_s, reference.bottom_m))
    a = float(np.interp(at_s, other.time_s, other.bottom_m))
    scale = max(abs(r), reference.scene.rock.build().crushing_penetration_m)
    return {"reference_m": r, "other_m": a, "abs_m": abs(a - r), "scale_m": scale, "rel": _relative(abs(a - r), scale)}


def compare_metrics(reference: SimulationResult, other: SimulationResult) -> dict[str, dict[str, float]]:
    """Each summary metric (models.evaluation.metrics) of both runs and the absolute and relative difference."""
    r_metrics, a_metrics = summary_metrics(reference), summary_metrics(other)
    out = {}
    for name, r in r_metrics.items():
        if name in NOT_COMPARED:
            continue
        a = a_metrics[name]
        difference = abs(a - r)
        out[name] = {"reference": r, "other": a, "abs": difference, "rel": _relative(difference, abs(r))}
    return out


def compare_runs(reference: SimulationResult, other: SimulationResult, end_s: float) -> dict:
    """Everything above for two runs of one scene over the window [0, end_s]."""
    return {
        "reference": reference.formulation,
        "other": other.formulation,
        "window_end_s": end_s,
        "histories": compare_histories(reference, other, end_s),
        "bottom_at_window_end": compare_bottom_at(reference, other, end_s),
        "metrics": compare_metrics(reference, other),
        "cpu_time_s": {reference.formulation: reference.cpu_time_s, other.formulation: other.cpu_time_s},
    }


DEFAULT_TOLERANCES = {"bottom_at_window_end_rel": 1e-4, "bit_velocity_rel_to_range": 1e-3}


def verdict(report: dict, tolerances: dict[str, float] = DEFAULT_TOLERANCES) -> dict[str, dict]:
    """The checked figures of a :func:`compare_runs` report against ``tolerances``."""
    measured = {
        "bottom_at_window_end_rel": report["bottom_at_window_end"]["rel"],
        "bit_velocity_rel_to_range": report["histories"]["bit_velocity_m_per_s"]["max_rel_to_range"],
    }
    return {name: {"value": value, "tolerance": tolerances[name], "passed": bool(value <= tolerances[name])}
            for name, value in measured.items()}
