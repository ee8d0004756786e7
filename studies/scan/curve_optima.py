"""What the optimum of a scanned curve metric(x) is: best grid point, lobes, main lobe, bands, and why
there is none: :class:`Optimum`, the one record of an optimum every analysis uses (a study's curves,
the frequency scans of calibration, sensitivity and reproduction).

Numerics on a sampled curve (x increasing, along a scan axis: the impact frequency or any other;
a value that is not finite counts as 0):

* **refined peak**: the vertex of the parabola through the best grid point and its neighbours
  (the point itself at an end of the scan or where the three points are not concave);
* **lobes**: the positive stretches of the curve, split at interior local minima. A peak counts
  only if its prominence (height above the higher of the two valleys that separate it from higher
  ground, the scan ends counting as 0) is at least ``dip_tolerance`` times its height, so that
  noise does not split a lobe; zero stretches always separate lobes;
* **main lobe**: along the impact frequency, the lobe whose refined peak is nearest, on a log scale,
  to a resonance estimate f_r (sub-harmonic lobes near f_r/2, f_r/3 can be as high as the main one);
  without an estimate (or along another axis), the lobe of the global maximum;
* **bands** at 80 % and 50 % of a lobe's peak: the contiguous interval around the peak where the
  metric stays at or above the level, its ends interpolated linearly between grid points (an end
  that reaches the scan's end is the scan's end);
* **best grid point**: the highest value and where it is;
* **no optimum**: why a curve has none (studies.scan.flat_curves: every point failed, or no crushing).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..display.catalogue import metric as metric_quantity
from .flat_curves import why_no_optimum

DIP_TOLERANCE = 0.05
FREQUENCY = "impact.frequency_hz"  # the axis along which the main lobe is the resonance's


@dataclass(frozen=True)
class Lobe:
    """One lobe of a curve: its extent, refined peak, peak value and bands (x in the axis's SI unit)."""

    first: float
    last: float
    peak: float
    peak_value: float
    peak_at_scan_end: bool  # the peak is the first or last scan point: the optimum may lie beyond
    band_80: tuple[float, float]
    band_50: tuple[float, float]


@dataclass(frozen=True)
class Optimum:
    """The optimum of ``metric`` along ``along`` on one curve (the values of the other axes: ``curve``):
    its ``points`` (``failed`` of them failed), the best grid point and its value, the lobes, the lobe of
    the global maximum and the main lobe (None when nothing is positive), the resonance estimate that
    chose the main lobe, and why there is no optimum (module doc). x in the axis's SI unit."""

    metric: str
    along: str
    points: int
    lobes: tuple[Lobe, ...]
    global_lobe: Lobe | None
    main_lobe: Lobe | None
    resonance_hz: float | None
    best: float | None = None
    best_value: float | None = None
    failed: int = 0
    no_optimum_reason: str | None = None
    curve: Mapping[str, Any] = field(default_factory=dict)

    @property
    def optimum(self) -> float | None:
        """The refined peak of the main lobe."""
        return None if self.main_lobe is None else self.main_lobe.peak

    @property
    def optimum_value(self) -> float | None:
        return None if self.main_lobe is None else self.main_lobe.peak_value

    @property
    def band_80(self) -> tuple[float, float] | None:
        """Where the main lobe stays at or above 80 % of its peak."""
        return None if self.main_lobe is None else self.main_lobe.band_80

    @property
    def band_50(self) -> tuple[float, float] | None:
        return None if self.main_lobe is None else self.main_lobe.band_50

    @property
    def peak_at_scan_end(self) -> bool | None:
        """Whether the main lobe peaks at the first or last point (its optimum may lie beyond the scan)."""
        return None if self.main_lobe is None else self.main_lobe.peak_at_scan_end

    @property
    def global_optimum(self) -> float | None:
        """The refined peak of the global maximum's lobe."""
        return None if self.global_lobe is None else self.global_lobe.peak

    @property
    def record(self) -> dict[str, Any]:
        """As JSON (study.json, calibration.json, reproduction.json): SI values, the metric's unit."""
        return {"metric": self.metric, "curve": dict(self.curve), "along": self.along, "points": self.points,
                "failed": self.failed, "best": self.best, "best_value": self.best_value,
                "optimum": self.optimum, "optimum_value": self.optimum_value, "peak_at_scan_end": self.peak_at_scan_end,
                "band_80": None if self.band_80 is None else list(self.band_80),
                "band_50": None if self.band_50 is None else list(self.band_50),
                "global_optimum": self.global_optimum, "resonance_hz": self.resonance_hz, "lobes": len(self.lobes),
                "value_unit": metric_quantity(self.metric).si_unit, "no_optimum_reason": self.no_optimum_reason}


def parabola_vertex(x: np.ndarray, values: np.ndarray, index: int) -> float:
    """Vertex of the parabola through point ``index`` and its neighbours, clipped to their span;
    the point itself at an end of the scan or where the three points are not concave."""
    if index in (0, len(values) - 1):
        return float(x[index])
    (f0, f1, f2), (y0, y1, y2) = x[index - 1:index + 2], values[index - 1:index + 2]
    numerator = (f1 - f0) ** 2 * (y1 - y2) - (f1 - f2) ** 2 * (y1 - y0)
    denominator = (f1 - f0) * (y1 - y2) - (f1 - f2) * (y1 - y0)
    if denominator <= 0:
        return float(f1)
    return float(np.clip(f1 - 0.5 * numerator / denominator, f0, f2))


def band(x: np.ndarray, values: np.ndarray, index: int, level: float) -> tuple[float, float]:
    """The contiguous interval around point ``index`` where values >= ``level``, ends interpolated."""
    edges = []
    for step in (-1, 1):
        inside = index
        while 0 <= inside + step < len(values) and values[inside + step] >= level:
            inside += step
        outside = inside + step
        if not 0 <= outside < len(values):
            edges.append(float(x[inside]))
            continue
        fraction = (values[inside] - level) / (values[inside] - values[outside])
        edges.append(float(x[inside] + fraction * (x[outside] - x[inside])))
    return edges[0], edges[1]


def _split_points(values: np.ndarray, dip_tolerance: float) -> list[tuple[int, int]]:
    """(first, last) index ranges of the lobes: positive stretches split at the lowest point between
    neighbouring peaks of sufficient relative prominence (the split point ends both lobes)."""
    from scipy.signal import find_peaks, peak_prominences  # 0.5 s to import: only where optima are found

    padded = np.concatenate([[0.0], values, [0.0]])
    peaks, _ = find_peaks(padded)
    prominences = peak_prominences(padded, peaks)[0]
    kept = [p - 1 for p, prominence in zip(peaks, prominences, strict=True)
            if prominence >= dip_tolerance * padded[p]]
    ranges = []
    for position, peak in enumerate(kept):
        first, last = peak, peak
        while first > 0 and values[first - 1] > 0:
            first -= 1
        while last < len(values) - 1 and values[last + 1] > 0:
            last += 1
        if position > 0:
            previous = kept[position - 1]
            first = max(first, previous + int(np.argmin(values[previous:peak + 1])))
        if position < len(kept) - 1:
            following = kept[position + 1]
            last = min(last, peak + int(np.argmin(values[peak:following + 1])))
        ranges.append((first, last))
    return ranges


def curve_optimum(x: Sequence[float], values: Sequence[float], resonance_hz: float | None = None,
                  dip_tolerance: float = DIP_TOLERANCE, metric: str = "penetration_rate_m_per_s",
                  along: str = FREQUENCY, failed: int = 0, curve: Mapping[str, Any] | None = None) -> Optimum:
    """The :class:`Optimum` of ``metric`` sampled at ``x`` (increasing) along ``along`` (module doc)."""
    points = np.asarray(x, dtype=float)
    raw = np.asarray(values, dtype=float)
    if points.shape != raw.shape or points.ndim != 1 or np.any(np.diff(points) <= 0):
        raise ValueError("x must increase and match the values one to one")
    if resonance_hz is not None and not resonance_hz > 0:
        raise ValueError(f"resonance_hz must be positive, got {resonance_hz}")
    curve_values = np.where(np.isfinite(raw) & (raw > 0), raw, 0.0)
    lobes = []
    for first, last in _split_points(curve_values, dip_tolerance):
        peak = first + int(np.argmax(curve_values[first:last + 1]))
        lobes.append(Lobe(
            first=float(points[first]), last=float(points[last]),
            peak=parabola_vertex(points, curve_values, peak), peak_value=float(curve_values[peak]),
            peak_at_scan_end=peak in (0, len(curve_values) - 1),
            band_80=band(points, curve_values, peak, 0.8 * curve_values[peak]),
            band_50=band(points, curve_values, peak, 0.5 * curve_values[peak])))
    common = {"metric": metric, "along": along, "points": len(points), "resonance_hz": resonance_hz,
              "failed": failed, "curve": dict(curve or {})}
    if not lobes:
        return Optimum(lobes=(), global_lobe=None, main_lobe=None,
                       no_optimum_reason=why_no_optimum(metric, list(raw)), **common)
    highest = max(lobes, key=lambda lobe: lobe.peak_value)  # the first of equal peaks
    main = highest if resonance_hz is None else \
        min(lobes, key=lambda lobe: abs(math.log(lobe.peak / resonance_hz)))
    best = int(np.flatnonzero(raw == highest.peak_value)[0])
    return Optimum(lobes=tuple(lobes), global_lobe=highest, main_lobe=main, best=float(points[best]),
                   best_value=highest.peak_value, **common)
