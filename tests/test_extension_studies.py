"""Studies of an extended drill: a scene's extension parameter is a scan, calibration, sensitivity and
advice axis like any scene key; workers (processes, Dask) import the extension by name and give the single
runs' numbers; a study's provenance records the extension. (Why 5: a scan over an extension's parameter was
'unknown scene key path', run_study took no extension, a built model does not pickle.)"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest
import yaml
from commands import main
from scenes import PAPER_BASE

import rpdrill
from rpdrill.studies.sensitivity.sensitivity_study import scene_values

# the numbers of a scene a sensitivity study may vary
UNITS = ("rpdrill.studies.sensitivity.sensitivity_study", "rpdrill.studies.advice.advice_search")

MASS = "extensions.clamp.parameters.mass_kg"
ALLOW = ["user_rig"]  # the tests' rig (tests/user_rig.py): code of one's own, allowed by who reads the scenes
CLAMP = {"clamp": {"function": "user_rig:add_clamp",
                   "parameters": {"mass_kg": 300.0, "stiffness_n_per_m": 1.0e8, "damping_n_s_per_m": 1.0e3}}}
SHORT = {"solver.end_time_s": 0.15, "metrics.transient_blows": 2, "metrics.block_blows": 4, "impact.amplitude_n": 400e3,
         "impact.frequency_hz": 45.0}


def study_file(path: Path, **changes) -> Path:
    data = {"name": "clamp_scan", "base_scene": str(PAPER_BASE), "base_overrides": {**SHORT, "extensions": CLAMP},
            "scan": {MASS: [100.0, 400.0, 900.0]}, "metrics": ["penetration_rate_m_per_s", "energy_balance_relative_error"],
            "plots": [{"x": MASS, "y": "penetration_rate_m_per_s"}]} | changes
    path.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    return path


def single_runs() -> dict[float, float]:
    base = rpdrill.load_scene(PAPER_BASE, allow_code=ALLOW).with_({**SHORT, "extensions": CLAMP})
    return {mass: rpdrill.simulate(base.with_({MASS: mass})).metrics["penetration_rate_m_per_s"]
            for mass in (100.0, 400.0, 900.0)}


@pytest.fixture(scope="module")
def singles() -> dict[float, float]:
    return single_runs()


def test_a_yaml_study_scans_an_extension_parameter_on_two_workers_as_single_runs_give(tmp_path, singles):
    out = tmp_path / "out"
    assert main(["study", str(study_file(tmp_path / "scan.yaml")), "--out", str(out), "--workers", "2", "--quiet",
                 "--allow-code", "user_rig"]) == 0
    with (out / "results.csv").open(newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert {float(r[MASS]): float(r["penetration_rate_m_per_s"]) for r in rows} == pytest.approx(singles, rel=1e-9)
    assert len(set(singles.values())) == 3  # the clamp's mass acts
    # the clamp is in the account: a number, within the standard preset's stated error (the test drill's fixed
    # step of 2e-5 s, 400 kN blows: 5e-4 to 1.1e-3 here)
    assert all(float(r["energy_balance_relative_error"]) < 3e-3 for r in rows)
    recorded = json.loads((out / "study.json").read_text())["extensions"]["clamp"]
    assert recorded["import_path"] == "user_rig:add_clamp" and recorded["file"].endswith("user_rig.py")
    plot = out / "00_penetration_rate_m_per_s_vs_extensions_clamp_parameters_mass_kg.png"
    assert plot.stat().st_size > 10_000


@pytest.mark.slow
@pytest.mark.parametrize("runner", ["processes", "dask"])
def test_run_study_scans_an_extension_parameter_on_processes_and_a_dask_local_cluster(tmp_path, singles, runner):
    study = rpdrill.load_study(study_file(tmp_path / "scan.yaml", plots=[]), allow_code=ALLOW)
    table = rpdrill.run_study(study, workers=2, dask="" if runner == "dask" else None)
    assert (table["status"] == "ok").all()
    assert dict(zip(table[MASS], table["penetration_rate_m_per_s"], strict=True)) == pytest.approx(singles, rel=1e-9)


@pytest.mark.slow
def test_an_extension_parameter_is_a_calibration_axis(tmp_path):
    calibration = {
        "name": "clamp_fit", "base_scene": str(PAPER_BASE), "base_overrides": {**SHORT, "extensions": CLAMP},
        "frequency_hz": {"from": 40, "to": 60, "step": 10},
        "parameters": {MASS: {"bounds": [100.0, 900.0], "reason": "the clamp's mass sets the collar's mode"}},
        "targets": [{"label": "a", "optimum_hz": 50, "band_hz": [45, 55]}],
        "search": {"popsize": 2, "max_generations": 1, "seed": 1}}
    path = tmp_path / "calibration.yaml"
    path.write_text(yaml.safe_dump(calibration, sort_keys=False), encoding="utf-8")
    assert main(["calibrate", str(path), "--out", str(tmp_path / "out"), "--workers", "2", "--quiet",
                 "--allow-code", "user_rig"]) == 0
    fitted = yaml.safe_load((tmp_path / "out" / "calibrated_scene.yaml").read_text())
    assert 100.0 <= fitted["extensions"]["clamp"]["parameters"]["mass_kg"] <= 900.0


def test_an_extension_parameter_is_a_sensitivity_parameter(tmp_path):
    base = rpdrill.load_scene(PAPER_BASE, allow_code=ALLOW).with_({**SHORT, "extensions": CLAMP})
    values = scene_values(base)
    assert values[MASS] == 300.0 and values["extensions.clamp.parameters.stiffness_n_per_m"] == 1e8
    sensitivity = {"name": "clamp_sensitivity", "base_scene": str(PAPER_BASE),
                   "base_overrides": {**SHORT, "extensions": CLAMP}, "frequency_hz": {"from": 40, "to": 60, "step": 10},
                   "scans": [{"label": "400 kN"}], "parameters": [MASS]}
    path = tmp_path / "sensitivity.yaml"
    path.write_text(yaml.safe_dump(sensitivity, sort_keys=False), encoding="utf-8")
    assert main(["sensitivity", str(path), "--out", str(tmp_path / "out"), "--workers", "2", "--quiet",
                 "--allow-code", "user_rig"]) == 0
    with (tmp_path / "out" / "one_at_a_time.csv").open(newline="") as handle:
        assert {row["parameter"] for row in csv.DictReader(handle)} == {MASS}


@pytest.mark.slow
def test_an_extension_parameter_is_an_advice_axis(monkeypatch):
    """The curves and the map coarse (3 points a curve, 2 x 2: 25 runs, not 192): what is checked is that the
    search takes the extension's parameter as an axis, not those grids (tests/test_advice.py checks them)."""
    monkeypatch.setattr("rpdrill.studies.advice.advice_search.MAP_POINTS", 2)
    monkeypatch.setattr("rpdrill.studies.advice.advice_search.SLICE_POINTS", 3)
    scene = rpdrill.load_scene(PAPER_BASE, allow_code=ALLOW).with_({**SHORT, "extensions": CLAMP, "solver.end_time_s": 0.07,
                                                  "metrics.transient_blows": 1, "metrics.block_blows": 2})
    (advice,) = rpdrill.advise(scene, {"impact.frequency_hz": (45.0, 60.0), "feed.force_n": (20e3, 30e3),
                                       MASS: (100.0, 900.0)},
                               search=rpdrill.AdviceSearch(popsize=2, max_generations=1), workers=2)
    assert advice.formulation == "exudyn" and 100.0 <= advice.best[MASS] <= 900.0 and MASS in advice.slices
    with pytest.raises(rpdrill.InputError, match="allowed: .*extensions.clamp.parameters.KEY"):
        rpdrill.advise(scene, {"impact.frequency_hz": (45.0, 60.0), "feed.force_n": (20e3, 30e3),
                               "extensions.other.parameters.mass_kg": (1.0, 2.0)})
