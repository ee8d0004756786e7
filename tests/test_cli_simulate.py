"""``rpdrill simulate``: outputs of a good run, one clear message and exit 2 for bad input."""

import json
import subprocess
import sys

import pytest
import yaml
from commands import main
from scenes import scene_dict

import rpdrill

QUICK = {"solver.end_time_s": 0.1, "metrics.transient_blows": 1, "metrics.block_blows": 2}


def write(tmp_path, data, name="scene.yaml"):
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data))
    return path


def test_simulate_writes_all_outputs(tmp_path):
    path = write(tmp_path, scene_dict(**QUICK, rock={"name": "sandstone"}))
    out = tmp_path / "out"
    assert main(["simulate", str(path), "--out", str(out), "--quiet"]) == 0
    assert {p.name for p in out.iterdir()} == {"timeseries.csv", "summary.json", "scene.resolved.yaml",
                                              "timeseries.png", "timeseries.svg", "drill.png"}
    header = (out / "timeseries.csv").read_text().splitlines()[0].split(",")
    assert header[0] == "time_s" and "bit_velocity_m_per_s" in header and "rock_force_n" in header
    assert len((out / "timeseries.csv").read_text().splitlines()) == 1 + 1001  # 0.1 s every 1e-4 s
    summary = json.loads((out / "summary.json").read_text())
    assert summary["metrics"]["energy_balance_relative_error"] < 0.01
    resolved = yaml.safe_load((out / "scene.resolved.yaml").read_text())
    assert resolved["rock"]["stiffness_n_per_m"] == 5.1e8  # filled in from Table 1
    assert resolved["solver"]["type"] == "rk44" and resolved["impact"]["shape"] == "half_sine"


BAD = [
    ("unit typo", {"impact.amplitude_kn": 220}, ["impact.amplitude_kn", "unknown key", "amplitude_n"]),
    ("missing", {"impact.frequency_hz": None}, ["impact.frequency_hz", "required"]),
    ("wrong type", {"impact.frequency_hz": "fast"}, ["impact.frequency_hz", "'fast'", "number"]),
    ("negative mass", {"drill_string.bodies.bit.mass_kg": -30.0},
     ["drill_string.bodies.bit.mass_kg", "-30.0", "greater than 0"]),
    ("zero stiffness", {"drill_string.connectors.collar_bit_joint.stiffness_n_per_m": 0.0},
     ["drill_string.connectors.collar_bit_joint.stiffness_n_per_m", "greater than 0"]),
    ("unknown connector end", {"drill_string.connectors.collar_bit_joint.to": "bitt"},
     ["drill_string", "'bitt'", "collar_bit_joint"]),
    ("feed on a missing body", {"feed.acts_on": "hammer"}, ["feed.acts_on", "'hammer'", "every_body"]),
    ("threshold", {"rock.threshold_n": 0.0}, ["rock.threshold_n", "0.0", "greater than 0"]),
    ("long pulse", {"impact.duration_s": 0.02}, ["impact.duration_s: 0.02", "shorter than the impact period"]),
    ("short run", {"solver.end_time_s": 0.01}, ["solver.end_time_s 0.01", "shorter than one impact period"]),
    ("unknown rock", {"rock": {"name": "granite"}}, ["rock.name", "'granite'", "sandstone"]),
    ("unknown solver", {"solver.type": "rk45"}, ["solver.type", "'rk45'", "generalized_alpha"]),
]


@pytest.mark.parametrize("label, overrides, expected", BAD, ids=[b[0] for b in BAD])
def test_bad_scene_one_message_exit_2(tmp_path, capsys, label, overrides, expected):
    path = write(tmp_path, scene_dict(**overrides))
    out = tmp_path / "out"
    assert main(["simulate", str(path), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert str(path) in err and "Traceback" not in err
    for fragment in expected:
        assert fragment in err
    assert not out.exists()  # nothing half-written


@pytest.mark.parametrize("content, expected", [(None, "no such file"), ("a: [1, 2", "not valid YAML"),
                                               ("- 1\n- 2\n", "mapping")])
def test_unreadable_files(tmp_path, capsys, content, expected):
    path = tmp_path / "scene.yaml"
    if content is not None:
        path.write_text(content)
    assert main(["simulate", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert expected in err and str(path) in err


def test_console_script_exit_status_and_no_traceback(tmp_path):
    path = write(tmp_path, scene_dict(**{"drill_string.bodies.shank.mass_kg": -1.0}))
    done = subprocess.run([sys.executable, "-m", "rpdrill.studies.cli", "simulate", str(path), "--out", str(tmp_path / "o")],
                          capture_output=True, text=True, check=False)
    assert done.returncode == 2
    assert "drill_string.bodies.shank.mass_kg" in done.stderr and "Traceback" not in done.stderr


def test_diverged_run_is_an_error_not_a_result(tmp_path, capsys):
    """Explicit Euler far beyond its stability limit: exit 1 and the message names the setting."""
    path = write(tmp_path, scene_dict(**QUICK, **{"solver.type": "explicit_euler", "solver.step_s": 2e-4}))
    out = tmp_path / "out"
    with pytest.warns(rpdrill.StepLimitWarning, match="explicit_euler is unstable"):
        assert main(["simulate", str(path), "--out", str(out), "--quiet"]) == 1
    err = capsys.readouterr().err
    assert "diverged" in err and "explicit_euler" in err and "step_s" in err
    assert not out.exists()


def test_an_out_folder_holding_another_run_is_refused_unless_overwrite(tmp_path, capsys):
    path = write(tmp_path, scene_dict(**QUICK))
    out = tmp_path / "out"
    out.mkdir()
    (out / "results.csv").write_text("point,status\n")  # a study's results
    assert main(["simulate", str(path), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert f"--out: {out}: holds results.csv" in err and "--overwrite" in err
    assert [p.name for p in out.iterdir()] == ["results.csv"]
    assert main(["simulate", str(path), "--out", str(out), "--quiet", "--overwrite"]) == 0
    assert {p.name for p in out.iterdir()} >= {"results.csv", "timeseries.csv", "summary.json"}


def test_simulate_with_the_exact_formulation_writes_its_run_info(tmp_path):
    """The exact run's record holds arrays (switch times): summary.json writes them as lists, its steady state
    as the regime's text."""
    path = write(tmp_path, scene_dict(**QUICK, solver={"formulation": "exact", "end_time_s": 0.1}))
    assert main(["simulate", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    run = json.loads((tmp_path / "out" / "summary.json").read_text())["run"]
    assert run["solver"]["mode_switches"] == len(run["solver"]["switch_times_s"]) > 0
    assert run["steady_state"]["regime"] == "time run" and run["steady_state"]["requested"] == "time"
