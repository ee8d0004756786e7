"""The optima of a study's curves, from its results table (studies.scan.curve_optima does the numerics).

A study's curves run along one scan axis, its **curve axis**: ``impact.frequency_hz`` when it is
scanned (the paper's optima are frequencies), otherwise the first numeric scan axis with at least
three values; a study without one has no optima. A curve is the points that share the values of
every other axis. For each curve (the points that share the values of every other axis) and each collected figure of
merit (studies.display.catalogue ``merit``):

* the best grid point: the highest value and where it is;
* the optimum: the refined peak (parabola vertex) of the main lobe, its peak value, and its bands
  where the metric stays at or above 80 % and 50 % of that peak, with whether the peak is the
  first or last point of the curve (the optimum may then lie beyond the scan);
* the main lobe: along the frequency, the lobe nearest to the rock-mode resonance of the curve's
  scene (models.drill.modal.rock_mode_frequency_hz: sub-harmonic lobes near f_r/2 can be as high); along
  another axis, the highest lobe.

A failed point counts as 0 (no band reaches across a failed run). Each is an
studies.scan.curve_optima.Optimum; in ``optima.csv`` its values are in SI units, the axis positions
named by the axis key (``optimum_impact.frequency_hz``), the metric's SI unit in ``value_unit``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ...models.drill.modal import rock_mode_frequency_hz
from ..display.catalogue import metric, quantity
from ..display.text_tables import text_table
from .curve_optima import FREQUENCY, Optimum, curve_optimum
from .study import Study

if TYPE_CHECKING:
    import pandas as pd


def _numeric(values: list[Any]) -> bool:
    return all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values)


def curve_axis(study: Study) -> str | None:
    """The axis a study's curves run along (module doc), or None."""
    candidates = [a for a, values in study.axes.items() if _numeric(values) and len(set(values)) >= 3]
    return FREQUENCY if FREQUENCY in candidates else next(iter(candidates), None)


def merit_metrics(study: Study) -> list[str]:
    """The collected metrics that are figures of merit, in the study's order."""
    return [m for m in study.spec.metrics if metric(m).merit]


def metric_values(table: pd.DataFrame, name: str) -> np.ndarray:
    """A metric's column of a results table as floats; NaN for a failed point."""
    return np.where(table["status"] == "failed", np.nan, table[name].to_numpy(dtype=float, na_value=np.nan))


def curves(study: Study, table: pd.DataFrame, along: str) -> list[tuple[dict[str, Any], pd.DataFrame]]:
    """The table's curves: (the values of every axis but ``along``, its rows sorted along it), in the
    order of their first point."""
    others = [a for a in study.axes if a != along]
    if not others:
        return [({}, table.sort_values(along, kind="stable"))]
    return [(dict(zip(others, (value.item() if isinstance(value, np.generic) else value for value in key),
                      strict=True)), members.sort_values(along, kind="stable"))
            for key, members in table.groupby(others, sort=False)]


def _resonance_hz(study: Study, members: pd.DataFrame, along: str) -> float | None:
    if along != FREQUENCY:
        return None
    simulation = study.points[int(members["point"].iloc[0])].simulation
    return rock_mode_frequency_hz(simulation.chain, simulation.rock) or None


def study_optima(study: Study, table: pd.DataFrame) -> list[Optimum]:
    """One optimum per (figure of merit, curve) (module doc); none without a curve axis."""
    along = curve_axis(study)
    if along is None:
        return []
    found = []
    for name in merit_metrics(study):
        for curve, members in curves(study, table, along):
            found.append(curve_optimum(members[along].to_numpy(dtype=float), metric_values(members, name),
                                       _resonance_hz(study, members, along), metric=name, along=along,
                                       failed=int((members["status"] == "failed").sum()), curve=curve))
    return found


def csv_rows(optima: list[Optimum]) -> list[dict[str, Any]]:
    """Optima as the rows of optima.csv: the curve's axes as columns, axis positions named by the axis key."""
    rows = []
    for optimum in optima:
        along = optimum.along
        band_80, band_50 = optimum.band_80 or (None, None), optimum.band_50 or (None, None)
        rows.append({"metric": optimum.metric, **optimum.curve, "along": along, "points": optimum.points,
                     "failed": optimum.failed, f"best_{along}": optimum.best, "best_value": optimum.best_value,
                     f"optimum_{along}": optimum.optimum, "optimum_value": optimum.optimum_value,
                     "peak_at_scan_end": optimum.peak_at_scan_end,
                     f"band_80_low_{along}": band_80[0], f"band_80_high_{along}": band_80[1],
                     f"band_50_low_{along}": band_50[0], f"band_50_high_{along}": band_50[1],
                     "main_lobe_resonance_hz": optimum.resonance_hz, "lobes": len(optimum.lobes),
                     "value_unit": metric(optimum.metric).si_unit, "no_optimum_reason": optimum.no_optimum_reason or ""})
    return rows


def _band(band: tuple[float, float] | None, along: str) -> str:
    return "-" if band is None else f"{quantity(along).show(band[0], 3)}-{quantity(along).show(band[1], 3)}"


def optima_table(optima: list[Optimum]) -> str:
    """The optima of the first figure of merit as a text table, in display units ('' without any)."""
    if not optima:
        return ""
    first, along = optima[0].metric, optima[0].along
    x, y = quantity(along), metric(first)
    others = list(optima[0].curve)
    headings = [quantity(a).heading() for a in others] + [
        f"best on grid [{x.unit}]", f"{y.name} there [{y.unit}]", f"optimum, refined [{x.unit}]",
        f"80 % band [{x.unit}]", f"50 % band [{x.unit}]"]
    mine = [o for o in optima if o.metric == first]
    lines = []
    for optimum in mine:
        main = optimum.main_lobe
        shown = ("none" + (f" ({optimum.no_optimum_reason.split(':')[0]})" if optimum.no_optimum_reason else "")) \
            if main is None else x.show(main.peak) + (" (scan end)" if main.peak_at_scan_end else "")
        lines.append([quantity(a).show(v) for a, v in optimum.curve.items()] + [
            "-" if optimum.best is None else x.show(optimum.best), y.show(optimum.best_value or 0.0),
            shown, _band(optimum.band_80, along), _band(optimum.band_50, along)])
    lobe = "the lobe nearest to the rock mode" if optima[0].resonance_hz else "the highest lobe"
    reasons = sorted({o.no_optimum_reason for o in mine if o.no_optimum_reason})
    notes = "".join(f"\nno optimum on {sum(o.no_optimum_reason == reason for o in mine)} curve(s): {reason}"
                    for reason in reasons)
    return f"{y.name} along {x.name}; optimum: refined peak of {lobe}\n" + text_table(headings, lines) + notes
