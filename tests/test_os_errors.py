"""Errors of the operating system as a user meets them (issue #39): an --out that cannot be written
(a read-only mount, a folder of mode 555), a disk that fills up, a name that is not UTF-8, a standard
output closed by its reader. Each ends in one clear message and the exit status the command line
states (2 before anything runs, 1 when a run could not finish), never an internal error, and leaves
nothing that blocks the next run.

A read-only or full disk is a real tmpfs mounted for the test (root, as on the developers' machines
and CI; skipped where mounting is not allowed); mode 555 is met as an unprivileged user through a
user namespace (``unshare --user``: root would write there anyway; skipped where unavailable)."""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path

import pytest
from commands import main

ROOT = Path(__file__).resolve().parents[1]
DRILL = Path(__file__).resolve().parent / "bad_inputs" / "valid" / "drill.yaml"


def command(*args: str) -> list[str]:
    return [sys.executable, "-m", "rpdrill.studies.cli", *args]


@contextlib.contextmanager
def tmpfs(folder: Path, options: str) -> Iterator[Path]:
    """A tmpfs mounted at ``folder`` with ``options`` (``ro``, ``size=64k``) while the block runs."""
    folder.mkdir(parents=True, exist_ok=True)
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(folder)], capture_output=True,
                          check=False)
    if done.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {done.stderr.decode(errors='replace').strip()}")
    try:
        yield folder
    finally:
        subprocess.run(["umount", "-l", str(folder)], capture_output=True, check=False)


def short_study(path: Path) -> Path:
    path.write_text(f"name: full_disk\nbase_scene: {DRILL}\n"
                    "base_overrides: {solver.end_time_s: 0.15, metrics: {transient_blows: 2, block_blows: 2}}\n"
                    "scan: {impact.frequency_hz: [40, 50, 60]}\nmetrics: [penetration_rate_m_per_s]\n"
                    "plots: [{x: impact.frequency_hz, y: [penetration_rate_m_per_s]}]\n", encoding="utf-8")
    return path


def clean(err: str) -> bool:
    return "Traceback" not in err and "internal error" not in err


def test_an_out_on_a_read_only_mount_is_refused_before_anything_runs(tmp_path, capsys):
    with tmpfs(tmp_path / "ro", "ro,size=1m") as mount:
        for out in (mount, mount / "new"):
            assert main(["simulate", str(DRILL), "--out", str(out), "--quiet"]) == 2
            err = capsys.readouterr().err
            assert clean(err) and f"--out: {out}" in err and ("Read-only" in err or "cannot write" in err), err
        assert list(mount.iterdir()) == []


@pytest.mark.slow
def test_an_out_of_mode_555_is_refused_for_a_user_who_cannot_write_there(tmp_path):
    if shutil.which("unshare") is None or subprocess.run(["unshare", "--user", "true"], check=False).returncode:
        pytest.skip("no user namespaces here")
    base = Path(tempfile.mkdtemp(prefix="rpdrill-555-"))  # (pytest's folders are private to root: 0700)
    try:
        base.chmod(0o755)
        folder = base / "locked"
        folder.mkdir(mode=0o555)
        for out, why in ((folder, "Permission denied"), (folder / "new", "cannot write in")):
            done = subprocess.run(["unshare", "--user", *command("simulate", str(DRILL), "--out", str(out), "--quiet")],
                                  cwd=ROOT, capture_output=True, text=True, timeout=300, check=False,
                                  env={**os.environ, "MPLCONFIGDIR": str(base / "mpl")})
            assert done.returncode == 2 and clean(done.stderr), done.stderr
            assert f"--out: {out}" in done.stderr and why in done.stderr, done.stderr
        assert list(folder.iterdir()) == []
    finally:
        shutil.rmtree(base, ignore_errors=True)


def test_a_full_disk_ends_a_simulation_with_one_line_and_leaves_nothing(tmp_path):
    with tmpfs(tmp_path / "full", "size=64k") as mount:
        done = subprocess.run(command("simulate", str(DRILL), "--out", str(mount / "out"), "--quiet"), cwd=ROOT,
                              capture_output=True, text=True, timeout=300, check=False)
        assert done.returncode == 1 and clean(done.stderr), done.stderr
        assert "No space left on device" in done.stderr and str(mount / "out") in done.stderr
        assert list(mount.iterdir()) == []  # no half file, no staging folder, no lock


@pytest.mark.slow
def test_a_study_on_a_disk_that_fills_up_resumes_once_there_is_room(tmp_path, capsys):
    """The disk fills up while the study writes: exit 1, one line; every file it left is whole
    (study.json was left empty and the next run refused to resume); with room again the same command
    completes from its finished rows (run in the test's process: what is checked is its status and
    message)."""
    study = short_study(tmp_path / "study.yaml")
    with tmpfs(tmp_path / "full", "size=48k") as mount:
        out = mount / "out"
        first = subprocess.run(command("study", str(study), "--out", str(out), "--workers", "1", "--quiet"),
                               cwd=ROOT, capture_output=True, text=True, timeout=300, check=False)
        assert first.returncode == 1 and clean(first.stderr), first.stderr
        assert "No space left on device" in first.stderr
        json.loads((out / "study.json").read_text(encoding="utf-8"))  # whole, not cut
        assert not [p for p in out.iterdir() if p.name.endswith(".tmp")]
        subprocess.run(["mount", "-o", "remount,size=20m", str(mount)], check=True)
        capsys.readouterr()
        status, err = main(["study", str(study), "--out", str(out), "--workers", "1", "--quiet"]), capsys.readouterr().err
        assert status == 0 and clean(err), err
        assert "3 finished earlier" in err or "running" in err


def test_an_out_name_that_is_not_utf8_is_refused_naming_the_byte(tmp_path, capsys):
    out = os.fsdecode(bytes(tmp_path) + b"/out\xffname")
    assert main(["simulate", str(DRILL), "--out", out, "--quiet"]) == 2
    err = capsys.readouterr().err
    assert clean(err) and "byte 0xff, not UTF-8" in err and "--out" in err, err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow
def test_a_closed_standard_output_ends_quietly_once_the_files_are_written(tmp_path):
    """``rpdrill simulate ... | head -n 0``: the reader is gone before the summary line is printed; the
    files are written and the command ends with its own status, silently (it was a BrokenPipeError)."""
    out = tmp_path / "out"
    process = subprocess.Popen(command("simulate", str(DRILL), "--out", str(out), "--quiet"), cwd=ROOT,
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    process.stdout.close()  # head -n 0
    err = process.stderr.read()
    assert process.wait(timeout=300) == 0 and clean(err) and "Broken pipe" not in err, err
    assert {"timeseries.csv", "summary.json", "scene.resolved.yaml"} <= {p.name for p in out.iterdir()}
