"""The library's front door, ``import rpdrill``: what a user of the Python API sees."""

import json
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest
import yaml
from commands import main
from scenes import PAPER_BASE, scene_dict

import rpdrill

ROOT = Path(__file__).resolve().parents[1]
QUICK = {"solver.end_time_s": 0.2, "metrics.transient_blows": 2, "metrics.block_blows": 2}


def test_the_readme_snippet_runs_from_a_fresh_process(tmp_path):
    """The issue's snippet, verbatim but for a shorter study, in a plain process outside the checkout."""
    study = tmp_path / "scan.yaml"
    study.write_text(yaml.safe_dump({
        "name": "scan", "base_scene": str(ROOT / "studies/scenes/paper_base.yaml"),
        "base_overrides": {"solver.formulation": "exact", "solver.end_time_s": 0.3},
        "scan": {"impact.frequency_hz": [50.0, 65.0]}, "metrics": ["penetration_rate_m_per_s"]}))
    code = f"""
import rpdrill
scene = rpdrill.load_scene({str(ROOT / "studies/scenes/paper_base.yaml")!r})
scene = scene.with_({{"impact.frequency_hz": 70.0, "solver.formulation": "exact"}})
result = rpdrill.simulate(scene)
rate = result.metrics["penetration_rate_m_per_s"]
assert isinstance(rate, float) and rate > 0, rate
frame = result.timeseries  # time_s a plain column on a plain index: pandas' merge_asof takes it as it is
assert frame.index.equals(__import__("pandas").RangeIndex(len(frame))) and "bit_velocity_m_per_s" in frame
assert frame["time_s"].is_monotonic_increasing
study = rpdrill.load_study({str(study)!r})
table = rpdrill.run_study(study, workers=2)
assert list(table["impact.frequency_hz"]) == [50.0, 65.0] and (table["status"] == "ok").all()
print(rate)
"""
    done = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, check=False, timeout=300)
    assert done.returncode == 0, done.stderr
    assert float(done.stdout.split()[-1]) > 0


def test_with_validates_every_change_and_names_the_key_path():
    scene = rpdrill.load_scene(PAPER_BASE)
    changed = scene.with_({"impact.frequency_hz": 70.0, "drill_string.bodies.collar.mass_kg": 2500.0})
    assert changed.impact.frequency_hz == 70.0 and changed.drill_string.bodies["collar"].mass_kg == 2500.0
    assert scene.impact.frequency_hz == 65.0  # a copy: the original is unchanged
    with pytest.raises(rpdrill.InputError, match=r"impact\.duration_s: 0\.1: must be shorter than the impact period"):
        scene.with_({"impact.duration_s": 0.1})
    with pytest.raises(ValueError, match=r"impact\.amplitude_kn: unknown scene key path; allowed keys here: "):
        scene.with_({"impact.amplitude_kn": 220.0})
    with pytest.raises(rpdrill.InputError, match=r"'colar' is not in the scene's drill_string\.bodies; there: "):
        scene.with_({"drill_string.bodies.colar.mass_kg": 2500.0})
    with pytest.raises(rpdrill.InputError, match=r"impact\.frequency_hz: 'fast': a number is required"):
        scene.with_({"impact.frequency_hz": "fast"})


def test_the_library_and_the_command_line_give_the_same_run(tmp_path):
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(scene_dict(**QUICK)))
    result = rpdrill.simulate(path, formulation="exact")
    assert main(["simulate", str(path), "--out", str(tmp_path / "out"), "--quiet", "--formulation", "exact"]) == 0
    written = pd.read_csv(tmp_path / "out" / "timeseries.csv")
    assert list(written.columns) == list(result.timeseries.columns)
    assert written["bit_velocity_m_per_s"].to_numpy() == pytest.approx(result.timeseries["bit_velocity_m_per_s"],
                                                                       rel=1e-9, abs=1e-12)
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    same = {name: value for name, value in result.metrics.items() if name != "cpu_time_s"}  # CPU time differs
    assert {name: summary["metrics"][name] for name in same} == pytest.approx(same)


def test_a_bad_scene_file_raises_the_message_the_command_line_prints(tmp_path, capsys):
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(scene_dict(**{"impact.amplitude_kn": 220})))
    with pytest.raises(rpdrill.InputError) as raised:
        rpdrill.load_scene(path)
    assert main(["simulate", str(path), "--out", str(tmp_path / "out")]) == 2
    assert capsys.readouterr().err.strip() == str(raised.value)


def test_run_study_returns_typed_columns_and_keeps_files_when_asked(tmp_path):
    study = tmp_path / "s.yaml"
    study.write_text(yaml.safe_dump({
        "name": "s", "base_scene": str(PAPER_BASE), "base_overrides": {"solver.end_time_s": 0.4},
        "scan": {"impact.frequency_hz": [40.0, 60.0]}, "metrics": ["penetration_rate_m_per_s"],
        "plots": [{"x": "impact.frequency_hz", "y": ["penetration_rate_m_per_s"]}]}))
    table = rpdrill.run_study(rpdrill.load_study(study, formulation="exact"), workers=1)
    assert table["penetration_rate_m_per_s"].dtype == float and table["status"].tolist() == ["ok", "ok"]
    out = tmp_path / "out"
    again = rpdrill.run_study(rpdrill.load_study(study, formulation="exact"), workers=1, out=out)
    pd.testing.assert_series_equal(again["penetration_rate_m_per_s"], table["penetration_rate_m_per_s"])
    assert {"results.csv", "study.json", "optima.csv"} <= {p.name for p in out.iterdir()}
    assert any(p.suffix == ".png" for p in out.iterdir())


NO_SIDE_EFFECTS = """
import io, json, sys, tempfile
from pathlib import Path
import matplotlib
matplotlib.use("svg")  # the user's own choice of backend
out = sys.stdout
import rpdrill
scene = rpdrill.load_scene(sys.argv[1]).with_({"solver.end_time_s": 0.3})
result = rpdrill.simulate(scene, formulation="exact")
after_simulate = sorted(m for m in ("matplotlib.pyplot", "matplotlib.figure") if m in sys.modules)
with tempfile.TemporaryDirectory() as folder:
    rpdrill.save_result(result, folder)  # the figures of rpdrill simulate
    rpdrill.run_study(sys.argv[2], workers=1, out=Path(folder) / "scan")  # a study's plots, drawn here
print(json.dumps({"backend": matplotlib.get_backend(), "pyplot": "matplotlib.pyplot" in sys.modules,
                  "after_simulate": after_simulate, "stdout_kept": sys.stdout is out}))
"""


@pytest.mark.slow
def test_library_calls_leave_the_callers_process_as_it_was(tmp_path):
    """``rpdrill.simulate`` loads no figure module; saving a result and running a study with plots draw
    their figures without pyplot: the backend the user chose stays, no pyplot is loaded, standard
    output is not replaced."""
    study = tmp_path / "scan.yaml"
    study.write_text(yaml.safe_dump({
        "name": "scan", "base_scene": str(ROOT / "studies/scenes/paper_base.yaml"),
        "base_overrides": {"solver.formulation": "exact", "solver.end_time_s": 0.3},
        "scan": {"impact.frequency_hz": [50.0, 60.0, 65.0]}, "metrics": ["penetration_rate_m_per_s"],
        "plots": [{"x": "impact.frequency_hz", "y": "penetration_rate_m_per_s"}]}))
    done = subprocess.run([sys.executable, "-c", NO_SIDE_EFFECTS, str(ROOT / "studies/scenes/paper_base.yaml"),
                           str(study)], cwd=tmp_path, capture_output=True, text=True, check=False, timeout=300)
    assert done.returncode == 0, done.stderr
    state = json.loads(done.stdout.splitlines()[-1])
    assert state == {"backend": "svg", "pyplot": False, "after_simulate": [], "stdout_kept": True}, state
