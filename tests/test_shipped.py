"""Shipped scenes, studies and analyses open by name from anywhere, and an installed wheel runs them."""

from __future__ import annotations

import os
import subprocess
import sys
import sysconfig
from pathlib import Path

import pytest
from commands import main

import rpdrill

ROOT = Path(__file__).resolve().parents[1]
SHIPPED = sorted((ROOT / "studies").glob("*/*.yaml"))


def test_every_shipped_file_is_listed_by_its_kind_and_name(capsys):
    listed = {f.path.resolve(): f for f in rpdrill.shipped_files()}
    assert set(listed) == {path.resolve() for path in SHIPPED}
    by_name = {f.name: f for f in listed.values()}
    assert by_name["paper_base"].kind == "scene" and by_name["paper/frequency_scan"].kind == "study"
    assert by_name["paper/sensitivity"].kind == "sensitivity" and by_name["paper/calibration"].kind == "calibration"
    assert by_name["accuracy_studies/paper_base"].kind == "accuracy"
    assert by_name["paper/reproduction"].kind == "reproduction"
    assert all(f.description for f in listed.values())
    assert main(["shipped"]) == 0
    out = capsys.readouterr().out
    assert all(f"  {name} " in out for name in by_name)
    assert main(["shipped", "--kind", "scene"]) == 0
    out = capsys.readouterr().out
    assert "study:" not in out and "  paper/rock_table " not in out and "  top_hammer_waves " in out


def test_a_shipped_file_opens_by_name_from_another_folder(tmp_path, monkeypatch):
    by_path = rpdrill.load_scene(ROOT / "studies" / "scenes" / "paper_base.yaml")
    study_by_path = rpdrill.load_study(ROOT / "studies" / "paper" / "frequency_scan.yaml")
    monkeypatch.chdir(tmp_path)
    assert rpdrill.load_scene("paper_base") == by_path
    study = rpdrill.load_study("paper/frequency_scan")
    assert study.base == study_by_path.base and len(study.points) == len(study_by_path.points)
    (tmp_path / "paper_base").write_text("not a scene: a file of the user's by that name wins\n")
    with pytest.raises(rpdrill.InputError, match="paper_base"):
        rpdrill.load_scene("paper_base")


def test_a_shipped_name_of_another_kind_or_none_is_refused_naming_what_there_is(capsys, tmp_path):
    with pytest.raises(rpdrill.InputError, match="a shipped study, not a scene; the shipped scene files: .*paper_base"):
        rpdrill.load_scene("paper/frequency_scan")
    with pytest.raises(rpdrill.InputError, match="no_such_drill: no such file; nor a shipped file's name "
                                                 r"\(rpdrill shipped lists them\)"):
        rpdrill.load_scene("no_such_drill")
    assert main(["study", "paper_base", "--out", str(tmp_path / "never_written")]) == 2
    assert "a shipped scene, not a study" in capsys.readouterr().err


@pytest.mark.slow
def test_a_wheel_installed_into_a_fresh_environment_runs_a_shipped_scene_by_name(tmp_path):
    """The wheel's package data holds every shipped file: a fresh virtual environment (its dependencies
    those of this one, by a .pth file: no download) runs ``paper_base`` from a folder outside the checkout."""
    wheels = tmp_path / "wheels"
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--quiet", "--no-deps", "--no-build-isolation",
                    "--wheel-dir", str(wheels), str(ROOT)], check=True, capture_output=True)  # setuptools: the test extra
    (wheel,) = wheels.glob("rpdrill-*.whl")
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(venv)], check=True)
    python = venv / "bin" / "python"
    site = subprocess.run([str(python), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                          check=True, capture_output=True, text=True).stdout.strip()
    (Path(site) / "dependencies.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    subprocess.run([sys.executable, "-m", "pip", "install", "--quiet", "--no-deps", "--target", site, str(wheel)],
                   check=True, capture_output=True)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    # on the scene's own formulation, Exudyn: the exact one would first compile its numba kernels into the
    # fresh install (16 CPU s measured, 1 s for the run on Exudyn)
    script = ("import rpdrill; scene = rpdrill.load_scene('paper_base').with_({'solver.end_time_s': 0.3}); "
              "print(rpdrill.__file__); "
              "print(rpdrill.simulate(scene).metrics['penetration_rate_m_per_s'])")
    env = {key: value for key, value in os.environ.items() if key != "PYTHONPATH"}
    out = subprocess.run([str(python), "-c", script], cwd=elsewhere, check=True, capture_output=True, text=True,
                         env=env).stdout.split("\n")
    assert out[0].startswith(site) and float(out[1]) > 0
    listing = subprocess.run([str(python), "-m", "rpdrill.studies.cli", "shipped"], cwd=elsewhere, check=True,
                             capture_output=True, text=True, env=env).stdout
    assert all(f"  {f.name} " in listing for f in rpdrill.shipped_files())
