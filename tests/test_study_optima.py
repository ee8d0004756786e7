"""studies.scan.study_optima: the curve axis, the optima of every curve of a study, the optima files and
table of ``rpdrill study``, and no plot for a study whose every point failed.
Unit tests of studies.scan.study_optima: they import it."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest
import yaml
from commands import main
from scenes import PAPER_BASE

import rpdrill
from rpdrill.models.drill.modal import rock_mode_frequency_hz
from rpdrill.studies.scan.curve_optima import curve_optimum
from rpdrill.studies.scan.study_optima import csv_rows, curve_axis, optima_table, study_optima

# the optima of a study's curves; the rock mode and a curve's optimum as the references
UNITS = ("rpdrill.studies.scan.study_optima", "rpdrill.studies.scan.curve_optima", "rpdrill.models.drill.modal")

load_study = rpdrill.load_study

SHORT = {"solver.end_time_s": 0.15, "metrics": {"transient_blows": 2, "block_blows": 2}}


def write(path, scan, metrics=("penetration_rate_m_per_s", "cpu_time_s"), plots=(), **changes):
    path.write_text(yaml.safe_dump({"name": "optima", "base_scene": str(PAPER_BASE), "base_overrides": SHORT,
                                    "scan": scan, "metrics": list(metrics), "plots": list(plots), **changes}))
    return path


def bump(frequency_hz: float, centre_hz: float) -> float:
    return 0.02 * np.exp(-0.5 * ((frequency_hz - centre_hz) / 6.0) ** 2)


def synthetic_table(study, centres_hz, fail=()):
    """A results table (as results.csv holds it) whose penetration rate is a bump around the centre of its
    amplitude's curve."""
    rows = []
    for point in study.points:
        f, amplitude = point.values["impact.frequency_hz"], point.values["impact.amplitude_n"]
        failed = (f, amplitude) in fail
        rows.append({"point": str(point.index), "impact.frequency_hz": str(f), "impact.amplitude_n": str(amplitude),
                     "status": "failed" if failed else "ok", "error": "x" if failed else "", "wall_time_s": "1",
                     "penetration_rate_m_per_s": "" if failed else str(bump(f, centres_hz[amplitude])),
                     "cpu_time_s": "" if failed else "0.5"})
    return rpdrill.table_frame(rows)


def test_curve_axis_is_the_frequency_when_scanned_else_the_first_numeric_axis(tmp_path):
    both = load_study(write(tmp_path / "a.yaml", {"impact.amplitude_n": [1e5, 2e5, 3e5],
                                                  "impact.frequency_hz": [40.0, 50.0, 60.0]}))
    assert curve_axis(both) == "impact.frequency_hz"
    feed = load_study(write(tmp_path / "b.yaml", {"rock.name": ["sandstone", "conglomerate"],
                                                  "feed.force_n": [1e4, 2e4, 3e4]}, base_overrides={**SHORT, "rock": {"name": "sandstone"}}))
    assert curve_axis(feed) == "feed.force_n"
    two = load_study(write(tmp_path / "c.yaml", {"impact.frequency_hz": [40.0, 50.0]}))
    assert curve_axis(two) is None and study_optima(two, rpdrill.table_frame([])) == []


def test_optima_of_every_curve_and_figure_of_merit(tmp_path):
    study = load_study(write(tmp_path / "s.yaml", {"impact.frequency_hz": {"from": 30, "to": 90, "step": 5},
                                                  "impact.amplitude_n": [160e3, 220e3]}))
    centres = {160e3: 52.0, 220e3: 63.0}
    table = synthetic_table(study, centres, fail={(90.0, 160e3)})
    optima = study_optima(study, table)
    assert [o.metric for o in optima] == ["penetration_rate_m_per_s"] * 2  # cpu_time_s is no figure of merit
    resonance = rock_mode_frequency_hz(study.points[0].simulation.chain, study.points[0].simulation.rock)
    for optimum in optima:
        amplitude = optimum.curve["impact.amplitude_n"]
        frequencies = np.arange(30.0, 91.0, 5.0)
        values = [bump(f, centres[amplitude]) for f in frequencies]
        expected = curve_optimum(frequencies, values, resonance).main_lobe
        record = optimum.record
        assert record["optimum"] == pytest.approx(expected.peak)
        assert record["optimum"] == pytest.approx(centres[amplitude], abs=0.5)  # the parabola finds the bump
        assert record["band_80"] == pytest.approx(list(expected.band_80))
        assert record["band_50"][0] < record["band_80"][0] < record["optimum"] < record["band_80"][1]
        assert record["best"] == frequencies[int(np.argmax(values))] and record["best_value"] == max(values)
        assert record["resonance_hz"] == pytest.approx(resonance)
        assert record["failed"] == (1 if amplitude == 160e3 else 0) and record["points"] == len(frequencies)
        assert record["curve"] == {"impact.amplitude_n": amplitude}  # typed: a number, not its text
    records = optima
    header = list(csv_rows(records)[0])
    assert {"impact.amplitude_n", "optimum_impact.frequency_hz", "band_80_low_impact.frequency_hz",
            "value_unit"} <= set(header)
    table = optima_table(records).splitlines()
    assert "impact amplitude [kN]" in table[1] and "optimum, refined [Hz]" in table[1] and "80 % band [Hz]" in table[1]
    assert table[2].split()[0] == "160" and table[3].split()[0] == "220"


def test_study_writes_optima_and_prints_the_table(tmp_path, capsys):
    study = write(tmp_path / "s.yaml", {"impact.frequency_hz": [40.0, 45.0, 50.0]},
                  plots=[{"x": "impact.frequency_hz", "y": "penetration_rate_m_per_s"}],
                  base_overrides={**SHORT, "impact.amplitude_n": 400e3,
                                  "solver": {"formulation": "exact", "end_time_s": 0.15}})
    out = tmp_path / "out"
    assert main(["study", str(study), "--out", str(out), "--workers", "1", "--quiet"]) == 0
    printed = capsys.readouterr().out
    assert "penetration rate along impact frequency" in printed and "optimum, refined [Hz]" in printed
    with (out / "optima.csv").open() as handle:
        (row,) = list(csv.DictReader(handle))
    assert row["metric"] == "penetration_rate_m_per_s" and row["value_unit"] == "m/s"
    assert 40.0 <= float(row["best_impact.frequency_hz"]) <= 50.0
    record = json.loads((out / "study.json").read_text())
    assert record["optima"][0]["best_value"] == pytest.approx(float(row["best_value"]))
    assert {p.name for p in out.glob("00_*")} == {"00_penetration_rate_m_per_s_vs_impact_frequency_hz.png",
                                                  "00_penetration_rate_m_per_s_vs_impact_frequency_hz.svg"}


def test_a_study_whose_every_point_failed_draws_no_plot(tmp_path, capsys):
    study = write(tmp_path / "fail.yaml", {"impact.frequency_hz": [40.0, 42.0, 44.0]},
                  plots=[{"x": "impact.frequency_hz", "y": "penetration_rate_m_per_s"}],
                  base_overrides={**SHORT, "impact.frequency_hz": 40.0, "solver.step_s": 1e-3})  # RK44 unstable
    out = tmp_path / "out"
    with pytest.warns(rpdrill.StepLimitWarning, match="exceeds the stability limit"):
        assert main(["study", str(study), "--out", str(out), "--workers", "1", "--quiet"]) == 1
    assert not list(out.glob("*.png")) and not list(out.glob("*.svg"))
    err = capsys.readouterr().err
    assert "no plot 00_penetration_rate_m_per_s_vs_impact_frequency_hz" in err


def test_formulation_option_runs_every_point_with_it(tmp_path):
    study = write(tmp_path / "s.yaml", {"impact.frequency_hz": [40.0, 45.0]},
                  base_overrides={**SHORT, "solver.step_s": 2e-5})
    assert {p.simulation.settings.formulation for p in load_study(study, "exact").points} == {"exact"}
    assert {p.simulation.settings.formulation for p in load_study(study).points} == {"exudyn"}
    out = tmp_path / "out"
    assert main(["study", str(study), "--out", str(out), "--formulation", "exact", "--workers", "1", "--quiet"]) == 0
    resolved = json.loads((out / "study.json").read_text())["resolved_study"]["base_scene"]["solver"]
    assert resolved["formulation"] == "exact" and resolved["step_s"] is None
