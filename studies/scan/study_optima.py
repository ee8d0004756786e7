"""The optima of a study's curves, from its results table (studies.scan.curve_optima does the numerics).

A study's curves run along one scan axis, its **curve axis**: ``impact.frequency_hz`` when it is
scanned (the paper's optima are frequencies), otherwise the first numeric scan axis with at least
three values; a study without one has no optima. A curve is the points that share the values of
every other axis. For each curve and each collected figure of merit (studies.display.catalogue ``merit``):

* the best grid point: the highest value and where it is;
* the optimum: the refined peak (parabola vertex) of the main lobe, its peak value, and its bands
  where the metric stays at or above 80 % and 50 % of that peak, with whether the peak is the
  first or last point of the curve (the optimum may then lie beyond the scan);
* the main lobe: along the frequency, the lobe nearest to the rock-mode resonance of the curve's
  scene (models.drill.modal.rock_mode_frequency_hz: sub-harmonic lobes near f_r/2 can be as high); along
  another axis, the highest lobe.

A failed point counts as 0 (no band reaches across a failed run). Records are in SI units, the
axis positions named by the axis key (``optimum_impact.frequency_hz``), the metric's SI unit in
``value_unit``.
"""

from __future__ import annotations

from collections import defaultdict
from typing import Any

from ...models.drill.modal import rock_mode_frequency_hz
from ..display.catalogue import metric, quantity
from ..display.text_tables import text_table
from .curve_optima import curve_optimum
from .flat_curves import why_no_optimum
from .study import Study

FREQUENCY = "impact.frequency_hz"
Row = dict[str, str]
Record = dict[str, Any]


def _numeric(values: list[Any]) -> bool:
    return all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values)


def curve_axis(study: Study) -> str | None:
    """The axis a study's curves run along (module doc), or None."""
    candidates = [a for a, values in study.axes.items() if _numeric(values) and len(set(values)) >= 3]
    return FREQUENCY if FREQUENCY in candidates else next(iter(candidates), None)


def merit_metrics(study: Study) -> list[str]:
    """The collected metrics that are figures of merit, in the study's order."""
    return [m for m in study.spec.metrics if metric(m).merit]


def metric_value(row: Row, name: str) -> float:
    """A metric of a results row; NaN for a failed point."""

    return float(row[name]) if row["status"] != "failed" and row[name] != "" else float("nan")


def curves(study: Study, rows: list[Row], along: str) -> dict[tuple[str, ...], list[Row]]:
    """Rows grouped by the values of every axis but ``along`` (the curve's key), each sorted along it."""
    others = [a for a in study.axes if a != along]
    groups: dict[tuple[str, ...], list[Row]] = defaultdict(list)
    for row in rows:
        groups[tuple(row[a] for a in others)].append(row)
    return {key: sorted(members, key=lambda r: float(r[along])) for key, members in groups.items()}


def _resonance_hz(study: Study, members: list[Row], along: str) -> float | None:
    if along != FREQUENCY:
        return None
    simulation = study.points[int(members[0]["point"])].simulation
    return rock_mode_frequency_hz(simulation.chain, simulation.rock) or None


def study_optima(study: Study, rows: list[Row]) -> list[Record]:
    """One record per (figure of merit, curve) (module doc); none without a curve axis."""
    along = curve_axis(study)
    if along is None:
        return []
    others = [a for a in study.axes if a != along]
    records = []
    for name in merit_metrics(study):
        for key, members in curves(study, rows, along).items():
            x = [float(r[along]) for r in members]
            values = [metric_value(r, name) for r in members]
            resonance = _resonance_hz(study, members, along)
            found = curve_optimum(x, values, resonance)
            main, highest = found.main_lobe, found.global_lobe
            records.append({
                "metric": name, "curve": dict(zip(others, key, strict=True)), "along": along,
                "points": len(members), "failed": sum(r["status"] == "failed" for r in members),
                "best": None if highest is None else x[values.index(highest.peak_value)],
                "best_value": None if highest is None else highest.peak_value,
                "optimum": None if main is None else main.peak_hz,
                "optimum_value": None if main is None else main.peak_value,
                "peak_at_scan_end": None if main is None else main.peak_at_scan_end,
                "band_80": None if main is None else list(main.band_80_hz),
                "band_50": None if main is None else list(main.band_50_hz),
                "resonance_hz": resonance, "lobes": len(found.lobes), "value_unit": metric(name).si_unit,
                "no_optimum_reason": why_no_optimum(name, values) if main is None else None,
            })
    return records


def csv_rows(records: list[Record]) -> list[dict[str, Any]]:
    """Records as table rows: the curve's axes as columns, axis positions named by the axis key."""
    rows = []
    for record in records:
        along = record["along"]
        band_80, band_50 = record["band_80"] or (None, None), record["band_50"] or (None, None)
        rows.append({"metric": record["metric"], **record["curve"], "along": along, "points": record["points"],
                     "failed": record["failed"], f"best_{along}": record["best"], "best_value": record["best_value"],
                     f"optimum_{along}": record["optimum"], "optimum_value": record["optimum_value"],
                     "peak_at_scan_end": record["peak_at_scan_end"],
                     f"band_80_low_{along}": band_80[0], f"band_80_high_{along}": band_80[1],
                     f"band_50_low_{along}": band_50[0], f"band_50_high_{along}": band_50[1],
                     "main_lobe_resonance_hz": record["resonance_hz"], "lobes": record["lobes"],
                     "value_unit": record["value_unit"], "no_optimum_reason": record.get("no_optimum_reason") or ""})
    return rows


def _band(band: list[float] | None, along: str) -> str:
    return "-" if band is None else f"{quantity(along).show(band[0], 3)}-{quantity(along).show(band[1], 3)}"


def optima_table(records: list[Record]) -> str:
    """The optima of the first figure of merit as a text table, in display units ('' without records)."""
    if not records:
        return ""
    first, along = records[0]["metric"], records[0]["along"]
    x, y = quantity(along), metric(first)
    others = list(records[0]["curve"])
    headings = [quantity(a).heading() for a in others] + [
        f"best on grid [{x.unit}]", f"{y.name} there [{y.unit}]", f"optimum, refined [{x.unit}]",
        f"80 % band [{x.unit}]", f"50 % band [{x.unit}]"]
    lines = []
    for record in (r for r in records if r["metric"] == first):
        optimum = ("none" + (f" ({record['no_optimum_reason'].split(':')[0]})" if record.get("no_optimum_reason")
                             else "")) if record["optimum"] is None else \
            x.show(record["optimum"]) + (" (scan end)" if record["peak_at_scan_end"] else "")
        lines.append([quantity(a).show(number_or_text(v)) for a, v in record["curve"].items()] + [
            "-" if record["best"] is None else x.show(record["best"]), y.show(record["best_value"] or 0.0),
            optimum, _band(record["band_80"], along), _band(record["band_50"], along)])
    lobe = "the lobe nearest to the rock mode" if records[0]["resonance_hz"] else "the highest lobe"
    reasons = sorted({r["no_optimum_reason"] for r in records if r["metric"] == first and r.get("no_optimum_reason")})
    notes = "".join(f"\nno optimum on {sum(r.get('no_optimum_reason') == reason for r in records if r['metric'] == first)}"
                    f" curve(s): {reason}" for reason in reasons)
    return f"{y.name} along {x.name}; optimum: refined peak of {lobe}\n" + text_table(headings, lines) + notes


def number_or_text(value: str) -> float | str:
    """A table cell as a number where it is one (an axis value such as '160000.0' or 'sandstone')."""
    try:
        return float(value)
    except ValueError:
        return value
