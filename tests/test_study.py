"""YAML studies: expansion, end-to-end runs, resume after a kill, refusal of a changed study,
Dask, and bad input."""

from __future__ import annotations

import contextlib
import csv
import hashlib
import json
import logging
import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import yaml
from commands import main
from scenes import PAPER_BASE, scene_dict

import rpdrill
from rpdrill.models.definition.outputs import METRICS
from rpdrill.studies.runtime.pools import (
    BATCHES_PER_WORKER,
    ONE_THREAD,
    _dask_logs_quiet,
    batches,
    process_pool,
)

# the metrics' registry, and the process pools' batches and threads
UNITS = ("rpdrill.models.definition.outputs", "rpdrill.studies.runtime.pools")

load_study = rpdrill.load_study

ROOT = Path(__file__).resolve().parents[1]
SHORT = {"solver.end_time_s": 0.15, "metrics": {"transient_blows": 2, "block_blows": 2}}


def write_study(path: Path, **changes) -> Path:
    """A small study on the test drill (4 points, 0.15 s each), with ``changes`` applied."""
    study = {
        "name": "small",
        "base_scene": str(PAPER_BASE),
        "base_overrides": SHORT,
        "scan": {"impact.frequency_hz": [40, 60], "impact.amplitude_n": [160.0e3, 220e3]},
        "metrics": ["penetration_rate_m_per_s", "bit_velocity_peak_m_per_s"],
        "plots": [
            {"x": "impact.frequency_hz", "y": "bit_velocity_peak_m_per_s", "curves": "impact.amplitude_n"},
            {"kind": "map", "x": "impact.frequency_hz", "y": "impact.amplitude_n", "z": "bit_velocity_peak_m_per_s"},
        ],
    }
    study.update(changes)
    path.write_text(yaml.safe_dump(study, sort_keys=False), encoding="utf-8")
    return path


def rows(out: Path) -> list[dict[str, str]]:
    with (out / "results.csv").open(newline="") as handle:
        return list(csv.DictReader(handle))


@pytest.fixture(scope="module")
def small_run(tmp_path_factory) -> tuple[Path, Path, int]:
    base = tmp_path_factory.mktemp("small")
    study, out = write_study(base / "small.yaml"), base / "out"
    return study, out, main(["study", str(study), "--out", str(out), "--workers", "2", "--quiet"])


def test_axes_expand_and_combine(tmp_path):
    study = load_study(write_study(
        tmp_path / "s.yaml",
        scan={"impact.frequency_hz": {"from": 40, "to": 50, "step": 5},
              "rock.stiffness_n_per_m": {"from": 1e8, "to": 1e9, "num": 3, "spacing": "log"},
              "rock.damping_n_s_per_m": [1e3, 2e3, 3e3]},
        combine=[["rock.stiffness_n_per_m", "rock.damping_n_s_per_m"]], plots=[]))
    assert study.axes["impact.frequency_hz"] == [40.0, 45.0, 50.0]
    assert study.axes["rock.stiffness_n_per_m"] == pytest.approx([1e8, 1e8 * 10**0.5, 1e9])
    assert len(study.points) == 9
    assert {(p.scene.rock.stiffness_n_per_m, p.scene.rock.damping_n_s_per_m) for p in study.points} \
        == set(zip(study.axes["rock.stiffness_n_per_m"], [1e3, 2e3, 3e3]))


@pytest.mark.parametrize("name, count", [("frequency_scan", 23), ("impulse_scan", 92), ("stiffness_scan", 92),
                                         ("rock_table", 69)])
def test_paper_studies_expand(name, count):
    study = load_study(ROOT / "studies" / "paper" / f"{name}.yaml")
    assert len(study.points) == count
    assert study.points[0].scene.impact.frequency_hz == 10.0


def test_rock_name_axis_supplies_rock_values():
    study = load_study(ROOT / "studies" / "paper" / "rock_table.yaml")
    rocks = {p.scene.rock.name: p.simulation.resolved_scene()["rock"]["stiffness_n_per_m"] for p in study.points}
    assert rocks == {"conglomerate": 8.4e8, "sandstone": 5.1e8, "soft_limestone": 2.1e8}


def test_points_run_on_a_base_scene_with_default_solver(tmp_path):
    base = {key: value for key, value in scene_dict().items() if key != "solver"}
    study = load_study(write_study(tmp_path / "s.yaml", base_scene=base, scan={"impact.frequency_hz": [40]},
                                   base_overrides=SHORT, plots=[]))
    table = rpdrill.run_study(study, workers=1)
    assert list(table["status"]) == ["ok"], list(table["error"])


def test_a_study_collects_every_metric_a_run_gives():
    """Without ``metrics`` a study collects every metric (models.definition.outputs.METRICS), the same a
    run of its scene gives (those of a piston scene and of a scene with rods left out)."""
    scene = rpdrill.Scene.model_validate({**scene_dict(), "metrics": SHORT["metrics"], "solver": {"end_time_s": 0.1}})
    elsewhere = {name for name, need in METRICS.items() if {"piston", "rods"} & need.data}  # outputs: RODS
    assert elsewhere and set(rpdrill.simulate(scene).metrics) == set(METRICS) - elsewhere


def test_study_hash_is_the_json_of_its_scenes_and_metrics(tmp_path):
    """Study.hash, assembled from the points' scene keys, is the hash of the JSON of the point scenes and
    metrics: folders written before it was assembled so stay resumable."""
    study = load_study(write_study(tmp_path / "hash.yaml"))
    content = {"points": [p.simulation.resolved_scene() for p in study.points], "metrics": list(study.spec.metrics)}
    assert study.hash == hashlib.sha256(json.dumps(content, sort_keys=True).encode()).hexdigest()
    assert len(set(study.scene_keys)) == len(study.points)


def test_study_end_to_end(small_run):
    study, out, status = small_run
    assert status == 0
    table = rows(out)
    assert sorted(int(r["point"]) for r in table) == [0, 1, 2, 3]
    assert all(r["status"] == "ok" and float(r["bit_velocity_peak_m_per_s"]) > 0 for r in table)
    assert {(float(r["impact.frequency_hz"]), float(r["impact.amplitude_n"])) for r in table} \
        == {(40, 160e3), (40, 220e3), (60, 160e3), (60, 220e3)}
    provenance = json.loads((out / "study.json").read_text())
    assert provenance["hash"] == load_study(study).hash
    assert provenance["exudyn_version"] and provenance["rpdrill_version"]
    assert provenance["resolved_study"]["base_scene"]["rock"]["threshold_n"] == 138e3
    assert provenance["resolved_study"]["base_scene"]["solver"]["end_time_s"] == 0.15
    assert len(provenance["point_wall_time_s"]) == 4
    assert len(list(out.glob("*.png"))) == 2


def test_several_studies_run_on_one_pool_into_folders_of_their_names(small_run, tmp_path, capsys):
    """Two studies in one command: each in --out/<file name>, with the rows and plots a command of its own
    gives; their points go to the workers as one run, and the point both have (40 Hz, 220 kN) runs once,
    its result written to both."""
    study, single, _ = small_run
    other = write_study(tmp_path / "other.yaml", name="other",
                        scan={"impact.frequency_hz": [40, 70], "impact.amplitude_n": [220e3]}, plots=[{"x": "impact.frequency_hz", "y": "bit_velocity_peak_m_per_s"}])
    out = tmp_path / "both"
    assert main(["study", str(study), str(other), "--out", str(out), "--workers", "2", "--quiet"]) == 0
    assert "other: 2 points, 0 finished earlier, 1 the same as another point (run once), running 1" \
        in capsys.readouterr().err

    def table(folder: Path) -> list[dict[str, str]]:
        return sorted(({k: v for k, v in row.items() if k != "wall_time_s"} for row in rows(folder)),
                      key=lambda row: int(row["point"]))

    assert table(out / "small") == table(single)
    shared = [next(r for r in rows(out / name) if float(r["impact.frequency_hz"]) == 40
                   and float(r["impact.amplitude_n"]) == 220e3) for name in ("small", "other")]
    assert shared[0] == {**shared[1], "point": shared[0]["point"]}  # the same run: its wall time too
    sessions = [json.loads((out / name / "study.json").read_text())["sessions"][-1] for name in ("small", "other")]
    assert [(s["points_run"], s["points_copied"]) for s in sessions] == [(4, 0), (1, 1)]
    assert len(table(out / "other")) == 2
    assert len(list((out / "small").glob("*.png"))) == 2 and len(list((out / "other").glob("*.png"))) == 1


def test_two_studies_of_one_name_are_refused_before_any_runs(tmp_path, capsys):
    first, second = tmp_path / "a" / "scan.yaml", tmp_path / "b" / "scan.yaml"
    for path in (first, second):
        path.parent.mkdir()
        write_study(path)
    assert main(["study", str(first), str(second), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    assert "several files named scan" in capsys.readouterr().err and not (tmp_path / "out").exists()


def test_failed_point_is_recorded_and_the_study_goes_on(tmp_path):
    study = write_study(tmp_path / "fail.yaml", scan={"solver.step_s": [2e-5, 1e-3]},
                        base_overrides={**SHORT, "impact.frequency_hz": 40}, plots=[])
    with pytest.warns(rpdrill.StepLimitWarning, match="exceeds the stability limit"):
        assert main(["study", str(study), "--out", str(tmp_path / "out"), "--workers", "1", "--quiet"]) == 1
    by_step = {float(r["solver.step_s"]): r for r in rows(tmp_path / "out")}
    assert by_step[2e-5]["status"] == "ok" and by_step[2e-5]["error"] == ""
    error = by_step[1e-3]["error"]
    assert by_step[1e-3]["status"] == "failed" and "SimulationFailed" in error
    assert "diverged at t =" in error and "rk44" in error and "try solver.step_s" in error  # the run's message
    assert by_step[1e-3]["penetration_rate_m_per_s"] == ""


def test_finished_study_rerun_skips_all(small_run, capsys):
    study, out, _ = small_run
    before = sorted(rows(out), key=lambda r: int(r["point"]))
    assert main(["study", str(study), "--out", str(out), "--workers", "1", "--quiet"]) == 0
    assert "4 finished earlier, running 0" in capsys.readouterr().err
    assert rows(out) == before  # rewritten in point order, nothing run again


def test_changed_study_is_refused(small_run, capsys):
    study, out, _ = small_run
    changed = write_study(study.with_name("changed.yaml"),
                          scan={"impact.frequency_hz": [40, 65], "impact.amplitude_n": [160e3, 220e3]})
    assert main(["study", str(changed), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "changed.yaml" in err and "differs" in err and str(out) in err


def test_resume_after_kill(tmp_path, capsys):
    study = write_study(tmp_path / "resume.yaml", base_overrides={"solver.end_time_s": 0.4},
                        scan={"impact.frequency_hz": [40, 45, 50, 55, 60, 65]}, plots=[])
    out = tmp_path / "out"
    process = subprocess.Popen([sys.executable, "-m", "rpdrill.studies.cli", "study", str(study), "--out", str(out),
                                "--workers", "1", "--quiet"], cwd=ROOT, start_new_session=True,
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and process.poll() is None:
        if (out / "results.csv").exists() and len(rows(out)) >= 2:
            break
        time.sleep(0.02)
    os.killpg(process.pid, signal.SIGKILL)
    process.wait()
    before = {r["point"]: r for r in rows(out)}
    assert 2 <= len(before) < 6, "the kill should come mid-run"
    assert main(["study", str(study), "--out", str(out), "--workers", "1", "--quiet"]) == 0
    assert f"{len(before)} finished earlier, running {6 - len(before)}" in capsys.readouterr().err
    after = rows(out)
    assert sorted(int(r["point"]) for r in after) == list(range(6))
    assert all(r == before[r["point"]] for r in after if r["point"] in before)


def worker_state(_: int) -> tuple[int, int]:
    """A pool worker's process id and the BLAS threads it runs (a top-level function: it is pickled)."""
    from threadpoolctl import threadpool_info

    return os.getpid(), max((pool["num_threads"] for pool in threadpool_info()), default=1)


def test_pool_workers_run_one_blas_thread_each_in_their_own_processes():
    """Two workers on two cores run two BLAS threads, not four; a second pool starts new workers."""
    first, second = ([s for batch in run(worker_state, [0, 1, 2, 3]) for s in batch]
                     for run in (process_pool_runner(), process_pool_runner()))
    for states in (first, second):
        assert all(threads == 1 and pid != os.getpid() for pid, threads in states)
    assert not {pid for pid, _ in first} & {pid for pid, _ in second}


def process_pool_runner() -> Any:
    """A two-worker process pool's runner, closed once its results are read."""
    def run(function: Any, arguments: list[int]) -> Iterator[list[Any]]:
        with process_pool(2) as runner:
            yield from runner(function, arguments)
    return run


@pytest.mark.parametrize("count, workers", [(0, 2), (1, 2), (7, 2), (92, 2), (207, 3)])
def test_batches_keep_every_point_once_in_order_and_even(count, workers):
    parts = batches(list(range(count)), workers)
    assert [p for part in parts for p in part] == list(range(count))
    assert len(parts) <= workers * BATCHES_PER_WORKER and all(parts)
    assert max(map(len, parts), default=0) - min(map(len, parts), default=0) <= 1


@pytest.mark.slow
def test_sigterm_stops_like_ctrl_c(tmp_path):
    """SIGTERM to the command (its pool workers busy): a message, exit 143, the finished rows kept, the
    interrupted session recorded in study.json, no traceback and no leaked semaphores."""
    study = write_study(tmp_path / "term.yaml", base_overrides={"solver.end_time_s": 3.0}, plots=[],
                        scan={"impact.frequency_hz": [40, 42, 44, 46, 48, 50, 52, 54, 56, 58]})
    out = tmp_path / "out"
    process = subprocess.Popen([sys.executable, "-m", "rpdrill.studies.cli", "study", str(study), "--out", str(out),
                                "--workers", "2", "--quiet"], cwd=ROOT, start_new_session=True,
                               stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and process.poll() is None:
            if (out / "results.csv").exists() and len(rows(out)) >= 1:
                break
            time.sleep(0.05)
        process.send_signal(signal.SIGTERM)  # the command only, not its workers
        _, err = process.communicate(timeout=120)
    finally:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGKILL)
    assert process.returncode == 143, err
    assert "terminated" in err and "Traceback" not in err and "leaked" not in err
    kept = rows(out)
    assert 1 <= len(kept) < 10 and all(r["status"] == "ok" for r in kept)
    session = json.loads((out / "study.json").read_text())["sessions"][-1]
    assert session["interrupted"] is True and session["points_run"] == len(kept)


@pytest.mark.slow
def test_dask_local_cluster(tmp_path):
    study = write_study(tmp_path / "dask.yaml", scan={"impact.frequency_hz": [40, 60]}, plots=[])
    out = tmp_path / "out"
    assert main(["study", str(study), "--out", str(out), "--dask", "--workers", "2", "--quiet"]) == 0
    assert sorted(r["point"] for r in rows(out)) == ["0", "1"]
    assert json.loads((out / "study.json").read_text())["sessions"][0]["runner"] == "dask (LocalCluster)"


@contextlib.contextmanager
def dask_cluster(folder: Path, workers: int) -> Iterator[str]:
    """A real Dask cluster on this machine, as a user starts one: ``dask scheduler`` and ``dask worker``
    processes (one thread each); yields the scheduler's address once every worker has joined."""
    from dask.distributed import Client

    scheduler_file = folder / "scheduler.json"
    environment = {**os.environ, **ONE_THREAD}
    command = [sys.executable, "-m", "dask"]
    processes = [subprocess.Popen([*command, "scheduler", "--scheduler-file", str(scheduler_file), "--port", "0",
                                   "--no-dashboard"], env=environment, stderr=subprocess.DEVNULL)]
    try:
        deadline = time.monotonic() + 60
        while not scheduler_file.exists() and time.monotonic() < deadline:
            time.sleep(0.05)
        address = json.loads(scheduler_file.read_text())["address"]
        processes.append(subprocess.Popen([*command, "worker", address, "--nworkers", str(workers), "--nthreads", "1",
                                           "--no-dashboard"], env=environment, stderr=subprocess.DEVNULL))
        with Client(address) as client:
            client.wait_for_workers(workers, timeout=60)
        yield address
    finally:
        for process in reversed(processes):
            process.terminate()
            process.wait(timeout=30)


@pytest.mark.slow
def test_study_on_a_real_dask_cluster_gives_the_local_results(tmp_path):
    """``rpdrill study --dask ADDRESS`` on a scheduler and two worker processes started with the dask
    command line: the same table as a run in this process (every column but the wall time)."""
    study = write_study(tmp_path / "cluster.yaml", plots=[])
    with dask_cluster(tmp_path, workers=2) as address:
        assert main(["study", str(study), "--out", str(tmp_path / "cluster"), "--dask", address, "--quiet"]) == 0
    assert main(["study", str(study), "--out", str(tmp_path / "local"), "--workers", "1", "--quiet"]) == 0
    sessions = json.loads((tmp_path / "cluster" / "study.json").read_text())["sessions"]
    assert sessions[0]["runner"] == f"dask ({address})"

    def table(out: Path) -> list[dict[str, str]]:
        return sorted(({k: v for k, v in row.items() if k != "wall_time_s"} for row in rows(out)),
                      key=lambda row: int(row["point"]))

    assert len(table(tmp_path / "cluster")) == 4
    assert table(tmp_path / "cluster") == table(tmp_path / "local")


@pytest.mark.parametrize("changes, expected", [
    ({"scna": {}}, "scna: {}: unknown key; allowed keys here: name, description, base_scene"),
    ({"scan": {"impact.freq": [40]}, "plots": []}, "scan.impact.freq: unknown scene key path; allowed keys here: amplitude_n"),
    ({"scan": {"impact.frequency_hz": [40, "fast"]}, "plots": []}, "scan.impact.frequency_hz: 'fast': a number is required"),
    ({"scan": {"impact.frequency_hz": [40, 2000]}, "plots": []}, "scan.impact.frequency_hz: 2000"),
    ({"scan": {"impact.frequency_hz": {"from": 40, "to": 50}}, "plots": []}, "scan.impact.frequency_hz: give a list"),
    ({"scan": {"rock.name": ["sandstone", "conglomerate"]}, "plots": []}, "scan.rock.name: the base rock sets stiffness_n_per_m"),
    ({"base_scene": "missing.yaml"}, "base_scene: 'missing.yaml': "),
    ({"base_scene": "missing.yaml"}, "missing.yaml: no such file"),
    ({"metrics": ["penetration_rate"]}, "metrics.0: 'penetration_rate': Input should be"),
    ({"plots": [{"x": "rock.threshold_n", "y": "penetration_rate_m_per_s"}]},
     "plots.0.x: 'rock.threshold_n': not a scan axis"),
    ({"scan": {"drill_string.bodies.colar.mass_kg": [2e3]}, "plots": []},
     "scan.drill_string.bodies.colar.mass_kg: 'colar' is not in the base scene's drill_string.bodies"),
    ({"base_overrides": {**SHORT, "solver.method": "DOP853"}},
     "solver.method: 'DOP853': a key of formulation 'ode', not of 'exudyn'"),
])
def test_bad_input_exits_2_naming_file_and_key(tmp_path, capsys, changes, expected):
    study = write_study(tmp_path / "bad.yaml", **changes)
    assert main(["study", str(study), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert str(study) in err and expected in err, err
    assert not (tmp_path / "out").exists()


def test_exact_formulation_as_the_fast_path_agrees_with_exudyn(tmp_path):
    """The same crushing points with formulation exact and exudyn (standard preset, 0.3 % stated)."""
    rates = {}
    for formulation in ("exudyn", "exact"):
        study = write_study(tmp_path / f"{formulation}.yaml", plots=[], scan={"impact.frequency_hz": [45, 50]},
                            base_overrides={"solver": {"formulation": formulation, "end_time_s": 0.4},
                                            "impact.amplitude_n": 400e3,
                                            "metrics": {"transient_blows": 5, "block_blows": 5}})
        out = tmp_path / formulation
        assert main(["study", str(study), "--out", str(out), "--workers", "1", "--quiet"]) == 0
        rates[formulation] = [float(r["penetration_rate_m_per_s"]) for r in sorted(rows(out), key=lambda r: r["point"])]
    assert min(rates["exact"]) > 0
    assert rates["exudyn"] == pytest.approx(rates["exact"], rel=3e-3)


def test_a_stop_while_a_result_is_fetched_from_dask_logs_nothing_but_a_lost_key_is_logged():
    """A stop during the fetch of a finished batch cancels it, and Dask's scheduler then logged
    "Couldn't gather keys: {...: 'forgotten'}" at ERROR (in 1 stop of 6 of tests/test_interrupts.py::
    test_a_study_on_a_dask_local_cluster_stops_within_2_s_without_worker_tracebacks); a key still known
    when a fetch fails (a worker lost) stays logged."""
    scheduler = logging.getLogger("distributed.scheduler")
    records: list[logging.LogRecord] = []
    handler = logging.Handler()
    handler.emit = records.append  # type: ignore[method-assign]
    scheduler.addHandler(handler)
    try:
        with _dask_logs_quiet():
            scheduler.error("Couldn't gather keys: %s", {"run_batch-0": "forgotten"})
            scheduler.error("Couldn't gather keys: %s", {"run_batch-1": "memory"})
        scheduler.error("Couldn't gather keys: %s", {"run_batch-2": "forgotten"})
    finally:
        scheduler.removeHandler(handler)
    assert [record.getMessage() for record in records] == [
        "Couldn't gather keys: {'run_batch-1': 'memory'}", "Couldn't gather keys: {'run_batch-2': 'forgotten'}"]
