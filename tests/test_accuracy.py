"""Work-precision harness: measured convergence orders on a linear case against its exact solution,
the Pareto front, and the ``rpdrill accuracy`` study end to end and on bad input. Unit tests of the
harness's measures (models.evaluation.workprecision) and of the study's time limit and points
(studies.accuracy.accuracy_study); the study itself through the command and rpdrill.accuracy."""

from __future__ import annotations

import csv
import json
import math
import warnings
from pathlib import Path

import numpy as np
import pytest
import yaml
from commands import main
from scenes import PAPER_BASE, PER_BODY, scene_dict, simulate

import rpdrill
from rpdrill.models.evaluation.workprecision import errors, pareto_front, signature, uniform_grid_s
from rpdrill.studies.accuracy.accuracy_study import TimeLimitExceeded, cpu_time_limit, load_accuracy_study

# The errors of a run against a reference on a grid and the Pareto front; a setting's CPU time limit and the
# study's expanded points.
UNITS = ("rpdrill.models.evaluation.workprecision", "rpdrill.studies.accuracy.accuracy_study")

END_S = 0.04  # two blows at 50 Hz
GRID = uniform_grid_s(END_S, 1e-4)


def convergence_order(steps_s: list[float], errors_: list[float]) -> float:
    """Slope of the least-squares line through (log step, log error): the measured order p of e ~ h^p."""
    slope, _ = np.polyfit(np.log(np.asarray(steps_s, float)), np.log(np.asarray(errors_, float)), 1)
    return float(slope)


def linear_scene(solver_type: str, step_s: float) -> rpdrill.Scene:
    """paper_base made linear: elastic rock without damping, feed on every body (the bit never
    lifts off: checked against the reference), 20 kN blows; the pulse (1 ms) and the period
    (20 ms) are whole numbers of every step, so no step straddles a kink of the pulse."""
    data = scene_dict(**{**PER_BODY,
                         "impact.amplitude_n": 20e3, "impact.frequency_hz": 50.0, "impact.duration_s": 1e-3})
    data["effects"] = {"rock_plasticity": False, "rock_damping": False, "torsion": False, "joint_damping": True}
    data["outputs"] = {"metrics": [], "timeseries": []}
    data["metrics"] = {"transient_blows": 0, "block_blows": 1}
    data["solver"] = {"type": solver_type, "step_s": step_s, "end_time_s": END_S, "output_interval_s": 1e-4}
    return rpdrill.Scene.model_validate(data)


@pytest.fixture(scope="module")
def reference():
    result = simulate(linear_scene("rk44", 1e-5), "exact")
    # the bit meets the rock at t = 0+ (from rest) and stays on it: the model is linear
    assert all(t < 1e-9 for t in result.solver.switch_times_s)
    assert result.bit_position_m[result.time_s > 0].min() > 0
    return signature(result, GRID)


@pytest.mark.parametrize("solver_type, order, steps_s", [
    ("rk44", 4, [2e-5, 1e-5, 5e-6]),
    ("rk33", 3, [1e-5, 5e-6, 2.5e-6]),
    ("explicit_midpoint", 2, [5e-6, 2.5e-6, 1.25e-6]),
    ("generalized_alpha", 2, [2.5e-6, 1.25e-6, 6.25e-7]),
])
def test_measured_order_of_fixed_step_solvers(reference, solver_type, order, steps_s):
    measured = []
    for step in steps_s:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            run = simulate(linear_scene(solver_type, step))
        measured.append(errors(reference, signature(run, GRID))["bit_velocity_rms_error_rel"])
    assert abs(convergence_order(steps_s, measured) - order) < 0.3, measured


def test_pareto_front():
    cost = [1.0, 2.0, 3.0, 4.0, 0.5, math.nan]
    error = [1e-2, 1e-3, 2e-3, 1e-5, 1e-1, 1e-9]
    assert pareto_front(cost, error) == [4, 0, 1, 3]


def test_cpu_time_limit_stops_a_run():
    with pytest.raises(TimeLimitExceeded), cpu_time_limit(0.2):
        while True:
            pass


def write_study(path: Path, **changes) -> Path:
    study = {
        "name": "small_accuracy",
        "base_scene": str(PAPER_BASE),
        "base_overrides": {"metrics": {"transient_blows": 1, "block_blows": 2}},
        "blows": 3,
        "repeats": 1,
        "reference": {"solver": {"formulation": "exact"}},
        "reference_check": {"solver": {"formulation": "ode", "method": "DOP853", "relative_tolerance": 1e-11}},
        "families": [
            {"label": "rk44", "solver": {"formulation": "exudyn", "type": "rk44"}, "sweep": {"step_s": [2e-5, 1e-5]}},
            {"label": "midpoint", "solver": {"formulation": "exudyn", "type": "explicit_midpoint"},
             "sweep": {"step_s": [1e-4]}},  # far beyond its stability limit: diverges
            {"label": "DOP853", "solver": {"formulation": "ode"}, "sweep": {"relative_tolerance": [1e-5]}},
        ],
    }
    study.update(changes)
    path.write_text(yaml.safe_dump(study))
    return path


@pytest.mark.slow
def test_accuracy_study_end_to_end(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["accuracy", str(write_study(tmp_path / "s.yaml")), "--out", str(out), "--workers", "1",
                 "--quiet"]) == 0
    err = capsys.readouterr().err
    with (out / "workprecision.csv").open() as handle:
        rows = list(csv.DictReader(handle))
    assert [r["family"] for r in rows] == ["rk44", "rk44", "midpoint", "DOP853"]
    failed = [r for r in rows if r["status"] == "failed"]
    assert [r["family"] for r in failed] == ["midpoint"] and "diverged" in failed[0]["error"]
    assert failed[0]["error"] in err  # printed whole, not cut mid-number
    ok = [r for r in rows if r["status"] == "ok"]
    assert all(float(r["cpu_time_s"]) > 0 and float(r["penetration_rate_error_rel"]) >= 0 for r in ok)
    assert float(ok[1]["bit_velocity_rms_error_rel"]) < float(ok[0]["bit_velocity_rms_error_rel"])
    with (out / "pareto.csv").open() as handle:
        front = list(csv.DictReader(handle))
    assert {r["measure"] for r in front} == {"bottom_end_error_rel", "penetration_rate_error_rel",
                                              "bit_velocity_rms_error_rel"}
    report = json.loads((out / "reference.json").read_text())
    assert all(report["agreement_below_smallest_error"].values())
    assert (out / "workprecision.png").stat().st_size > 10_000
    # a rerun finds every setting finished; as a library call it returns the typed tables the files hold
    result = rpdrill.accuracy(tmp_path / "s.yaml", workers=1, out=out)
    assert isinstance(result, rpdrill.AccuracyResult) and "0 finished earlier" not in capsys.readouterr().err
    assert list(result.table["family"]) == [r["family"] for r in rows]
    assert result.table["cpu_time_s"].tolist()[:2] == [float(r["cpu_time_s"]) for r in rows[:2]]
    assert len(result.pareto) == len(front) and result.references_agree
    assert result.report["agreement"] == pytest.approx(report["agreement"])


def test_the_solver_column_names_what_a_preset_resolves_to(tmp_path):
    """A preset family's rows name the preset's own solver (reference is rk67), not a default."""
    families = [{"label": "presets", "solver": {"formulation": "exudyn"}, "sweep": {"preset": ["fast", "reference"]}},
                {"label": "DOP853", "solver": {"formulation": "ode"}, "sweep": {"relative_tolerance": [1e-5]}}]
    study = load_accuracy_study(write_study(tmp_path / "s.yaml", families=families))
    assert [point.values["solver"] for point in study.points] == ["rk44", "rk67", "DOP853"]


@pytest.mark.parametrize("changes, expected", [
    ({"blows": 0}, "blows"),
    ({"families": [{"label": "x", "solver": {"formulation": "ode", "method": "RK45"},
                    "sweep": {"relative_tolerance": [1e-3]}}]}, "solver.method: 'RK45'"),
    ({"families": [{"label": "x", "solver": {"formulation": "exudyn", "type": "rk5"}, "sweep": {"step_s": [1e-5]}}]},
     "solver.type"),
    ({"families": [{"label": "x", "solver": {"formulation": "exudyn"}, "sweep": {"step_s": [1e-5], "preset": ["fast"]}}]},
     "families.0.sweep"),
    ({"families": [{"label": "x", "solver": {"formulation": "exact"}, "sweep": {"step_s": [1e-5]}}]},
     "a key of formulation 'exudyn', not of 'exact'"),
])
def test_bad_input_exits_2(tmp_path, capsys, changes, expected):
    study = write_study(tmp_path / "bad.yaml", **changes)
    assert main(["accuracy", str(study), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    message = capsys.readouterr().err
    assert str(study) in message and expected in message, message
