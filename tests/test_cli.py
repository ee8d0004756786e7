"""The command line as a whole: --version, --formulation, warnings as one line (from workers too,
once each), the files a study writes in its help."""

from __future__ import annotations

import importlib.metadata
import json
import subprocess
import sys
import warnings
from pathlib import Path

import pytest
import yaml
from commands import COMMANDS, main
from scenes import PAPER_BASE, scene_dict

ROOT = Path(__file__).resolve().parents[1]
QUICK = {"solver.end_time_s": 0.1, "metrics.transient_blows": 1, "metrics.block_blows": 2}


def test_version(capsys):
    with pytest.raises(SystemExit) as done:
        main(["--version"])
    assert done.value.code == 0
    assert capsys.readouterr().out.strip() == \
        f"rpdrill {importlib.metadata.version('rpdrill')} (Exudyn {importlib.metadata.version('exudyn')})"


@pytest.mark.parametrize("words", [[]] + [[name] for name in COMMANDS], ids=lambda words: " ".join(words) or "rpdrill")
def test_every_help_prints(words, capsys):
    """``rpdrill --help`` and every command's ``--help`` print and exit 0 (a stray '%' in a help text
    is a format error of argparse's)."""
    with pytest.raises(SystemExit) as done:
        main([*words, "--help"])
    assert done.value.code == 0
    assert "usage: rpdrill" in capsys.readouterr().out


def test_study_help_lists_the_files_it_writes(capsys):
    with pytest.raises(SystemExit):
        main(["study", "--help"])
    text = capsys.readouterr().out
    for name in ("results.csv", "study.json", "optima.csv", ".svg", "--formulation"):
        assert name in text


def test_simulate_with_another_formulation(tmp_path):
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(scene_dict(**QUICK)))  # an Exudyn scene with rk44 options
    out = tmp_path / "out"
    assert main(["simulate", str(path), "--out", str(out), "--formulation", "exact", "--quiet"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["formulation"] == "exact" and summary["metrics"]["penetration_rate_m_per_s"] >= 0
    assert (out / "timeseries.svg").stat().st_size > 0


def test_warning_format_is_restored_after_a_command(tmp_path):
    before = warnings.formatwarning
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(scene_dict(**QUICK)))
    main(["simulate", str(path), "--out", str(tmp_path / "out"), "--quiet"])
    assert warnings.formatwarning is before


@pytest.mark.slow
def test_worker_warnings_print_once_as_one_line(tmp_path):
    """Two points on two worker processes, both warned about their step: one line, no source path."""
    study = tmp_path / "steps.yaml"
    study.write_text(yaml.safe_dump({
        "name": "steps", "base_scene": str(PAPER_BASE),
        "base_overrides": {"solver.end_time_s": 0.15, "impact.frequency_hz": 40.0, "solver.step_s": 2e-4,
                           "metrics": {"transient_blows": 2, "block_blows": 2}},
        "scan": {"impact.amplitude_n": [200e3, 220e3]}, "metrics": ["penetration_rate_m_per_s"]}))
    done = subprocess.run([sys.executable, "-m", "rpdrill.studies.cli", "study", str(study), "--out",
                           str(tmp_path / "out"), "--workers", "2", "--quiet"], cwd=ROOT, capture_output=True,
                          text=True, check=False)
    lines = [line for line in done.stderr.splitlines() if "warning:" in line or "Warning" in line]
    assert len(lines) == 1, done.stderr
    assert lines[0].startswith("rpdrill: warning: scene 'test_drill': solver.step_s 0.0002 exceeds the stability limit")
    assert ".py" not in done.stderr and "Traceback" not in done.stderr
