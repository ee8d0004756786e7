"""``rpdrill calibrate``: parabola optimum, a small fit end to end, bad input."""

import json

import numpy as np
import pytest
import yaml
from scenes import PAPER_BASE

from rpdrill.studies.calibrate import load_calibration, optimum_hz
from rpdrill.studies.cli import main


def test_parabola_vertex_recovers_a_peak_between_scan_points():
    frequencies = [50.0, 55.0, 60.0, 65.0, 70.0]
    assert optimum_hz(frequencies, [100 - (f - 62.3) ** 2 for f in frequencies]) == pytest.approx(62.3)
    assert optimum_hz(frequencies, [0.0] * 5) is None
    assert optimum_hz(frequencies, list(np.arange(5.0))) == 70.0  # maximum at the scan's end


def write(tmp_path, **changes):
    data = {"name": "tiny", "base_scene": str(PAPER_BASE),
            "base_overrides": {"solver.end_time_s": 0.3, "metrics": {"transient_blows": 5, "block_blows": 5},
                               "impact.amplitude_n": 400e3},
            "parameters": {"drill_string.bodies.collar.mass_kg": [2000.0, 4000.0]},
            "frequency_hz": [40, 45, 50, 55, 60], "targets": [{"optimum_hz": 50}], "max_evaluations": 4} | changes
    path = tmp_path / "calibration.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def test_small_calibration_end_to_end(tmp_path):
    out = tmp_path / "out"
    assert main(["calibrate", str(write(tmp_path)), "--out", str(out), "--workers", "1", "--quiet"]) == 0
    report = json.loads((out / "calibration.json").read_text())
    assert 1 <= len(report["history"]) <= 5  # Nelder-Mead may finish its last simplex step
    best = report["best"]
    assert best["objective"] == min(r["objective"] for r in report["history"])
    assert 2000.0 <= best["parameters"]["drill_string.bodies.collar.mass_kg"] <= 4000.0
    scene = yaml.safe_load((out / "calibrated_scene.yaml").read_text())
    assert scene["drill_string"]["bodies"]["collar"]["mass_kg"] == best["parameters"]["drill_string.bodies.collar.mass_kg"]


def test_shipped_calibration_is_valid():
    calibration = load_calibration(PAPER_BASE.parents[1] / "studies" / "paper" / "calibration.yaml")
    assert len(calibration.spec.targets) == 3 and calibration.frequencies[0] == 20


@pytest.mark.parametrize("changes, fragment", [
    ({"parameters": {"drill_string.bodies.colar.mass_kg": [1, 2]}}, "parameters"),
    ({"parameters": {"drill_string.bodies.collar.mass_kg": [4000, 2000]}}, "lower bound 4000"),
    ({"metric": "speed"}, "metric: 'speed'"),
    ({"targets": [{"optimum_hz": -5}]}, "targets.0.optimum_hz"),
])
def test_bad_calibration_exit_2(tmp_path, capsys, changes, fragment):
    path = write(tmp_path, **changes)
    assert main(["calibrate", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert fragment in err and str(path) in err and "Traceback" not in err
