"""Interrupts with real processes (issue #30): a command sent SIGINT or SIGTERM (to it alone or to its
whole process group), or killed, exits within 2 s keeping every point finished before the signal, no
process of its run is left 2 s later, and a rerun completes with the rows of an uninterrupted run."""

from __future__ import annotations

import contextlib
import csv
import json
import os
import signal
import subprocess
import sys
import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import pytest
import yaml
from commands import main
from scenes import PAPER_BASE

import rpdrill

# the advice's grids made coarse for an advice's reruns
UNITS = ("rpdrill.studies.advice.advice_search",)

ROOT = Path(__file__).resolve().parents[1]
EXIT_WITHIN_S = 2.0
LEFT_WITHIN_S = 2.0  # no process of a stopped run's session may be left this long after the command exited


@dataclass
class Stopped:
    status: int
    exit_after_s: float  # from the signal to the exit
    kept_at_signal: int  # points finished when the signal was sent
    left: list[str]  # processes of the run's session alive LEFT_WITHIN_S after it exited
    err: str


def command(*args: str) -> list[str]:
    return [sys.executable, "-m", "rpdrill.studies.cli", *args]


def run_here(args: list[str]) -> None:
    """A command of :func:`command` on the exact formulation run to its end in this process (a rerun or an
    uninterrupted run: only the run that is stopped needs a process of its own). Not on Exudyn: the program
    loads Exudyn's build without range checks, this process the regular one, and their figures differ in the
    last bits (a study's bit velocity peak 0.027096719349116293 against ...113247)."""
    assert main(args[3:]) == 0


def stop(args: list[str], finished: Callable[[], int], signum: int, group: bool | None = True, at_least: int = 1,
         timeout_s: float = 240) -> Stopped:
    """Run ``args`` in a session of its own; once ``finished()`` reaches ``at_least``, send ``signum`` to
    its whole process group (``group``), the command alone, or one of its workers alone (None); how it
    ended."""
    process = subprocess.Popen(args, cwd=ROOT, start_new_session=True, stdout=subprocess.DEVNULL,
                               stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline and process.poll() is None and finished() < at_least:
            time.sleep(0.05)
        assert process.poll() is None, "the command ended before the signal"
        kept = finished()
        sent = time.monotonic()
        if group is None:  # one of its workers alone
            children = Path(f"/proc/{process.pid}/task/{process.pid}/children").read_text().split()
            os.kill(int(children[0]), signum)
        else:
            (os.killpg if group else os.kill)(process.pid, signum)
        _, err = process.communicate(timeout=60)
        after = time.monotonic() - sent
        return Stopped(process.returncode, after, kept, left_after(process.pid, LEFT_WITHIN_S), err)
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(process.pid, signal.SIGKILL)  # whatever of the run is left (its own process group)


def left_after(session: int, within_s: float) -> list[str]:
    """The processes of ``session`` alive ``within_s`` after its leader exited: polled, and none once the
    session is empty (a session with no process left cannot gain one: a new process needs a parent in it)."""
    deadline = time.monotonic() + within_s
    while True:
        left = subprocess.run(["pgrep", "-s", str(session)], capture_output=True, text=True, check=False).stdout.split()
        if not left or time.monotonic() >= deadline:
            return left
        time.sleep(0.05)


def csv_rows(path: Path) -> list[dict[str, str]]:
    if not path.exists():
        return []
    with path.open(newline="", encoding="utf-8") as handle:
        return [r for r in csv.DictReader(handle) if None not in r.values()]


def lines(path: Path) -> int:
    return len([line for line in path.read_text().splitlines() if line.strip()]) if path.exists() else 0


def without_times(rows: list[dict[str, str]]) -> list[dict[str, str]]:
    return sorted(({k: v for k, v in r.items() if k not in ("wall_time_s", "cpu_time_s")} for r in rows),
                  key=lambda r: int(r["point"]))


def write(path: Path, data: dict) -> Path:
    path.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    return path


def study_file(tmp_path: Path) -> Path:
    """12 points of about 0.5 s each (3 s of the test drill on Exudyn)."""
    return write(tmp_path / "long.yaml", {
        "name": "long", "base_scene": str(PAPER_BASE), "base_overrides": {"solver.end_time_s": 3.0},
        "scan": {"impact.frequency_hz": [40, 42, 44, 46, 48, 50, 52, 54, 56, 58, 60, 62]},
        "metrics": ["penetration_rate_m_per_s", "bit_velocity_peak_m_per_s"]})


def assert_stopped_cleanly(stopped: Stopped, status: int, kept: int) -> None:
    assert stopped.status == status, stopped.err
    assert stopped.exit_after_s < EXIT_WITHIN_S, stopped
    assert not stopped.left, stopped
    assert "Traceback" not in stopped.err and "internal error" not in stopped.err
    assert kept >= stopped.kept_at_signal  # every point finished before the signal is kept


@pytest.mark.slow
@pytest.mark.parametrize("signum, group", [(signal.SIGINT, True), (signal.SIGTERM, True), (signal.SIGTERM, False)])
def test_a_study_stops_within_2_s_keeping_its_finished_points(tmp_path, signum, group):
    out = tmp_path / "out"
    stopped = stop(command("study", str(study_file(tmp_path)), "--out", str(out), "--workers", "2", "--quiet"),
                   lambda: len(csv_rows(out / "results.csv")), signum, group, at_least=2)
    kept = csv_rows(out / "results.csv")
    assert_stopped_cleanly(stopped, 130 if signum == signal.SIGINT else 143, len(kept))
    assert len(kept) < 12 and all(r["status"] != "failed" for r in kept)
    assert json.loads((out / "study.json").read_text())["sessions"][-1]["interrupted"] is True


@pytest.mark.slow
def test_a_killed_study_leaves_no_worker(tmp_path):
    out = tmp_path / "out"
    stopped = stop(command("study", str(study_file(tmp_path)), "--out", str(out), "--workers", "2", "--quiet"),
                   lambda: len(csv_rows(out / "results.csv")), signal.SIGKILL, group=False, at_least=1)
    assert stopped.status == -signal.SIGKILL and not stopped.left, stopped


@pytest.mark.slow
def test_a_worker_killed_alone_stops_the_run_keeping_its_finished_points(tmp_path):
    out = tmp_path / "out"
    stopped = stop(command("study", str(study_file(tmp_path)), "--out", str(out), "--workers", "2", "--quiet"),
                   lambda: len(csv_rows(out / "results.csv")), signal.SIGTERM, group=None, at_least=1)
    assert stopped.status == 143 and "worker process ended" in stopped.err, stopped
    assert stopped.exit_after_s < 5 and not stopped.left, stopped
    assert len(csv_rows(out / "results.csv")) >= stopped.kept_at_signal


def slow_points(tmp_path: Path) -> Path:
    """4 points of several CPU seconds each (30 s of the test drill on Exudyn), only the rate recorded."""
    return write(tmp_path / "slow.yaml", {
        "name": "slow", "base_scene": str(PAPER_BASE), "base_overrides": {"solver.end_time_s": 30.0},
        "scan": {"impact.frequency_hz": [40, 45, 50, 55]}, "metrics": ["penetration_rate_m_per_s"]})


def cpu_s(pid: str) -> float:
    """CPU seconds (user + system) process ``pid`` has used, 0 if it is gone."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except OSError:
        return 0.0
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")  # utime, stime: fields 14, 15


def workers_into_their_points(study: Path, workers: int = 2, cpu_seconds: float = 1.0) -> Callable[[], int]:
    """1 once ``workers`` pool workers of the command running ``study`` (forked from it: its command line, another
    parent than this process) have each run ``cpu_seconds`` of their points: then in the middle of them."""
    def into() -> int:
        busy = 0
        for proc in Path("/proc").glob("[0-9]*"):
            try:
                named = str(study) in (proc / "cmdline").read_text()
                parent = (proc / "stat").read_text().rsplit(")", 1)[1].split()[1]
            except OSError:
                continue
            if named and parent != str(os.getpid()) and cpu_s(proc.name) >= cpu_seconds:
                busy += 1
        return int(busy >= workers)
    return into


@pytest.mark.slow
def test_a_killed_command_leaves_no_worker_in_the_middle_of_a_point(tmp_path):
    """Why a pool worker asks the kernel to end it with its command (PR_SET_PDEATHSIG,
    studies.runtime.interrupts.worker_ends_with_its_command): the command killed (SIGKILL: none of its
    own code runs) while its workers are seconds from the end of their points; 2 s later no worker is
    left. Without it each worker runs its point to the end before it finds its command gone (seen, with the
    call commented out: the workers still running 2 s after the kill)."""
    study = slow_points(tmp_path)
    stopped = stop(command("study", str(study), "--out", str(tmp_path / "out"), "--workers", "2", "--quiet"),
                   workers_into_their_points(study), signal.SIGKILL, group=False, at_least=1)
    assert stopped.status == -signal.SIGKILL and not stopped.left, stopped


@pytest.mark.slow
def test_a_stop_does_not_wait_for_the_points_under_way(tmp_path):
    """Why the command ends its workers on a stop (studies.runtime.pools._terminate_workers: Python 3.14's
    ``terminate_workers``, before it the executor's own processes): Ctrl-C while both workers are seconds
    from the end of their points (they ignore it: the command stops the run) exits within 2 s. Without it
    the pool's shutdown waits for the points under way (seen, with the call commented out: no exit within
    the 60 s this test waits, on the shared 2-core machine)."""
    study = slow_points(tmp_path)
    stopped = stop(command("study", str(study), "--out", str(tmp_path / "out"), "--workers", "2", "--quiet"),
                   workers_into_their_points(study), signal.SIGINT, group=True, at_least=1)
    assert stopped.status == 130 and stopped.exit_after_s < EXIT_WITHIN_S and not stopped.left, stopped
    assert "Traceback" not in stopped.err


def exact_study_file(tmp_path: Path) -> Path:
    """12 points of about 0.25 CPU s each on the exact formulation (20 s of the test drill): what is under test
    is the stop and the resume, not Exudyn (the study's stop on Exudyn: the tests above), and the reruns run
    in the test's process (:func:`run_here`)."""
    return write(tmp_path / "exact.yaml", {
        "name": "exact", "base_scene": str(PAPER_BASE),
        "base_overrides": {"solver": {"end_time_s": 20.0, "formulation": "exact"}},
        "scan": {"impact.frequency_hz": [40, 42, 44, 46, 48, 50, 52, 54, 56, 58, 60, 62]},
        "metrics": ["penetration_rate_m_per_s", "bit_velocity_peak_m_per_s"]})


@pytest.mark.slow
def test_an_interrupted_study_resumes_to_the_rows_of_an_uninterrupted_run(tmp_path):
    study, out, whole = exact_study_file(tmp_path), tmp_path / "out", tmp_path / "whole"
    stopped = stop(command("study", str(study), "--out", str(out), "--workers", "2", "--quiet"),
                   lambda: len(csv_rows(out / "results.csv")), signal.SIGINT, at_least=3)
    kept = csv_rows(out / "results.csv")
    assert_stopped_cleanly(stopped, 130, len(kept))
    assert len(kept) < 12
    for folder in (out, whole):
        run_here(command("study", str(study), "--out", str(folder), "--workers", "2", "--quiet"))
    assert without_times(csv_rows(out / "results.csv")) == without_times(csv_rows(whole / "results.csv"))


def sensitivity_file(tmp_path: Path) -> Path:
    """The tiny sensitivity study of test_sensitivity, on the exact formulation (what is under test is the
    stop and the resume, not Exudyn: 28 CPU s of the test on Exudyn, 13 on the exact formulation)."""
    return write(tmp_path / "sensitivity.yaml", {
        "name": "tiny", "base_scene": str(PAPER_BASE),
        "base_overrides": {"solver": {"end_time_s": 0.6, "formulation": "exact"},
                           "metrics": {"transient_blows": 10, "block_blows": 5},
                           "rock.threshold_n": 60e3, "feed.force_n": 20e3},
        "frequency_hz": {"from": 35, "to": 70, "step": 5},
        "metrics": ["penetration_rate_m_per_s", "collar_velocity_peak_m_per_s"],
        "scans": [{"label": "160 kN", "overrides": {"impact.amplitude_n": 160e3}},
                  {"label": "220 kN", "overrides": {"impact.amplitude_n": 220e3}}],
        "parameters": ["drill_string.bodies.collar.mass_kg", "rock.stiffness_n_per_m"]})


@pytest.mark.slow
def test_a_sensitivity_study_stops_within_2_s_and_resumes_to_the_same_rows(tmp_path):
    study, out, whole = sensitivity_file(tmp_path), tmp_path / "out", tmp_path / "whole"
    stopped = stop(command("sensitivity", str(study), "--out", str(out), "--workers", "2", "--quiet"),
                   lambda: len(csv_rows(out / "results.csv")), signal.SIGINT, at_least=1)
    kept = csv_rows(out / "results.csv")
    assert_stopped_cleanly(stopped, 130, len(kept))
    assert 1 <= len(kept) < 10
    for folder in (out, whole):
        run_here(command("sensitivity", str(study), "--out", str(folder), "--workers", "2", "--quiet"))
    assert without_times(csv_rows(out / "results.csv")) == without_times(csv_rows(whole / "results.csv"))


def calibration_file(tmp_path: Path) -> Path:
    """The tiny calibration of test_calibrate, on the exact formulation (what is under test is the stop and
    the resume, not Exudyn: 33 CPU s of the test on Exudyn, 9 on the exact formulation): 10 evaluations of
    3 scans of 6 frequencies."""
    return write(tmp_path / "calibration.yaml", {
        "name": "tiny", "base_scene": str(PAPER_BASE),
        "base_overrides": {"solver": {"end_time_s": 0.4, "formulation": "exact"},
                           "metrics": {"transient_blows": 5, "block_blows": 5}},
        "frequency_hz": {"from": 40, "to": 90, "step": 10}, "refine_hz": 2,
        "parameters": {"drill_string.bodies.collar.mass_kg": {"bounds": [2000.0, 4000.0], "scale": "log",
                                                              "reason": "sets the rock mode"},
                       "impact.duration_s": {"bounds": [0.8e-3, 1.4e-3], "reason": "piston length"}},
        "targets": [{"label": "a", "optimum_hz": 60, "band_hz": [55, 65], "overrides": {"impact.amplitude_n": 400e3}},
                    {"label": "b", "optimum_hz": 70, "metric": "collar_velocity_peak_m_per_s"}],
        "search": {"popsize": 2, "max_generations": 1, "seed": 3}})


@pytest.mark.slow
def test_a_calibration_stops_within_2_s_and_resumes_to_the_same_evaluations(tmp_path):
    spec, out, whole = calibration_file(tmp_path), tmp_path / "out", tmp_path / "whole"
    stopped = stop(command("calibrate", str(spec), "--out", str(out), "--workers", "2", "--quiet"),
                   lambda: lines(out / "evaluations.jsonl"), signal.SIGINT, at_least=1)
    assert_stopped_cleanly(stopped, 130, lines(out / "evaluations.jsonl"))
    for folder in (out, whole):
        run_here(command("calibrate", str(spec), "--out", str(folder), "--workers", "2", "--quiet"))

    def by_unit(folder: Path) -> dict[tuple[float, ...], float]:
        records = [json.loads(line) for line in (folder / "evaluations.jsonl").read_text().splitlines()]
        return {tuple(r["unit"]): r["objective"] for r in records}

    assert by_unit(out) == by_unit(whole)
    assert (out / "calibrated_scene.yaml").read_text() == (whole / "calibrated_scene.yaml").read_text()


@pytest.mark.slow
def test_an_advice_stops_within_2_s_and_resumes_to_the_same_advice(tmp_path, monkeypatch):
    """rpdrill advise keeps every point run before the signal (evaluations.jsonl) and, run again,
    replays them and gives the advice of an uninterrupted run. The reruns here draw the curves and the map
    coarse (what is checked is the search's replay; the stop comes within its first 32 points, before them)."""
    monkeypatch.setattr("rpdrill.studies.advice.advice_search.MAP_POINTS", 3)
    monkeypatch.setattr("rpdrill.studies.advice.advice_search.SLICE_POINTS", 5)
    # 1 s of the drill (45 blows at the lowest frequency; 3 s before): ~2 CPU s less a command, and the
    # command still runs for seconds after its 10th point
    scene = write(tmp_path / "drill.yaml", {**yaml.safe_load(PAPER_BASE.read_text()), "solver": {"end_time_s": 1.0}})
    out, whole = tmp_path / "out", tmp_path / "whole"

    def advise(folder: Path) -> list[str]:
        return command("advise", str(scene), "--frequency-hz", "45", "75", "--feed-kn", "10", "30", "--popsize", "4",
                       "--generations", "3", "--out", str(folder), "--workers", "2", "--quiet")

    stopped = stop(advise(out), lambda: lines(out / "evaluations.jsonl"), signal.SIGINT, at_least=10)
    assert_stopped_cleanly(stopped, 130, lines(out / "evaluations.jsonl"))
    assert not (out / "advice.json").exists()
    for folder in (out, whole):  # the advice's search runs on the exact formulation (docs/advice.md)
        run_here(advise(folder))
    first, second = (json.loads((f / "advice.json").read_text())["results"][0] for f in (out, whole))
    assert first["replayed"] >= stopped.kept_at_signal and second["replayed"] == 0
    sessions = json.loads((out / "checkpoint.json").read_text())["sessions"]  # recorded as calibrate's are
    assert [s["interrupted"] for s in sessions] == [True, False] and sessions[0]["points_run"] >= stopped.kept_at_signal
    assert sessions[1]["points_replayed"] == first["replayed"]
    assert (first["best"], first["best_value"]) == (second["best"], second["best_value"])


def test_the_cancelled_futures_race_of_a_stop_prints_no_traceback():
    """A stop that ends the workers can make concurrent.futures' management thread set an exception on
    a future the stop cancelled (InvalidStateError; seen once in CI and once in seven Ctrl-Cs of a study):
    nothing printed for it while a pool lives; another thread's exception still is."""
    code = """
import threading
from concurrent.futures import InvalidStateError
from rpdrill.studies.runtime.pools import process_pool

def fail(error):
    raise error

with process_pool(1):
    for error in (InvalidStateError("CANCELLED: <Future state=cancelled>"), ValueError("a real one")):
        thread = threading.Thread(target=fail, args=(error,))
        thread.start()
        thread.join()
"""
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=60)
    assert "InvalidStateError" not in done.stderr and "ValueError: a real one" in done.stderr


@pytest.mark.parametrize("after_s", [0.2, 0.5, 1.0])
def test_a_ctrl_c_while_the_program_starts_prints_one_line(tmp_path, after_s):
    """The program takes its Ctrl-C handler before its libraries load (a second or two): a Ctrl-C then
    prints one line (it printed Python's KeyboardInterrupt traceback) and nothing is written."""
    out = tmp_path / "out"
    process = subprocess.Popen(command("simulate", str(PAPER_BASE), "--out", str(out), "--quiet"), cwd=ROOT,
                               start_new_session=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    time.sleep(after_s)
    sent = time.monotonic()
    os.killpg(process.pid, signal.SIGINT)
    _, err = process.communicate(timeout=60)
    assert process.returncode == 130 and time.monotonic() - sent < EXIT_WITHIN_S, err
    assert len(err.splitlines()) == 1 and "interrupted" in err and "Traceback" not in err, err
    assert not out.exists()



def test_a_ctrl_c_caught_inside_string_code_exits_with_the_commands_status(tmp_path):
    """A Ctrl-C that lands in code run from a string (a namedtuple numba makes as it loads) is caught as any
    other, and the program exits 130: CPython killed itself by SIGINT at exit (status -2) when run as
    ``python -m``. The command here raises the interrupt from such code at once."""
    (tmp_path / "stopped_in_string_code.py").write_text(
        "from rpdrill.studies.cli import main, simulate_command\n"
        "simulate_command.run = lambda args: exec('raise KeyboardInterrupt')\n"
        "main.console()\n")
    done = subprocess.run([sys.executable, "-m", "stopped_in_string_code", "simulate", str(PAPER_BASE), "--out",
                           str(tmp_path / "out")], cwd=tmp_path, capture_output=True, text=True, timeout=120, check=False)
    assert done.returncode == 130, done.stderr
    assert done.stderr == "rpdrill: interrupted; finished results are kept\n"


@pytest.mark.parametrize("interrupt", [KeyboardInterrupt, type("Terminated", (KeyboardInterrupt,), {})])
def test_a_ctrl_c_during_an_exudyn_solve_is_the_callers_interrupt_not_a_failed_run(interrupt):
    """A Ctrl-C reaching a Python function Exudyn's solver calls (here the progress callback) reaches the
    caller of rpdrill.simulate as the interrupt it was (it was a SimulationFailed wrapping Exudyn's
    ModelError), and Exudyn's "DYNAMIC SOLVER FAILED" lines are not issued as warnings (the command line
    printed them before its one line)."""
    def progress(time_s: float) -> None:
        if time_s > 0.01:
            raise interrupt()

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with pytest.raises(interrupt) as raised:
            rpdrill.simulate(PAPER_BASE, formulation="exudyn", progress=progress)
    assert type(raised.value) is interrupt
    assert [str(warning.message) for warning in caught] == []

@pytest.mark.slow
def test_a_study_on_a_dask_local_cluster_stops_within_2_s_without_worker_tracebacks(tmp_path):
    """The cluster's workers are forked ignoring Ctrl-C (studies.runtime.pools): a Ctrl-C of the whole
    process group reaches the command only, which ends them; it printed two workers' tracebacks and
    took up to 4 s."""
    out = tmp_path / "out"
    stopped = stop(command("study", str(study_file(tmp_path)), "--out", str(out), "--dask", "--workers", "2",
                           "--quiet"), lambda: len(csv_rows(out / "results.csv")), signal.SIGINT, at_least=1)
    kept = csv_rows(out / "results.csv")
    assert_stopped_cleanly(stopped, 130, len(kept))
    assert len(stopped.err.splitlines()) == 2, stopped.err  # what it runs, and the one line of the stop
    assert json.loads((out / "study.json").read_text())["sessions"][-1]["interrupted"] is True

