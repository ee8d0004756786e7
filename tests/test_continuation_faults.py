"""Continuation studies under faults (issue 47, section 5; studies/scan/continuation_runs.py): Ctrl-C keeps the
chains done and records the session, a kill between the writes of continuation.csv and results.csv resumes, a
finished study run again runs nothing and records its own wall time, an axis given out of order is followed in
order and said, and an --out the system will not let a run write is refused saying why."""

from __future__ import annotations

import csv
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml
from commands import main

import rpdrill
from rpdrill.studies.scan import continuation_runs

# a kill between the writes of a continuation chain, injected into its runner
UNITS = ("rpdrill.studies.scan.continuation_runs",)

ROOT = Path(__file__).resolve().parents[1]
DRILL = Path(__file__).resolve().parent / "test_drill.yaml"
FREQUENCIES = [27.5, 28.0, 28.5, 29.5]
# the test drill at 400 kN on a lightly damped shock absorber (tests/test_steady_state.py): period-2 orbits at
# 28-28.5 Hz, a period doubling up to period 1 at 29.5 Hz; three amplitudes, three chains of four points
STUDY = {"name": "chains", "base_scene": str(DRILL),
         "base_overrides": {"solver": {"formulation": "exact", "end_time_s": 1.5},
                            "drill_string.connectors.shock_absorber.damping_n_s_per_m": 2.0e3},
         "scan": {"impact.amplitude_n": [380e3, 400e3, 420e3], "impact.frequency_hz": FREQUENCIES},
         "steady_state": "continuation", "continuation_axis": "impact.frequency_hz",
         "metrics": ["penetration_rate_m_per_s"]}
FILES = ("results.csv", "continuation.csv", "bifurcations.csv")


def write_study(tmp_path: Path, **changes) -> Path:
    path = tmp_path / "chains.yaml"
    path.write_text(yaml.safe_dump({**STUDY, **changes}, sort_keys=False), encoding="utf-8")
    return path


def rows(path: Path) -> list[dict[str, str]]:
    """A CSV file's whole rows, without the wall times, in point order (results) or as written."""
    if not path.exists():
        return []
    with path.open(newline="", encoding="utf-8") as handle:
        found = [{k: v for k, v in r.items() if k != "wall_time_s"} for r in csv.DictReader(handle)
                 if None not in r.values()]
    return sorted(found, key=lambda r: int(r["point"])) if path.name == "results.csv" else found


@pytest.fixture(scope="module")
def whole(tmp_path_factory) -> Path:
    """The study run without a fault, one worker."""
    folder = tmp_path_factory.mktemp("whole")
    assert main(["study", str(write_study(folder)), "--out", str(folder / "out"), "--workers", "1", "--quiet"]) == 0
    return folder / "out"


@pytest.mark.slow
def test_ctrl_c_keeps_the_chains_done_records_the_session_and_resumes_to_the_uninterrupted_files(tmp_path, whole):
    """Issue 47: Ctrl-C kept nothing (the folder removed, no session): the chains ran before the results
    table and its study.json were written."""
    study, out = write_study(tmp_path), tmp_path / "out"
    process = subprocess.Popen([sys.executable, "-m", "rpdrill.studies.cli", "study", str(study), "--out", str(out),
                                "--workers", "2", "--quiet"], cwd=ROOT, start_new_session=True,
                               stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 120
        while len(rows(out / "results.csv")) < 4 and process.poll() is None and time.monotonic() < deadline:
            time.sleep(0.05)
        assert process.poll() is None, "the study ended before the signal"
        kept = len(rows(out / "results.csv"))
        os.killpg(process.pid, signal.SIGINT)
        _, err = process.communicate(timeout=60)
    finally:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGKILL)
    assert process.returncode == 130 and "Traceback" not in err, err
    done = rows(out / "results.csv")
    assert kept <= len(done) < 12 and len(done) % 4 == 0  # whole chains
    session = json.loads((out / "study.json").read_text())["sessions"][-1]
    assert session["interrupted"] is True and session["points_run"] == len(done)
    points = {r["point"] for r in done}
    assert {r["point"] for r in rows(out / "continuation.csv")} == points
    assert main(["study", str(study), "--out", str(out), "--workers", "1", "--quiet"]) == 0
    for name in FILES:
        assert rows(out / name) == rows(whole / name), name


def test_a_kill_between_the_writes_of_a_chain_resumes_running_that_chain_only(tmp_path, whole, capsys):
    """Issue 47: a kill between continuation.csv and study.json left a folder the same command refused (exit 2).
    study.json is now written before any chain runs; a chain's lines of continuation.csv and bifurcations.csv
    are appended before its rows of results.csv. The folder a kill leaves after those lines (the last one cut)
    and before the rows resumes: that chain runs again, the files end as the uninterrupted run's."""
    out = tmp_path / "out"
    out.mkdir()
    for name in ("study.json", *FILES):
        (out / name).write_bytes((whole / name).read_bytes())
    table = (out / "results.csv").read_text().splitlines(keepends=True)
    last = [line for line in table[1:] if line.split(",")[0] in {"8", "9", "10", "11"}]  # the third chain's rows
    (out / "results.csv").write_text("".join(line for line in table if line not in last))
    passes = (out / "continuation.csv").read_text()
    (out / "continuation.csv").write_text(passes[:-20])  # its last line cut
    assert main(["study", str(write_study(tmp_path)), "--out", str(out), "--workers", "1", "--quiet"]) == 0
    assert "12 points, 8 finished earlier, running 4 in 1 chain(s)" in capsys.readouterr().err
    for name in FILES:
        assert rows(out / name) == rows(whole / name), name


@pytest.mark.parametrize("damage", ["continuation.csv deleted", "bifurcations.csv of an earlier rpdrill's columns"])
def test_a_finished_folder_whose_chain_files_are_gone_or_older_runs_its_chains_again(tmp_path, whole, capsys, damage):
    """A misuse of one's own: the chains' files deleted, or written by an earlier rpdrill (bifurcations.csv without
    point_from, point_to): the results table alone does not make a chain done; every chain runs again and the
    files end as the uninterrupted run's (before, a chain was done by its rows alone: the lines would be lost)."""
    out = tmp_path / "out"
    out.mkdir()
    for name in ("study.json", *FILES):
        (out / name).write_bytes((whole / name).read_bytes())
    if damage.startswith("continuation"):
        (out / "continuation.csv").unlink()
    else:
        lines = (out / "bifurcations.csv").read_text().splitlines(keepends=True)
        (out / "bifurcations.csv").write_text("".join(line.split(",", 2)[2] for line in lines))
    assert main(["study", str(write_study(tmp_path)), "--out", str(out), "--workers", "1", "--quiet"]) == 0
    assert "12 points, 0 finished earlier, running 12 in 3 chain(s)" in capsys.readouterr().err
    for name in FILES:
        assert rows(out / name) == rows(whole / name), name


def test_a_finished_continuation_study_run_again_runs_nothing_and_records_its_wall_time(tmp_path, monkeypatch):
    """Issue 47: run again, a finished study said 'running 0' and rebuilt every model (its chains ran before the
    table knew they were done), and its sessions' wall times left the chains out."""
    calls, spent = [], []
    followed = continuation_runs.run_followed

    def timed(*args):
        calls.append(args)
        start = time.perf_counter()
        try:
            return followed(*args)
        finally:
            spent.append(time.perf_counter() - start)

    monkeypatch.setattr(continuation_runs, "run_followed", timed)
    study, out = write_study(tmp_path, scan={"impact.amplitude_n": [400e3], "impact.frequency_hz": FREQUENCIES}), \
        tmp_path / "out"
    rpdrill.run_study(study, workers=1, out=out)
    assert len(calls) == 2 * len(FREQUENCIES)  # both passes
    first = json.loads((out / "study.json").read_text())["sessions"][0]
    # the chains are in it: the session's wall time holds every chain's (was: at least half of the call's, which
    # failed when the call's first imports in a fresh worker took longer than the chains: 0.311 s of 0.641 s);
    # less half a millisecond: the session's wall time is rounded to 1 ms (studies.runtime.resumable)
    assert first["points_run"] == 4 and first["wall_time_s"] >= sum(spent) - 5e-4 and sum(spent) > 0
    calls.clear()
    rpdrill.run_study(study, workers=1, out=out)
    assert calls == []
    again = json.loads((out / "study.json").read_text())["sessions"][-1]
    assert again["points_run"] == 0 and again["wall_time_s"] < first["wall_time_s"]


def test_an_axis_out_of_order_is_followed_in_order_and_said(tmp_path, whole):
    """Issue 47: [29.5, 27.5, 28.5, 28.0] ran and wrote its tables in the typed order; the points run in
    increasing order (a warning says so) and give the ordered study's files; an axis in decreasing order is
    kept as given."""
    shuffled = write_study(tmp_path, scan={**STUDY["scan"], "impact.frequency_hz": [29.5, 27.5, 28.5, 28.0]})
    with pytest.warns(UserWarning, match=r"scan.impact.frequency_hz: \[29.5, 27.5, 28.5, 28.0\] is not in order; "
                                         r"a continuation follows it .* increasing order, \[27.5, 28.0, 28.5, 29.5\]"):
        study = rpdrill.load_study(shuffled)
    assert [p.values["impact.frequency_hz"] for p in study.points[:4]] == FREQUENCIES
    out = tmp_path / "out"
    with pytest.warns(UserWarning, match="is not in order"):  # (the command prints it as 'rpdrill: warning: ...')
        assert main(["study", str(shuffled), "--out", str(out), "--workers", "1", "--quiet"]) == 0
    for name in FILES:
        assert rows(out / name) == rows(whole / name), name
    falling = write_study(tmp_path, scan={**STUDY["scan"], "impact.frequency_hz": FREQUENCIES[::-1]})
    assert [p.values["impact.frequency_hz"] for p in rpdrill.load_study(falling).points[:4]] == FREQUENCIES[::-1]


@pytest.mark.parametrize("target", ["/proc/self", "/proc"])
@pytest.mark.parametrize("command", [["simulate", str(DRILL), "--overwrite"], ["study", "STUDY"]])
def test_an_out_linked_into_proc_is_refused_saying_why(tmp_path, capsys, target, command):
    """Issue 47: --out linked to /proc/self with --overwrite said 'another rpdrill run writes there' (filelock
    reports a folder that takes no files as a lock held); a folder that cannot be made below /proc ended as a
    run that could not finish (exit 1)."""
    link = tmp_path / "link"
    link.symlink_to(target)
    out = link if target == "/proc/self" else link / "new"
    arguments = [str(write_study(tmp_path)) if word == "STUDY" else word for word in command]
    assert main([arguments[0], arguments[1], "--out", str(out), *arguments[2:], "--quiet"]) == 2
    err = capsys.readouterr().err
    assert f"--out: {out}: cannot" in err and "No such file or directory" in err
    assert "another rpdrill run" not in err and "could not finish" not in err
