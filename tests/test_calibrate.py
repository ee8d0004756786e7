"""``rpdrill calibrate``: objective pieces, a tiny differential-evolution fit end to end, resume
(nothing recomputed, identical result, interrupted and extended runs), refusals and bad input. The fit through
the command and rpdrill.calibrate; the objective's pieces and the calibration file's reading are unit tests
(UNITS)."""

from __future__ import annotations

import csv
import json
import shutil
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import yaml
from commands import main
from scenes import PAPER_BASE

import rpdrill
from rpdrill import Budget
from rpdrill.models.evaluation.workprecision import non_dominated
from rpdrill.studies.calibration.calibration_search import objective, refined_frequencies_hz
from rpdrill.studies.calibration.calibration_spec import Parameter, load_calibration

# The Pareto filter, the objective and the refined axis, the calibration file's parameters and scenes, and the
# run of a scan's point (failed on purpose).
UNITS = ("rpdrill.models.evaluation.workprecision", "rpdrill.studies.calibration.calibration_search",
         "rpdrill.studies.calibration.calibration_spec", "rpdrill.studies.scan.curves")

ROOT = Path(__file__).resolve().parents[1]
COLLAR = "drill_string.bodies.collar.mass_kg"
PULSE = "impact.duration_s"


def spec(**changes) -> dict:
    """A tiny calibration of the test drill: 2 parameters, 3 targets (two the same scan), 6
    frequencies, 0.4 s exact runs, a DE population of 5 for 1 generation (10 evaluations)."""
    return {
        "name": "tiny", "base_scene": str(PAPER_BASE),
        "base_overrides": {"solver": {"formulation": "exact", "end_time_s": 0.4},
                           "metrics": {"transient_blows": 5, "block_blows": 5}},
        "frequency_hz": {"from": 40, "to": 90, "step": 10}, "refine_hz": 2,
        "parameters": {COLLAR: {"bounds": [2000.0, 4000.0], "scale": "log", "reason": "sets the rock mode"},
                       PULSE: {"bounds": [0.8e-3, 1.4e-3], "reason": "piston length"}},
        "targets": [{"label": "a", "optimum_hz": 60, "band_hz": [55, 65], "overrides": {"impact.amplitude_n": 400e3}},
                    {"label": "b", "optimum_hz": 70, "metric": "collar_velocity_peak_m_per_s"},
                    {"label": "a again", "optimum_hz": 62, "overrides": {"impact.amplitude_n": 400e3}}],
        "rising": [["a", "b"]],
        "search": {"popsize": 2, "max_generations": 1, "seed": 3},
    } | changes


def write(path: Path, data: dict) -> Path:
    path.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    return path


def calibrate(path: Path, out: Path, workers: str = "1") -> int:
    return main(["calibrate", str(path), "--out", str(out), "--workers", workers, "--quiet"])


def evaluations(out: Path) -> list[dict]:
    return [json.loads(line) for line in (out / "evaluations.jsonl").read_text().splitlines()]


def csv_rows(path: Path) -> list[dict[str, str]]:
    with path.open(newline="") as handle:
        return list(csv.DictReader(handle))


@pytest.fixture(scope="module")
def tiny(tmp_path_factory) -> tuple[Path, Path]:
    """The tiny calibration run once on a pool of 2 worker processes: (calibration file, out)."""
    base = tmp_path_factory.mktemp("tiny")
    path, out = write(base / "tiny.yaml", spec()), base / "out"
    assert calibrate(path, out, workers="2") == 0
    return path, out


# --- the objective and its pieces ---------------------------------------------------------------

def test_log_scale_maps_the_unit_interval_onto_the_bounds():
    parameter = Parameter(bounds=(1e6, 1e8), scale="log", reason="r")
    assert parameter.value(0.0) == 1e6 and parameter.value(1.0) == 1e8
    assert parameter.value(0.5) == pytest.approx(1e7)
    assert parameter.unit(1e7) == pytest.approx(0.5) and parameter.unit(1e9) == 1.0  # clipped


def test_objective_sums_weighted_squared_misses_and_the_rising_shortfall(tmp_path):
    calibration = load_calibration(write(tmp_path / "c.yaml", spec(targets=[
        {"label": "a", "optimum_hz": 60, "weight": 2.0}, {"label": "b", "optimum_hz": 70},
        {"label": "c", "optimum_hz": 80}], rising=[["a", "b", "c"]], rising_weight=0.5)))
    results = [SimpleNamespace(label="a", optimum=66.0, miss=0.1), SimpleNamespace(label="b", optimum=63.0, miss=-0.1),
               SimpleNamespace(label="c", optimum=None, miss=1.0)]  # a above b: 3 Hz short; c without optimum
    total, penalty = objective(calibration, results)
    assert penalty == pytest.approx(3.0 / 70)
    assert total == pytest.approx(2 * 0.01 + 0.01 + 1.0 + 0.5 * 3.0 / 70)


def test_refined_axis_adds_points_around_the_optima_only():
    axis = (40.0, 50.0, 60.0, 70.0)
    assert refined_frequencies_hz(axis, [52.4, None], 2.0) == [40.0, 44.0, 46.0, 48.0, 50.0, 52.0, 54.0, 56.0,
                                                                 58.0, 60.0, 62.0, 70.0]
    assert refined_frequencies_hz(axis, [52.4], None) == list(axis)


def test_non_dominated_keeps_the_trade_offs():
    misses = np.array([[0.1, 0.3], [0.2, 0.1], [0.2, 0.3], [0.1, 0.3]])  # row 2 is dominated; 0 and 3 tie
    assert non_dominated(misses) == [0, 1, 3]


# --- end to end ------------------------------------------------------------------------------------

def test_tiny_calibration_end_to_end(tiny):
    _, out = tiny
    records = evaluations(out)
    assert len(records) == 10  # DE: max(5, popsize x 2 parameters) x (1 + 1 generation)
    report = json.loads((out / "calibration.json").read_text())
    best = report["best"]
    assert best["objective"] == min(r["objective"] for r in records) == min(r["objective"] for r in report["evaluations"])
    assert all(r["simulations"] == 2 * 6 for r in records)  # 'a again' is the scan of 'a': run once
    scene = yaml.safe_load((out / "calibrated_scene.yaml").read_text())
    assert 2000.0 <= scene["drill_string"]["bodies"]["collar"]["mass_kg"] <= 4000.0
    assert 0.8e-3 <= scene["impact"]["duration_s"] <= 1.4e-3
    assert scene["drill_string"]["bodies"]["collar"]["mass_kg"] == best["parameters"][COLLAR]
    rows = csv_rows(out / "targets.csv")
    assert [r["label"] for r in rows] == ["a", "b", "a again"]
    assert rows[0]["paper_band_low_hz"] == "55" and rows[0]["within_tolerance"] in ("yes", "no")
    assert rows[0]["main_lobe_optimum_hz"] == rows[2]["main_lobe_optimum_hz"]
    assert abs(float(rows[1]["relative_miss"])) <= 1.0
    pareto = csv_rows(out / "pareto.csv")
    assert pareto and set(pareto[0]) >= {COLLAR, PULSE, "miss a", "miss b", "objective"}
    front = {int(r["evaluation"]) for r in pareto}
    misses = np.array([[abs(t["miss"]) for t in r["targets"]] for r in records])
    for i in set(range(len(records))) - front:  # every evaluation left out is dominated by one kept
        assert any(np.all(misses[j] <= misses[i]) and np.any(misses[j] < misses[i]) for j in front)
    assert "| a | penetration_rate_m_per_s | 60 (55-65) |" in (out / "targets.md").read_text()
    cost = report["cost"]
    assert cost["simulations"] >= 10 * 12 and cost["wall_time_s"] > 0 and cost["evaluations"] == 10
    target = best["targets"][0]  # each target's optimum: studies.scan.curve_optima.Optimum.record
    assert target["label"] == "a" and target["along"] == "impact.frequency_hz" and target["points"] == 6
    assert target["optimum"] is None or 40 <= target["optimum"] <= 90


def test_calibrate_as_a_library_call_gives_the_command_s_result(tiny):
    """``rpdrill.calibrate`` (no ``out``: a scratch checkpoint) finds the best set the command found, and
    the calibrated scene is that set on the base scene."""
    path, out = tiny
    result = rpdrill.calibrate(path, workers=1)
    report = json.loads((out / "calibration.json").read_text())
    assert isinstance(result, rpdrill.CalibrationResult) and result.out is None and len(result.records) == 10
    assert result.best.objective == report["best"]["objective"]
    assert result.best.parameters == report["best"]["parameters"]
    assert result.scene.drill_string.bodies["collar"].mass_kg == report["best"]["parameters"][COLLAR]
    assert set(result.optima_hz) == {"a", "b", "a again"}


def test_rerun_replays_every_evaluation_and_gives_the_same_result(tiny, tmp_path):
    path, first = tiny
    out = tmp_path / "out"
    shutil.copytree(first, out)
    assert calibrate(path, out) == 0  # in this process this time
    assert evaluations(out) == evaluations(first)  # nothing appended: nothing recomputed
    session = json.loads((out / "checkpoint.json").read_text())["sessions"][-1]
    assert session["evaluations_run"] == 0 and session["evaluations_replayed"] == 10
    for name in ("calibrated_scene.yaml", "targets.csv", "pareto.csv"):
        assert (out / name).read_text() == (first / name).read_text()


def test_interrupted_calibration_continues_where_it_stopped(tiny, tmp_path):
    path, first = tiny
    out = tmp_path / "out"
    shutil.copytree(first, out)
    lines = (out / "evaluations.jsonl").read_text().splitlines(keepends=True)
    (out / "evaluations.jsonl").write_text("".join(lines[:4]) + lines[4][:50])  # killed while writing
    assert calibrate(path, out) == 0
    resumed = evaluations(out)
    assert resumed[:4] == evaluations(first)[:4] and len(resumed) == 10
    by_unit = {tuple(r["unit"]): r["objective"] for r in evaluations(first)}
    assert {tuple(r["unit"]): r["objective"] for r in resumed} == by_unit
    assert (out / "calibrated_scene.yaml").read_text() == (first / "calibrated_scene.yaml").read_text()


def test_larger_budget_continues_the_same_search(tiny, tmp_path):
    _, first = tiny
    out = tmp_path / "out"
    shutil.copytree(first, out)
    longer = write(tmp_path / "longer.yaml", spec(search={"popsize": 2, "max_generations": 2, "seed": 3}))
    assert calibrate(longer, out) == 0
    records = evaluations(out)
    assert records[:10] == evaluations(first) and len(records) == 15
    session = json.loads((out / "checkpoint.json").read_text())["sessions"][-1]
    assert session["evaluations_replayed"] == 10 and session["evaluations_run"] == 5


def test_another_calibration_into_the_same_out_is_refused(tiny, tmp_path, capsys):
    _, first = tiny
    out = tmp_path / "out"
    shutil.copytree(first, out)
    other = write(tmp_path / "other.yaml", spec(targets=[{"label": "a", "optimum_hz": 50}], rising=[]))
    assert calibrate(other, out) == 2
    err = capsys.readouterr().err
    assert str(other) in err and "differs" in err and str(out) in err
    assert evaluations(out) == evaluations(first)


def test_overwrite_starts_another_calibration_afresh(tiny, tmp_path):
    _, first = tiny
    out = tmp_path / "out"
    shutil.copytree(first, out)
    other = write(tmp_path / "other.yaml", spec(search={"method": "nelder-mead", "max_evaluations": 2}))
    assert main(["calibrate", str(other), "--out", str(out), "--workers", "1", "--quiet", "--overwrite"]) == 0
    checkpoint = json.loads((out / "checkpoint.json").read_text())
    assert checkpoint["calibration_file"] == str(other) and len(checkpoint["sessions"]) == 1
    assert checkpoint["sessions"][0]["evaluations_replayed"] == 0 and len(evaluations(out)) <= 3


def test_nelder_mead_stays_within_its_budget(tmp_path):
    path = write(tmp_path / "nm.yaml", spec(search={"method": "nelder-mead", "max_evaluations": 3}))
    assert calibrate(path, tmp_path / "out") == 0
    assert 1 <= len(evaluations(tmp_path / "out")) <= 4  # Nelder-Mead may finish its last step


def test_every_simulation_failing_exits_1_without_a_scene(tmp_path, monkeypatch, capsys):
    def failing(branch, value, simulation, start_check=True):
        return {"status": "failed", "error": "RuntimeError: diverged", "wall_time_s": 0.0}
    monkeypatch.setattr("rpdrill.studies.scan.curves.run_followed", failing)  # runs in this process (--workers 1)
    path = write(tmp_path / "c.yaml", spec(search={"popsize": 2, "max_generations": 0, "seed": 3}))
    assert calibrate(path, tmp_path / "out") == 1
    assert "RuntimeError: diverged" in capsys.readouterr().err
    assert not (tmp_path / "out" / "calibrated_scene.yaml").exists()


def test_shipped_calibration_is_valid():
    # more than an hour of CPU (rpdrill calibrate needs --yes)
    calibration = load_calibration(ROOT / "studies" / "paper" / "calibration.yaml", Budget(accept_long=True))
    spec_ = calibration.spec
    assert len(spec_.parameters) >= 8 and all(p.reason.strip() for p in spec_.parameters.values())
    assert calibration.base.solver.formulation == "exact" and spec_.search.method == "differential-evolution"
    assert [t.optimum_hz for t in spec_.targets] == [65, 60, 65, 80, 32, 69, 80, 83.7, 87.6, 90]
    assert spec_.rising == [["3.1 b) 160 kN", "3.1 b) 220 kN", "3.1 b) 280 kN"],
                            ["3.2 Fig. 6 k = 8.93e7", "3.2 Fig. 6 k = 2.1e8", "3.2 Fig. 6 k = 5.1e8",
                             "3.2 Fig. 6 k = 8.4e8"]]
    # section 3.2's one invariant impulse feeds all its scans, none of 3.1's
    amplitudes = [calibration.scene({**calibration.values(calibration.start_unit()), "$impulse_3_2_n": 123e3}, t)
                  .impact.amplitude_n for t in range(len(spec_.targets))]
    assert amplitudes[4:] == [123e3] * 6 and 123e3 not in amplitudes[:4]
    assert calibration.frequencies_hz[0] == 10 and calibration.frequencies_hz[-1] == 120


def test_a_free_parameter_feeds_the_overrides_that_name_it_and_nothing_else(tmp_path):
    free = {"bounds": [300e3, 500e3], "reason": "one impulse for two scans"}
    calibration = load_calibration(write(tmp_path / "c.yaml", spec(
        parameters=spec()["parameters"] | {"$impulse": free},
        targets=[{"label": "a", "optimum_hz": 60, "overrides": {"impact.amplitude_n": "$impulse"}},
                 {"label": "b", "optimum_hz": 70, "overrides": {"rock": {"stiffness_n_per_m": 5e8, "damping_n_s_per_m": 2e3,
                                                                     "threshold_n": "$impulse"}}},
                 {"label": "c", "optimum_hz": 62}])))
    values = calibration.values(np.array([0.5, 0.5, 0.25]))
    assert values["$impulse"] == pytest.approx(350e3)
    assert calibration.scene(values, 0).impact.amplitude_n == pytest.approx(350e3)
    assert calibration.scene(values, 1).rock.threshold_n == pytest.approx(350e3)
    base = calibration.scene(values, 2)
    assert base.impact.amplitude_n == calibration.base.impact.amplitude_n and "$impulse" not in calibration.changes(values, 2)
    assert calibration.start_unit()[2] == 0.5  # no base-scene value: the middle of its bounds


# --- bad input ---------------------------------------------------------------------------------------

def parameter(**entry) -> dict:
    return {"parameters": {COLLAR: {"bounds": [2000.0, 4000.0], "reason": "r"} | entry}}


BAD = [
    ("missing reason", {"parameters": {COLLAR: {"bounds": [2000.0, 4000.0]}}},
     [f"parameters.{COLLAR}.reason", "missing"]),
    ("lo >= hi", parameter(bounds=[4000.0, 2000.0]), [f"parameters.{COLLAR}.bounds", "[4000.0, 2000.0]", "below"]),
    ("non-finite bound", parameter(bounds=[2000.0, float("inf")]),
     [f"parameters.{COLLAR}.bounds.1", "inf", "finite"]),
    ("log bound <= 0", parameter(bounds=[0.0, 4000.0], scale="log"),
     [f"parameters.{COLLAR}.bounds", "[0.0, 4000.0]", "positive lower bound"]),
    ("unknown path", {"parameters": {"drill_string.bodies.colar.mass_kg": {"bounds": [1, 2], "reason": "r"}}},
     ["parameters.drill_string.bodies.colar.mass_kg", "'colar'", "collar"]),
    ("unknown metric", {"metric": "speed"}, ["metric", "'speed'", "penetration_rate_m_per_s"]),
    ("unknown label in rising", {"rising": [["a", "c"]]}, ["rising.0.1", "'c'", "labels: a, b, a again"]),
    ("non-positive optimum", {"targets": [{"optimum_hz": -5}]}, ["targets.0.optimum_hz", "-5", "greater than 0"]),
    ("bound makes an invalid scene", {"parameters": {PULSE: {"bounds": [0.8e-3, 30e-3], "reason": "r"}}},
     [f"parameters.{PULSE}.bounds", "0.03", "shorter than"]),
    ("setting of another method", {"search": {"method": "nelder-mead", "popsize": 3}},
     ["search", "popsize", "max_evaluations"]),
    ("free parameter no target uses", {"parameters": {"$unused": {"bounds": [1.0, 2.0], "reason": "r"}}},
     ["parameters.$unused", "no target's overrides use"]),
    ("override names an undeclared free parameter",
     {"targets": [{"optimum_hz": 60, "overrides": {"impact.amplitude_n": "$nothing"}}]},
     ["targets.0.overrides.impact.amplitude_n", "'$nothing'", "not a parameter"]),
]


@pytest.mark.parametrize("changes, fragments", [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_bad_calibration_exit_2(tmp_path, capsys, changes, fragments):
    path = write(tmp_path / "calibration.yaml", spec(**changes))
    assert calibrate(path, tmp_path / "out") == 2
    err = capsys.readouterr().err
    assert str(path) in err and "Traceback" not in err and len(err.strip().splitlines()) == 1
    for fragment in fragments:
        assert fragment in err
    assert not (tmp_path / "out").exists()
