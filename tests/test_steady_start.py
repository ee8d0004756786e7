"""Where the drill goes from its scene's start beside the orbits continuation follows (issue 47, section 6;
models/steady/start_check.py). On the test drill of docs/steady_state.md the continuation up the frequency
follows a stable period-1 orbit at 30.25 Hz and a period-2 orbit at 31.0 Hz, while the drill run from its start
bounces irregularly at 30.25 Hz and settles on period 5 at 31.0 Hz: the results say so, and exact time runs of
400 blows from the start (through the public API, independent of the check) show the same."""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np
import pytest
import yaml

import rpdrill

DRILL = Path(__file__).resolve().parent / "test_drill.yaml"
WINDOW = {"solver": {"formulation": "exact", "end_time_s": 1.5}, "impact.amplitude_n": 400e3,
          "drill_string.connectors.shock_absorber.damping_n_s_per_m": 2e3}
FREQUENCIES = [29.75, 30.25, 30.5, 31.0]


@pytest.fixture(scope="module")
def followed(tmp_path_factory) -> Path:
    """The continuation study over the window, one worker."""
    folder = tmp_path_factory.mktemp("window")
    study = folder / "window.yaml"
    study.write_text(yaml.safe_dump({"name": "window", "base_scene": str(DRILL), "base_overrides": WINDOW,
                                     "scan": {"impact.frequency_hz": FREQUENCIES}, "steady_state": "continuation",
                                     "metrics": ["penetration_rate_m_per_s"]}), encoding="utf-8")
    rpdrill.run_study(study, workers=1, out=folder / "out")
    return folder / "out"


def rows(path: Path) -> list[dict[str, str]]:
    with path.open(newline="", encoding="utf-8") as handle:
        return list(csv.DictReader(handle))


def last_blows(frequency_hz: float, blows: int = 400, last: int = 12) -> tuple[np.ndarray, np.ndarray]:
    """The advance [m] and peak rock force [N] of the last ``last`` blows of an exact time run of ``blows`` blows
    from the scene's start (rpdrill.simulate)."""
    scene = rpdrill.load_scene(DRILL).with_({**WINDOW, "impact.frequency_hz": frequency_hz,
                                             "solver.end_time_s": blows / frequency_hz})
    result = rpdrill.simulate(scene)
    series = result.timeseries
    period = 1.0 / frequency_hz
    starts = (np.arange(blows - last, blows + 1)) * period
    bottom = np.interp(starts, series["time_s"], series["borehole_bottom_m"])
    blow = np.floor(series["time_s"].to_numpy() / period + 1e-9)
    peaks = np.array([series["rock_force_n"].to_numpy()[blow == k].max() for k in range(blows - last, blows)])
    return np.diff(bottom), peaks


def repeats(values: np.ndarray, period: int, relative: float) -> bool:
    return bool(np.all(np.abs(values[period:] - values[:-period]) <= relative * np.abs(values).max()))


def test_the_result_says_where_the_start_goes_where_it_is_not_the_orbit_followed(followed):
    passes = {float(r["impact.frequency_hz"]): r for r in rows(followed / "continuation.csv")}
    assert [passes[f]["regime_up"] for f in FREQUENCIES] == ["period-1", "period-1", "period-2", "period-2"]
    assert [passes[f]["start_regime_up"] for f in FREQUENCIES] == ["period-1", "irregular", "period-2", "period-5"]
    table = {float(r["impact.frequency_hz"]): r for r in rows(followed / "results.csv")}
    for frequency, reached in ((30.25, "no periodic response within"), (31.0, "another, stable period-5 orbit")):
        assert table[frequency]["status"] == "ok"
        assert table[frequency]["error"].startswith("coexisting regimes: the ") and reached in table[frequency]["error"]
    assert not table[29.75]["error"].startswith("coexisting") and not table[30.5]["error"].startswith("coexisting")
    coexisting = [r for r in rows(followed / "bifurcations.csv") if r["kind"] == "coexisting" and r["pass"] == "up"]
    assert [(float(r["impact.frequency_hz_from"]), int(r["point_from"])) for r in coexisting] == [(30.25, 1), (31.0, 3)]
    assert "from the scene's start the drill reaches a stable period-5 orbit" in coexisting[1]["detail"]


def test_time_runs_from_the_start_show_what_the_result_says():
    """Independent of the check: 400-blow exact time runs from the start. At 31.0 Hz the advance repeats every 5
    blows and not every 2 (one blow in five crushes); at 30.5 Hz no blow drills and the peak rock force
    alternates (the period-2 orbit the start reaches); at 30.25 Hz the peak rock force repeats no period up to 6
    blows (irregular); at 29.75 Hz it repeats every blow (the period-1 orbit)."""
    advance, peaks = last_blows(31.0)
    assert repeats(advance, 5, 1e-6) and not repeats(advance, 2, 1e-2) and advance.max() > 0
    advance, peaks = last_blows(30.5)
    # (a peak read from samples 1e-4 s apart: within 1e-3 of itself from blow to blow, 129.5 against 123.8 kN)
    assert np.all(advance == 0) and repeats(peaks, 2, 1e-3) and not repeats(peaks, 1, 1e-2)
    _, peaks = last_blows(30.25)
    assert not any(repeats(peaks, n, 1e-2) for n in range(1, 7))
    _, peaks = last_blows(29.75)
    assert repeats(peaks, 1, 1e-3)


def test_a_single_periodic_run_that_reaches_its_orbit_says_so_without_a_note():
    scene = rpdrill.load_scene(DRILL).with_({**WINDOW, "impact.frequency_hz": 30.5, "solver.steady_state": "periodic"})
    result = rpdrill.simulate(scene)
    steady = result.steady_state
    assert steady.regime_name == "period-2" and steady.start.regime == "period-2"
    assert steady.start.reaches_orbit is True and "coexisting" not in steady.note
    assert math.isfinite(result.metrics["penetration_rate_m_per_s"])


def test_another_formulation_is_checked_by_the_exact_model_and_an_extension_not_at_all():
    """The Exudyn formulation's orbit is checked by the exact model that guides it; a scene with an extension that
    changes the motion, which the exact model does not run, is not checked (no start_regime, no note)."""
    paper = rpdrill.load_scene(Path(__file__).resolve().parents[1] / "studies" / "scenes" / "paper_base.yaml",
                               allow_code=["user_rig"])
    scene = paper.with_({"solver.steady_state": "periodic", "solver.end_time_s": 0.3})
    result = rpdrill.simulate(scene)
    assert result.steady_state.regime_name == "period-1" and result.steady_state.start.reaches_orbit is True
    clamped = scene.with_({"extensions": {"clamp": {"function": "user_rig:add_clamp", "parameters": {
        "mass_kg": 300.0, "stiffness_n_per_m": 1.0e9, "damping_n_s_per_m": 2.0e4}}}})
    extended = rpdrill.simulate(clamped)
    assert extended.steady_state.regime_name == "period-1" and extended.steady_state.start is None
