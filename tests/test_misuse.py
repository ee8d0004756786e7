"""Misuse a new user tries (issue #30): two runs into one folder, a stale lock, a resumed table
edited by hand, a value at the edge of the floats. What the user sees: exit status, messages, files."""

from __future__ import annotations

import csv
import json
import re
import subprocess
import sys
from pathlib import Path

import pytest
import yaml
from commands import main
from scenes import PAPER_BASE

import rpdrill
from rpdrill import InputError

# a time-series figure drawn from given columns, and the advisor's evaluation log read back
UNITS = ("rpdrill.studies.figures.timeseries_figure", "rpdrill.studies.advice.advice_search", "rpdrill.studies.runtime.evaluation_log")

ROOT = Path(__file__).resolve().parents[1]
CORPUS = Path(__file__).resolve().parent / "bad_inputs"
SHORT = {"solver.end_time_s": 0.15, "metrics": {"transient_blows": 2, "block_blows": 2}}


def write_study(path: Path, frequencies: list[float], end_time_s: float = 0.15) -> Path:
    study = {"name": "misuse", "base_scene": str(PAPER_BASE),
             "base_overrides": {**SHORT, "solver.end_time_s": end_time_s},
             "scan": {"impact.frequency_hz": frequencies},
             "metrics": ["penetration_rate_m_per_s", "bit_velocity_peak_m_per_s"]}
    path.write_text(yaml.safe_dump(study, sort_keys=False), encoding="utf-8")
    return path


def rows(out: Path) -> list[dict[str, str]]:
    with (out / "results.csv").open(newline="") as handle:
        return list(csv.DictReader(handle))


def command(*args: str) -> list[str]:
    return [sys.executable, "-m", "rpdrill.studies.cli", *args]


def test_a_rock_damper_of_the_smallest_float_runs(tmp_path, capsys):
    scene = yaml.safe_load((CORPUS / "valid" / "drill.yaml").read_text())
    scene["rock"]["damping_n_s_per_m"] = 5e-324
    path = tmp_path / "denormal.yaml"
    path.write_text(yaml.safe_dump(scene), encoding="utf-8")
    assert main(["simulate", str(path), "--out", str(tmp_path / "out")]) == 0, capsys.readouterr().err


@pytest.mark.slow
def test_two_studies_on_one_out_one_runs_the_other_exits_2(tmp_path):
    study = write_study(tmp_path / "two.yaml", [40, 45, 50, 55, 60, 65], end_time_s=0.3)
    out = tmp_path / "out"
    runs = [subprocess.Popen(command("study", str(study), "--out", str(out), "--workers", "1", "--quiet"), cwd=ROOT,
                             stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True) for _ in range(2)]
    results = sorted((run.wait(timeout=300), run.stderr.read()) for run in runs)
    (ran, _), (refused, message) = results
    assert (ran, refused) == (0, 2), message
    assert "another rpdrill run" in message and "pid " in message and str(out) in message
    assert sorted(int(r["point"]) for r in rows(out)) == list(range(6))  # no row twice
    assert not (out / ".rpdrill.lock").exists()


def test_a_stale_lock_is_taken_over_and_said_once(tmp_path, capsys):
    study = write_study(tmp_path / "stale.yaml", [40, 60])
    out = tmp_path / "out"
    out.mkdir()
    (out / ".rpdrill.lock").write_text("pid 999999999: rpdrill study stale.yaml --out out\n")
    assert main(["study", str(study), "--out", str(out), "--workers", "1", "--quiet"]) == 0
    err = capsys.readouterr().err
    assert err.count("took over the lock") == 1 and "pid 999999999" in err
    assert not (out / ".rpdrill.lock").exists() and len(rows(out)) == 2


@pytest.mark.slow
def test_a_resumed_table_with_edited_rows_runs_them_again(tmp_path, capsys):
    study = write_study(tmp_path / "edited.yaml", [40, 50, 60])
    out = tmp_path / "out"
    # both runs by the rpdrill program (its Exudyn build: studies.cli.main.choose_exudyn_build), so that rows compare exactly
    first = subprocess.run(command("study", str(study), "--out", str(out), "--workers", "1", "--quiet"), cwd=ROOT,
                           capture_output=True, text=True, timeout=300, check=False)
    assert first.returncode == 0, first.stderr
    original = sorted(rows(out), key=lambda r: int(r["point"]))
    edited = [dict(r) for r in original]
    edited[0]["penetration_rate_m_per_s"] = "fast"  # a metric edited to text
    edited[2]["impact.frequency_hz"] = "61.0"  # a parameter edited
    with (out / "results.csv").open("w", newline="") as handle:
        writer = csv.DictWriter(handle, list(original[0]))
        writer.writeheader()
        writer.writerows(edited)
    capsys.readouterr()
    done = subprocess.run(command("study", str(study), "--out", str(out), "--workers", "1", "--quiet"), cwd=ROOT,
                          capture_output=True, text=True, timeout=300, check=False)
    err = done.stderr
    assert done.returncode == 0, err
    assert err.count("damaged or edited") == 1 and "'fast'" in err and "internal error" not in err
    assert "1 finished earlier, running 2" in err
    again = sorted(rows(out), key=lambda r: int(r["point"]))
    strip = ("wall_time_s",)
    assert [{k: v for k, v in r.items() if k not in strip} for r in again] == \
        [{k: v for k, v in r.items() if k not in strip} for r in original]


@pytest.mark.slow
def test_simulate_of_an_unsettled_run_says_so_in_one_warning_line(tmp_path):
    """The test drill at 65 Hz: the bit stops crushing after the first block (its block rates 0.11 and
    0 mm/s): a result, but one warning line and the status in summary.json."""
    out = tmp_path / "out"
    done = subprocess.run(command("simulate", str(CORPUS / "valid" / "drill.yaml"), "--out", str(out), "--quiet"),
                          cwd=ROOT, capture_output=True, text=True, timeout=300, check=False)
    assert done.returncode == 0, done.stderr
    warned = [line for line in done.stderr.splitlines() if line.startswith("rpdrill: warning:")]
    assert len(warned) == 1 and "has not settled" in warned[0] and "mm/s" in warned[0]
    assert json.loads((out / "summary.json").read_text())["status"] == "unsettled"
    result = rpdrill.simulate(CORPUS / "valid" / "drill.yaml")  # from Python: the same status, and why
    assert result.status == "unsettled" and result.status_why in warned[0]


def test_a_study_row_of_a_run_the_stability_check_flags_is_not_ok(tmp_path, capsys):
    """Explicit Euler at a step small enough to finish: the check warns that it is unstable at any
    step on the undamped modes; its row says so."""
    study = {"name": "euler", "base_scene": str(PAPER_BASE),
             "base_overrides": {"solver.end_time_s": 0.06, "solver.type": "explicit_euler", "solver.step_s": 1e-6,
                                "metrics": {"transient_blows": 1, "block_blows": 1}},
             "scan": {"impact.frequency_hz": [50.0]}, "metrics": ["penetration_rate_m_per_s"]}
    path = tmp_path / "euler.yaml"
    path.write_text(yaml.safe_dump(study), encoding="utf-8")
    out = tmp_path / "out"
    main(["study", str(path), "--out", str(out), "--workers", "1", "--quiet"])
    (row,) = rows(out)
    assert row["status"] == "unstable" and "unstable at any step" in row["error"]
    assert "1 unstable" in capsys.readouterr().err


def test_what_exudyn_prints_comes_out_as_a_warning_line(tmp_path):
    """An automatic-step run at a tolerance Exudyn cannot reach: Exudyn's own warning (reached
    minStepSize) comes out as one rpdrill warning line, not raw; the run is refused as failed."""
    scene = yaml.safe_load((CORPUS / "valid" / "drill.yaml").read_text())
    scene["solver"] = {"type": "dopri5", "relative_tolerance": 1e-14, "absolute_tolerance": 1e-16,
                       "end_time_s": 0.05}
    scene["metrics"] = {"transient_blows": 1, "block_blows": 1}
    path = tmp_path / "tight.yaml"
    path.write_text(yaml.safe_dump(scene), encoding="utf-8")
    done = subprocess.run(command("simulate", str(path), "--out", str(tmp_path / "out"), "--quiet"), cwd=ROOT,
                          capture_output=True, text=True, timeout=300, check=False)
    assert done.returncode == 1, done.stderr
    assert "Python WARNING" not in done.stdout + done.stderr
    warned = [line for line in done.stderr.splitlines() if "minStepSize" in line]
    assert len(warned) == 1 and warned[0].startswith("rpdrill: warning: scene 'bad_input_base': Exudyn: ")


def _strict_json(path: Path) -> dict:
    """The JSON in ``path``, refusing NaN and Infinity (Python's json reads them; JSON has no such values)."""
    def refuse(constant: str) -> None:
        raise AssertionError(f"{path} holds {constant}: not valid JSON")
    return json.loads(path.read_text(encoding="utf-8"), parse_constant=refuse)


@pytest.mark.slow
def test_a_run_whose_figures_are_not_numbers_is_not_ok_and_its_summary_is_valid_json(tmp_path):
    """A rock threshold of 1e-3 N: the impact does no work, so the efficiency is 0 / 0; the run's status says
    so in one warning line and summary.json, which holds null (valid JSON), not NaN."""
    scene = yaml.safe_load((CORPUS / "valid" / "drill.yaml").read_text())
    scene["rock"]["threshold_n"] = 1e-3
    path = tmp_path / "weak_rock.yaml"
    path.write_text(yaml.safe_dump(scene), encoding="utf-8")
    out = tmp_path / "out"
    done = subprocess.run(command("simulate", str(path), "--out", str(out), "--quiet"), cwd=ROOT, capture_output=True,
                          text=True, timeout=300, check=False)
    assert done.returncode == 0, done.stderr
    summary = _strict_json(out / "summary.json")
    assert summary["status"] == "not_finite" and summary["metrics"]["energy_transfer_efficiency"] is None
    warned = [line for line in done.stderr.splitlines() if line.startswith("rpdrill: warning:")]
    assert len(warned) == 1 and "energy_transfer_efficiency nan: not a finite number" in warned[0]


def test_a_run_whose_energy_balance_is_off_is_not_ok(tmp_path):
    """An impact of 1e-3 N against a 30 kN feed: the balance of the impact work cannot close (4 times the
    impact work on the paper drill, 1.3e7 % reported); the status says which bound it exceeds."""
    import rpdrill

    scene = rpdrill.load_scene(PAPER_BASE).with_({"impact.amplitude_n": 1e-3, "solver.end_time_s": 0.15,
                                                  "metrics.transient_blows": 2, "metrics.block_blows": 2})
    result = rpdrill.simulate(scene, formulation="ode")
    bound = float(re.search(r"bound ([0-9.e+-]+)", result.status_why).group(1))
    assert result.status == "unbalanced" and result.metrics["energy_balance_relative_error"] > bound > 0


def test_a_resumed_table_with_non_finite_cells_runs_them_again(tmp_path, capsys):
    """A penetration rate edited to inf in results.csv is damage: the point runs again (it moved the
    optimum's band when kept)."""
    study = write_study(tmp_path / "inf.yaml", [40, 50])
    out = tmp_path / "out"
    assert main(["study", str(study), "--out", str(out), "--workers", "1", "--quiet"]) == 0
    original = sorted(rows(out), key=lambda r: int(r["point"]))
    edited = [dict(r) for r in original]
    edited[1]["penetration_rate_m_per_s"] = "inf"
    with (out / "results.csv").open("w", newline="") as handle:
        writer = csv.DictWriter(handle, list(original[0]))
        writer.writeheader()
        writer.writerows(edited)
    capsys.readouterr()
    with pytest.warns(UserWarning, match=r"1 row\(s\) damaged or edited.*'inf': not a finite number"):
        assert main(["study", str(study), "--out", str(out), "--workers", "1", "--quiet"]) == 0
    assert "1 finished earlier, running 1" in capsys.readouterr().err
    again = sorted(rows(out), key=lambda r: int(r["point"]))
    assert again[1]["penetration_rate_m_per_s"] == original[1]["penetration_rate_m_per_s"]
    _strict_json(out / "study.json")


def test_a_figure_of_one_requested_series_draws_it(tmp_path):
    """outputs.timeseries: [piston_contact_force_n] and none of the usual panels recorded: the figure draws
    the series asked for (it crashed: 'Number of rows must be a positive integer')."""
    import numpy as np

    import rpdrill
    from rpdrill.studies.figures.timeseries_figure import plot_timeseries

    scene = rpdrill.load_scene(ROOT / "studies" / "scenes" / "top_hammer_piston.yaml").with_(
        {"outputs": {"timeseries": ["piston_contact_force_n"]}})
    t = np.linspace(0.0, 0.3, 301)
    written = plot_timeseries({"time_s": t, "piston_contact_force_n": np.sin(40 * t) ** 8 * 4e5}, scene,
                              tmp_path / "timeseries.png")
    assert written and all(path.stat().st_size > 0 for path in written)


def test_a_checkpoint_line_edited_to_nan_is_refused_not_replayed(tmp_path):
    """rpdrill writes null for a number that is not finite; a NaN or Infinity in evaluations.jsonl was
    put there by hand: refused naming the line (it would be replayed as a result)."""
    from rpdrill.studies.advice.advice_search import AdviceEvaluation
    from rpdrill.studies.runtime.evaluation_log import EVALUATIONS, EvaluationLog

    identity, source = {"hash": "0" * 64}, tmp_path / "search.yaml"
    log = EvaluationLog(tmp_path, identity, source, AdviceEvaluation)
    log.append(AdviceEvaluation(rock="", point={"impact.frequency_hz": 50.0}, value=float("nan"), failed_runs=0,
                                error=""))
    log.close()
    line = json.loads((tmp_path / EVALUATIONS).read_text())
    assert line["value"] is None  # written as null
    assert EvaluationLog(tmp_path, identity, source, AdviceEvaluation).records[0].value is None  # and replayed
    (tmp_path / EVALUATIONS).write_text(json.dumps({**line, "value": "Infinity"}).replace('"Infinity"', "Infinity") + "\n")
    with pytest.raises(InputError, match="line 1 is not an evaluation rpdrill wrote"):
        EvaluationLog(tmp_path, identity, source, AdviceEvaluation)
