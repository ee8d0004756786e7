"""``rpdrill sensitivity``: one-at-a-time changes move the optima the way the rock mode says, the trend
check, SALib's Morris screening, resume, and bad input."""

from __future__ import annotations

import csv
import json
import warnings
from pathlib import Path

import pytest
import yaml
from commands import main
from scenes import PAPER_BASE

import rpdrill
from rpdrill.studies.sensitivity.sensitivity_study import load_sensitivity, scene_values

# the sensitivity file read, and the numbers of a scene it may vary
UNITS = ("rpdrill.studies.sensitivity.sensitivity_study",)

COLLAR, ROCK = "drill_string.bodies.collar.mass_kg", "rock.stiffness_n_per_m"
ROOT = Path(__file__).resolve().parents[1]


def spec(**changes) -> dict:
    """The test drill crushing on every blow (F_th 60 kN, 20 kN feed) at two amplitudes; its main
    lobe peaks near 51 Hz, the rock mode of the 3 t collar on k_n = 5e8 N/m with contact losses."""
    return {
        "name": "tiny", "base_scene": str(PAPER_BASE),
        "base_overrides": {"solver": {"formulation": "exact", "end_time_s": 0.6},
                           "metrics": {"transient_blows": 10, "block_blows": 5},
                           "rock.threshold_n": 60e3, "feed.force_n": 20e3},
        "frequency_hz": {"from": 35, "to": 70, "step": 5},
        "metrics": ["penetration_rate_m_per_s", "collar_velocity_peak_m_per_s"],
        "scans": [{"label": "160 kN", "overrides": {"impact.amplitude_n": 160e3}},
                  {"label": "220 kN", "overrides": {"impact.amplitude_n": 220e3}}],
        "parameters": [COLLAR, ROCK],
    } | changes


def write(path: Path, data: dict) -> Path:
    path.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    return path


def table(path: Path) -> list[dict[str, str]]:
    with path.open(newline="", encoding="utf-8") as handle:
        return list(csv.DictReader(handle))


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    base = tmp_path_factory.mktemp("sensitivity")
    study, out = write(base / "s.yaml", spec()), base / "out"
    return study, out, main(["sensitivity", str(study), "--out", str(out), "--workers", "1", "--quiet"])


def test_heavier_collar_lowers_and_stiffer_rock_raises_the_optimum(run):
    """The optima sit at the rock mode, f ~ sqrt(k_n / m_collar) / 2 pi: +10 % collar mass lowers them,
    +10 % rock stiffness raises them, and -10 % the other way, in every scan and for both metrics."""
    _, out, status = run
    assert status == 0
    changes = table(out / "one_at_a_time.csv")
    assert len(changes) == 2 * 2 * 2 * 2  # parameters x signs x scans x metrics
    for c in changes:
        expected = -1 if c["parameter"] == COLLAR else 1
        assert float(c["optimum_change"]) * float(c["change"]) * expected > 0, c


def test_trends_and_summary(run):
    _, out, _ = run
    kept = table(out / "trends.csv")
    assert kept[0]["parameter"] == "nominal" and len(kept) == 5
    summary = json.loads((out / "summary.json").read_text())
    rate = summary["metrics"]["penetration_rate_m_per_s"]
    changes = [abs(float(c["peak_change"])) for c in table(out / "one_at_a_time.csv")
               if c["metric"] == "penetration_rate_m_per_s"]
    assert rate["largest_peak_change"] == pytest.approx(max(changes))
    assert set(rate["parameters_by_peak_change"]) == {COLLAR, ROCK}
    assert summary["variations"] == 4 and summary["nominal_keeps_every_trend"]
    assert len(list(out.glob("tornado_*.svg"))) == 4


def test_sensitivity_as_a_library_call_gives_the_command_s_tables(run):
    """``rpdrill.sensitivity`` (no ``out``: a scratch table, nothing drawn) gives the command's results as
    typed tables: the same optima, one-at-a-time changes and trends as the files hold."""
    study, out, _ = run
    result = rpdrill.sensitivity(study, workers=1)
    assert isinstance(result, rpdrill.SensitivityResult) and result.out is None and not result.figures
    files = rpdrill.table_frame(table(out / "results.csv"))
    columns = [c for c in files.columns if c != "wall_time_s"]
    assert result.table[columns].equals(files[columns])
    assert result.one_at_a_time["optimum_change"].dtype == float and len(result.one_at_a_time) == 16
    assert [str(c) for c in result.trends["change"]] == [row["change"] for row in table(out / "trends.csv")]
    assert result.summary == json.loads((out / "summary.json").read_text())
    assert result.global_indices.empty


def test_rerun_runs_nothing(run, capsys):
    study, out, _ = run
    before = table(out / "results.csv")
    assert main(["sensitivity", str(study), "--out", str(out), "--workers", "1", "--quiet"]) == 0
    assert "10 finished earlier, running 0" in capsys.readouterr().err
    assert table(out / "results.csv") == before


def test_morris_screening_ranks_the_parameters(tmp_path):
    study = write(tmp_path / "g.yaml", spec(parameters=[COLLAR], scans=spec()["scans"][:1],
                                            **{"global": {"method": "morris", "parameters": [COLLAR, ROCK],
                                                          "samples": 2, "seed": 3}}))
    out = tmp_path / "out"
    assert main(["sensitivity", str(study), "--out", str(out), "--workers", "1", "--quiet"]) == 0
    indices = table(out / "global.csv")
    assert {i["parameter"] for i in indices} == {COLLAR, ROCK}
    optimum = {i["parameter"]: float(i["mu_star"]) for i in indices
               if i["quantity"] == "optimum_hz" and i["metric"] == "collar_velocity_peak_m_per_s"}
    assert all(value > 0 for value in optimum.values())  # both move the rock mode


def test_morris_indices_without_any_optimum_are_not_computed(tmp_path, capsys):
    """A scan that never crushes has no penetration optimum, nominal or sampled: its indices are NaN,
    not a masked SALib result (no warning), and the collar velocity's are computed."""
    never = [{"label": "never crushes", "overrides": {"impact.amplitude_n": 160e3, "rock.threshold_n": 1e9}}]
    study = write(tmp_path / "g.yaml", spec(parameters=[COLLAR], scans=never,
                                            **{"global": {"method": "morris", "parameters": [COLLAR, ROCK],
                                                          "samples": 2, "seed": 3}}))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert main(["sensitivity", str(study), "--out", str(tmp_path / "out"), "--workers", "1", "--quiet"]) == 0
    assert not [str(w.message) for w in caught] and "warning" not in capsys.readouterr().err.lower()
    indices = [i for i in table(tmp_path / "out" / "global.csv") if i["quantity"] == "optimum_hz"]
    rate = [i for i in indices if i["metric"] == "penetration_rate_m_per_s"]
    assert rate and all(i["mu_star"] == "nan" and int(i["missing"]) == 6 for i in rate)
    assert all(float(i["mu_star"]) >= 0 for i in indices if i["metric"] == "collar_velocity_peak_m_per_s")


def test_all_parameters_are_the_numbers_the_scene_sets():
    study = load_sensitivity(ROOT / "studies" / "paper" / "sensitivity.yaml")
    values = scene_values(study.base)
    assert set(study.varied) <= set(values) and "impact.frequency_hz" not in study.varied
    assert {"impact.duration_s", "feed.force_n", "rock.threshold_n", "rock.stiffness_n_per_m"} <= set(study.varied)


@pytest.mark.parametrize("changes, fragment", [
    ({"parameters": ["drill_string.bodies.colar.mass_kg"]}, "'colar' is not in the base scene"),
    ({"parameters": ["torsion.inertia_kg_m2"]}, "sets no number there"),
    ({"scans": [{"overrides": {}}]}, "every scan needs a label"),
    ({"rising": [["160 kN", "300 kN"]]}, "'300 kN': not a scan label"),
    ({"relative_step": 1.5}, "relative_step"),
])
def test_bad_sensitivity_files_exit_2(tmp_path, capsys, changes, fragment):
    path = write(tmp_path / "bad.yaml", spec(**changes))
    assert main(["sensitivity", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert fragment in err and str(path) in err and "Traceback" not in err
