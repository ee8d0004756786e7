"""What the optimum of a scanned curve metric(frequency) is: global maximum, lobes, main lobe, bands.

Pure numerics on a sampled curve (frequencies increasing; a value that is not finite counts as 0):

* **refined peak**: the vertex of the parabola through the best grid point and its neighbours
  (the point itself at an end of the scan or where the three points are not concave);
* **lobes**: the positive stretches of the curve, split at interior local minima. A peak counts
  only if its prominence (height above the higher of the two valleys that separate it from higher
  ground, the scan ends counting as 0) is at least ``dip_tolerance`` times its height, so that
  noise does not split a lobe; zero stretches always separate lobes;
* **main lobe**: the lobe whose refined peak is nearest, on a log-frequency scale, to a resonance
  estimate f_r (sub-harmonic lobes near f_r/2, f_r/3 can be as high as the main one); without an
  estimate, the lobe of the global maximum;
* **bands** at 80 % and 50 % of a lobe's peak: the contiguous interval around the peak where the
  metric stays at or above the level, its ends interpolated linearly between grid points (an end
  that reaches the scan's end is the scan's end).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

DIP_TOLERANCE = 0.05


@dataclass(frozen=True)
class Lobe:
    """One lobe of a curve: its extent, refined peak, peak value and bands (Hz)."""

    first_hz: float
    last_hz: float
    peak_hz: float
    peak_value: float
    peak_at_scan_end: bool  # the peak is the first or last scan point: the optimum may lie beyond
    band_80_hz: tuple[float, float]
    band_50_hz: tuple[float, float]


@dataclass(frozen=True)
class CurveOptimum:
    """The lobes of a curve (by frequency), the lobe of its global maximum and its main lobe
    (None when nothing is positive), and the resonance estimate used to choose the main lobe."""

    lobes: tuple[Lobe, ...]
    global_lobe: Lobe | None
    main_lobe: Lobe | None
    resonance_hz: float | None

    @property
    def global_hz(self) -> float | None:
        return None if self.global_lobe is None else self.global_lobe.peak_hz

    @property
    def main_hz(self) -> float | None:
        return None if self.main_lobe is None else self.main_lobe.peak_hz


def parabola_vertex_hz(frequencies_hz: np.ndarray, values: np.ndarray, index: int) -> float:
    """Vertex of the parabola through point ``index`` and its neighbours, clipped to their span;
    the point itself at an end of the scan or where the three points are not concave."""
    if index in (0, len(values) - 1):
        return float(frequencies_hz[index])
    (f0, f1, f2), (y0, y1, y2) = frequencies_hz[index - 1:index + 2], values[index - 1:index + 2]
    numerator = (f1 - f0) ** 2 * (y1 - y2) - (f1 - f2) ** 2 * (y1 - y0)
    denominator = (f1 - f0) * (y1 - y2) - (f1 - f2) * (y1 - y0)
    if denominator <= 0:
        return float(f1)
    return float(np.clip(f1 - 0.5 * numerator / denominator, f0, f2))


def band_hz(frequencies_hz: np.ndarray, values: np.ndarray, index: int, level: float) -> tuple[float, float]:
    """The contiguous interval around point ``index`` where values >= ``level``, ends interpolated."""
    edges = []
    for step in (-1, 1):
        inside = index
        while 0 <= inside + step < len(values) and values[inside + step] >= level:
            inside += step
        outside = inside + step
        if not 0 <= outside < len(values):
            edges.append(float(frequencies_hz[inside]))
            continue
        fraction = (values[inside] - level) / (values[inside] - values[outside])
        edges.append(float(frequencies_hz[inside] + fraction * (frequencies_hz[outside] - frequencies_hz[inside])))
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


def curve_optimum(frequencies_hz: Sequence[float], values: Sequence[float], resonance_hz: float | None = None,
                  dip_tolerance: float = DIP_TOLERANCE) -> CurveOptimum:
    """Lobes, global-maximum lobe and main lobe of the sampled curve (module docstring)."""
    frequencies = np.asarray(frequencies_hz, dtype=float)
    curve = np.asarray(values, dtype=float)
    if frequencies.shape != curve.shape or frequencies.ndim != 1 or np.any(np.diff(frequencies) <= 0):
        raise ValueError("frequencies must increase and match the values one to one")
    if resonance_hz is not None and not resonance_hz > 0:
        raise ValueError(f"resonance_hz must be positive, got {resonance_hz}")
    curve = np.where(np.isfinite(curve) & (curve > 0), curve, 0.0)
    lobes = []
    for first, last in _split_points(curve, dip_tolerance):
        peak = first + int(np.argmax(curve[first:last + 1]))
        lobes.append(Lobe(
            first_hz=float(frequencies[first]), last_hz=float(frequencies[last]),
            peak_hz=parabola_vertex_hz(frequencies, curve, peak), peak_value=float(curve[peak]),
            peak_at_scan_end=peak in (0, len(curve) - 1),
            band_80_hz=band_hz(frequencies, curve, peak, 0.8 * curve[peak]),
            band_50_hz=band_hz(frequencies, curve, peak, 0.5 * curve[peak])))
    if not lobes:
        return CurveOptimum((), None, None, resonance_hz)
    highest = max(lobes, key=lambda lobe: lobe.peak_value)  # the first of equal peaks
    main = highest if resonance_hz is None else \
        min(lobes, key=lambda lobe: abs(math.log(lobe.peak_hz / resonance_hz)))
    return CurveOptimum(tuple(lobes), highest, main, resonance_hz)
