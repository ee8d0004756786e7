"""studies.scan.curve_optima on synthetic curves: refined peaks, lobes, main lobe, bands, and why a curve has none.
Unit tests of that module: they import it."""

import numpy as np
import pytest

from rpdrill.studies.scan.curve_optima import band, curve_optimum, parabola_vertex

# the optima of synthetic curves
UNITS = ("rpdrill.studies.scan.curve_optima",)

FREQUENCIES = np.arange(10.0, 121.0, 5.0)


def bump(frequencies, centre_hz, height, width_hz):
    return height * np.exp(-0.5 * ((frequencies - centre_hz) / width_hz) ** 2)


def test_parabola_vertex_recovers_a_peak_between_scan_points():
    frequencies = np.array([50.0, 55.0, 60.0, 65.0, 70.0])
    values = 100 - (frequencies - 62.3) ** 2
    assert parabola_vertex(frequencies, values, int(np.argmax(values))) == pytest.approx(62.3)
    assert parabola_vertex(frequencies, np.arange(5.0), 4) == 70.0  # at the scan's end


def test_band_ends_are_interpolated_crossings():
    frequencies = np.array([0.0, 1.0, 2.0, 3.0, 4.0])
    values = np.array([0.0, 1.0, 2.0, 1.0, 0.0])  # a triangle: >= 1.5 on [1.5, 2.5]
    assert band(frequencies, values, 2, 1.5) == pytest.approx((1.5, 2.5))
    assert band(frequencies, values, 2, 0.0) == (0.0, 4.0)  # reaches both scan ends


def test_main_lobe_is_the_resonance_not_a_higher_sub_harmonic():
    # main resonance 66 Hz, a higher sub-harmonic lobe near f_r/2 (35 Hz), zero in between
    values = bump(FREQUENCIES, 66.0, 10.0, 4.0) + bump(FREQUENCIES, 35.0, 12.0, 3.0)
    values[values < 0.05] = 0.0
    optimum = curve_optimum(FREQUENCIES, values, resonance_hz=72.0)
    assert len(optimum.lobes) == 2
    assert optimum.global_optimum == pytest.approx(35.0, abs=0.5)
    assert optimum.global_lobe.peak_value == pytest.approx(values.max())
    assert optimum.optimum == pytest.approx(66.0, abs=0.5)
    assert optimum.main_lobe.peak_value == pytest.approx(values[FREQUENCIES == 65.0][0])
    low, high = optimum.main_lobe.band_80
    assert 60 < low < 65 < high < 70  # 80 % of a Gaussian of width 4 Hz: 66 -+ 2.7 Hz
    assert optimum.main_lobe.band_50[0] < low and optimum.main_lobe.band_50[1] > high
    without_estimate = curve_optimum(FREQUENCIES, values)
    assert without_estimate.main_lobe == without_estimate.global_lobe


def test_lobes_touching_at_a_deep_dip_split_there():
    values = bump(FREQUENCIES, 40.0, 5.0, 6.0) + bump(FREQUENCIES, 80.0, 8.0, 6.0) + 0.5  # no zero stretch
    optimum = curve_optimum(FREQUENCIES, values, resonance_hz=45.0)
    assert len(optimum.lobes) == 2
    assert optimum.lobes[0].last == optimum.lobes[1].first == 60.0  # the lowest point between peaks
    assert optimum.optimum == pytest.approx(40.0, abs=0.5)
    assert optimum.global_optimum == pytest.approx(80.0, abs=0.5)


def test_curve_peaking_at_the_scan_end():
    values = np.linspace(0.0, 3.0, len(FREQUENCIES))
    optimum = curve_optimum(FREQUENCIES, values, resonance_hz=150.0)
    assert optimum.optimum == optimum.global_optimum == 120.0
    assert optimum.main_lobe.peak_at_scan_end
    assert optimum.main_lobe.band_80[1] == 120.0


@pytest.mark.parametrize("values", [np.zeros(len(FREQUENCIES)), np.full(len(FREQUENCIES), np.nan),
                                    -np.ones(len(FREQUENCIES))])
def test_flat_zero_or_failed_curve_has_no_optimum(values):
    optimum = curve_optimum(FREQUENCIES, values, resonance_hz=60.0)
    assert optimum.lobes == () and optimum.optimum is None and optimum.global_optimum is None
    assert optimum.best is None and optimum.record["band_80"] is None
    expected = {"zeros": "no crushing", "nan": "no result", "negative": None}  # the penetration rate's reasons
    kind = "nan" if np.isnan(values).all() else "zeros" if (values == 0).all() else "negative"
    assert (optimum.no_optimum_reason or "").split(":")[0] == (expected[kind] or "")


def test_the_optimum_of_another_axis_is_its_highest_lobe():
    """Along another axis than the impact frequency the main lobe is the highest (no resonance chooses)."""
    feed_n = np.linspace(10e3, 60e3, 11)
    values = bump(feed_n, 22e3, 1.0, 4e3) + bump(feed_n, 48e3, 2.0, 4e3)
    optimum = curve_optimum(feed_n, values, metric="penetration_rate_m_per_s", along="feed.force_n",
                            curve={"rock.name": "sandstone"})
    assert optimum.main_lobe is optimum.global_lobe and optimum.optimum == pytest.approx(48e3, abs=1e3)
    assert optimum.record["along"] == "feed.force_n" and optimum.record["curve"] == {"rock.name": "sandstone"}


def test_flat_positive_curve_is_one_lobe_over_the_whole_scan():
    optimum = curve_optimum(FREQUENCIES, np.full(len(FREQUENCIES), 2.0))
    assert len(optimum.lobes) == 1
    assert optimum.main_lobe.band_50 == (10.0, 120.0)


def test_a_shallow_noisy_dip_does_not_split_a_lobe():
    rng = np.random.default_rng(3)
    values = bump(FREQUENCIES, 65.0, 10.0, 12.0) * (1 + 0.002 * rng.standard_normal(len(FREQUENCIES)))
    dip = np.flatnonzero(FREQUENCIES == 60.0)[0]
    values[dip] = 0.97 * min(values[dip - 1], values[dip + 1])  # a 3 % dip next to the peak
    optimum = curve_optimum(FREQUENCIES, values, resonance_hz=30.0)
    assert len(optimum.lobes) == 1
    assert optimum.optimum == pytest.approx(65.0, abs=2.5)
    assert len(curve_optimum(FREQUENCIES, values, dip_tolerance=0.0).lobes) > 1  # counted without the tolerance


def test_bad_arguments_are_refused():
    with pytest.raises(ValueError, match="increase"):
        curve_optimum([10.0, 5.0], [1.0, 2.0])
    with pytest.raises(ValueError, match="resonance_hz"):
        curve_optimum([5.0, 10.0], [1.0, 2.0], resonance_hz=0.0)
