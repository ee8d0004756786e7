"""``rpdrill reproduce``: the paper's values stated once (the reproduction file and the calibration's
targets agree), the pages generated from the runs (numbers on the page equal the run's record), written
into --out only and into the docs folder only when asked, a variant, and bad input."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
import yaml
from commands import main

import rpdrill
from rpdrill import Budget
from rpdrill.studies.calibration.calibration_spec import is_free, load_calibration
from rpdrill.studies.reproduction.paper_reproduction import load_reproduction

# the reproduction file and the calibration's targets read, to check they state the paper's values once
UNITS = ("rpdrill.studies.calibration.calibration_spec", "rpdrill.studies.reproduction.paper_reproduction")

ROOT = Path(__file__).resolve().parents[1]
PIPE_DRILL = Path(__file__).resolve().parent / "pipe_drill.yaml"


def test_the_paper_is_stated_once():
    """Every case with a paper optimum is a calibration target with the same optimum and band, and the
    calibration's targets are reproduction cases with the same scene overrides."""
    reproduction = load_reproduction(ROOT / "studies" / "paper" / "reproduction.yaml")
    calibration = load_calibration(ROOT / "studies" / "paper" / "calibration.yaml", Budget(accept_long=True))
    cases = {case.label: case for case in reproduction.spec.cases}
    for label, target in zip(calibration.labels, calibration.spec.targets, strict=True):
        if label == "3.1 a)":  # the 3.1 a) scan is the 220 kN case of 3.1 b) (docs/parameters.md)
            continue
        case = cases[label]
        if case.paper.optimum_hz is None:  # a centre the calibration interpolates where the paper gives none
            assert target.weight < 1 and case.paper.says.startswith("not given") and \
                f"{target.optimum_hz:g} Hz" in case.paper.says, label
        else:
            assert (case.paper.optimum_hz, case.paper.band_hz) == (target.optimum_hz, target.band_hz), label
        assert same_overrides(case.overrides, target.overrides) and case.metric == target.metric, label


def same_overrides(case: object, target: object) -> bool:
    """The reproduction case's overrides are the target's, a number where the target names a free
    parameter ($name, fitted by the calibration: the case holds its calibrated value)."""
    if isinstance(target, str) and is_free(target):
        return isinstance(case, (int, float))
    if isinstance(target, dict):
        return isinstance(case, dict) and case.keys() == target.keys() and \
            all(same_overrides(case[key], target[key]) for key in target)
    return case == target


def spec(**changes) -> dict:
    """Two cases of the frozen pipe drill on a coarse grid around their optima, one figure, one variant."""
    return {
        "name": "tiny_reproduction", "base_scene": str(PIPE_DRILL),
        "base_overrides": {"solver": {"formulation": "exact", "end_time_s": 1.0}},
        "frequency_hz": {"from": 50, "to": 80, "step": 3}, "metrics": ["penetration_rate_m_per_s", "advance_per_blow_m"],
        "cases": [{"label": "160 kN", "overrides": {"impact.amplitude_n": 160e3},
                   "paper": {"optimum_hz": 60, "band_hz": [55, 65], "says": "55-65 Hz"}},
                  {"label": "280 kN", "overrides": {"impact.amplitude_n": 280e3},
                   "paper": {"optimum_hz": 80, "band_hz": [75, 85], "says": "75-85 Hz"}}],
        "rising": [["160 kN", "280 kN"]], "sub_harmonics": "160 kN",
        "figures": [{"number": 4, "title": "impulse", "cases": ["160 kN", "280 kN"], "metrics": ["advance_per_blow_m"]}],
        "variants": [{"label": "lighter pipe", "description": "a 6 t pipe",
                      "overrides": {"drill_string.bodies.pipe.length_m": 225.0}}],
    } | changes


def write(path: Path, data: dict) -> Path:
    path.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    return path


def test_reproduce_writes_generated_pages_into_out_and_docs_only_when_asked(tmp_path):
    source, out, docs = write(tmp_path / "r.yaml", spec()), tmp_path / "out", tmp_path / "docs"
    assert main(["reproduce", str(source), "--out", str(out), "--workers", "1", "--quiet"]) == 0
    assert {p.name for p in out.iterdir()} >= {"reproduction.md", "figures.md", "parameters.md", "cases.csv",
                                               "reproduction.json", "figures"}
    assert {p.name for p in (out / "figures").iterdir()} == {"fig4.png", "fig4.svg"}
    assert not docs.exists()
    record = json.loads((out / "reproduction.json").read_text())["variants"]
    page = (out / "reproduction.md").read_text()
    for optimum in record["None"]["optima"]:  # the page's optima are the run's, as recorded
        assert f"| {optimum['label']} | penetration_rate_m_per_s | " in page
        assert f"{optimum['optimum']:.1f} Hz" in page
    assert record["None"]["trends"][0]["rises"]  # the frozen drill's optimum rises with the impulse
    assert "lighter pipe" in record and "| trend: 160 kN < 280 kN | rises |" in page
    for name in ("reproduction.md", "figures.md", "parameters.md"):  # each page states what made it
        made = (out / name).read_text()
        assert f"Generated by `rpdrill reproduce {source} --out {out}` (inputs: `{source}`" in made, made[:400]
    (out / "figures" / "stale.svg").write_text("")  # a rerun into the same folder replaces its figures
    assert main(["reproduce", str(source), "--out", str(out), "--docs", str(docs), "--workers", "1",
                 "--quiet"]) == 0
    assert not (out / "figures" / "stale.svg").exists()
    assert (docs / "reproduction.md").read_text() == (out / "reproduction.md").read_text()
    assert (docs / "figures" / "fig4.svg").exists()


def test_reproduce_as_a_library_call_gives_the_command_s_optima(tmp_path):
    """``rpdrill.reproduce`` without ``out``: the cases, optima and trends the command records, the
    pages in memory (stating the call's command line, without --out), nothing written."""
    source, out = write(tmp_path / "r.yaml", spec()), tmp_path / "out"
    assert main(["reproduce", str(source), "--out", str(out), "--workers", "1", "--quiet"]) == 0
    result = rpdrill.reproduce(source, workers=1)
    assert isinstance(result, rpdrill.ReproductionResult) and result.out is None and result.passed
    recorded = json.loads((out / "reproduction.json").read_text())["variants"]
    assert [r.optimum.record | {"label": r.case.label, "error": r.error} for r in result.results] == \
        recorded["None"]["optima"]
    assert set(result.by_variant) == {None, "lighter pipe"} and result.trends == recorded["None"]["trends"]
    assert f"Generated by `rpdrill reproduce {source}` (inputs:" in result.pages["reproduction.md"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out", "r.yaml"]


@pytest.mark.parametrize("changes, fragment", [
    ({"sub_harmonics": "3.1 a)"}, "'3.1 a)': not a case label"),
    ({"metrics": ["penetration_rate_m_per_s"]}, "metrics must list advance_per_blow_m"),
    ({"variants": [{"label": "x", "description": "y", "add": {"bodies": {"pipe": {"mass_kg": 1.0}}}}]},
     "variants.0.add.bodies: pipe: already in the base scene"),
    ({"variants": [{"label": "x", "description": "y", "overrides": {"drill_string.bodies.pipo.length_m": 1.0}}]},
     "'pipo' is not in the base scene"),
])
def test_bad_reproduction_files_exit_2(tmp_path, capsys, changes, fragment):
    path = write(tmp_path / "bad.yaml", spec(**changes))
    assert main(["reproduce", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert fragment in err and str(path) in err and "Traceback" not in err
    assert not (tmp_path / "out").exists()


def test_no_result_number_is_typed_into_the_generated_page_templates():
    """The page module holds no numbers of results: every number it prints is formatted from a value."""
    text = (ROOT / "studies" / "pages" / "paper_pages.py").read_text()
    literals = re.findall(r"(?<![\w.{:])\d+\.\d+ ?(?:Hz|mm/s|m/s|%)", text)
    assert literals == []


FIG6 = ("3.2 Fig. 6 k = 8.93e7", "3.2 Fig. 6 k = 8.4e8")


@pytest.mark.slow
def test_the_shipped_scene_reproduces_the_headlines_but_fig_6_and_says_so(tmp_path, capsys):
    """The product's claim, on the shipped scene and cases as they are: every optimum the paper states
    within the reproduction file's tolerance and every rising trend, but Fig. 6's (docs/fig6.md: a global
    search found none together with the rest); the command exits 1 and says how many it reached, and
    the page gives the reason for Fig. 6's missing optima. The file's variants (other upper strings,
    three quarters of its runs) and its figures (the paper's Figs. 2-6 drawn from the same runs, a quarter of
    what was left; test_reproduce_writes_generated_pages_... draws one) are left out of this copy of it: they
    state no claim of the paper."""
    shipped = ROOT / "studies" / "paper" / "reproduction.yaml"
    data = yaml.safe_load(shipped.read_text(encoding="utf-8"))
    assert data.pop("variants") and data.pop("figures")
    data["base_scene"] = str(shipped.parent / data["base_scene"])
    data["calibration"] = str(shipped.parent / data["calibration"])
    out = tmp_path / "out"
    assert main(["reproduce", str(write(tmp_path / "reproduction.yaml", data)), "--out", str(out), "--workers", "1",
                 "--quiet"]) == 1
    assert "6 of 8 optima the paper states reached" in capsys.readouterr().err
    record = json.loads((out / "reproduction.json").read_text())["variants"]
    assert list(record) == ["None"]
    record = record["None"]
    rises = {tuple(t["cases"]): t["rises"] for t in record["trends"]}
    assert len(rises) == 3 and sum(rises.values()) == 2 and not rises[tuple(data["rising"][2])]
    reproduction = load_reproduction(shipped)
    stated = {c.label: c.paper.optimum_hz for c in reproduction.spec.cases if c.paper.optimum_hz is not None}
    reached = {o["label"]: o["optimum"] for o in record["optima"]}
    assert len(stated) == 8
    for label, paper_hz in stated.items():
        if label in FIG6:
            assert reached[label] is None  # nothing crushes: no optimum, and the page says why
        else:
            assert abs(reached[label] / paper_hz - 1) <= reproduction.spec.tolerance, label
    page = (out / "reproduction.md").read_text()
    reason = "none (no crushing: the peak rock force stays below F_th at every point)"
    rows = [line for line in page.splitlines() if line.startswith("| 3.2 Fig. 6 k = ") and " < " not in line]
    assert len(rows) == 4 and all(reason in row for row in rows)


@pytest.mark.slow
def test_the_fig6_searchs_best_drill_has_spikes_not_maxima():
    """docs/fig6.md: the best drill of the Fig. 6 search, scanned every 1 Hz, reaches six of the eight
    stated optima with every trend rising, but its Fig. 6 "optima" are single-frequency spikes (80 %
    bands at most 2 Hz wide) and the softest rock's lies far below 80 Hz. As the library call in this
    process, without ``out``: the same scans and optima as the command (test_reproduce_as_a_library_call_...),
    without drawing its five figures or starting a pool (a quarter of the command's CPU, measured)."""
    result = rpdrill.reproduce(ROOT / "docs" / "fig6" / "best_drill_reproduction.yaml", workers=1)
    assert [t["rises"] for t in result.trends] == [True, True, True]
    assert (len(result.reached), len(result.stated)) == (6, 8) and not result.passed
    optima = {r.case.label: r.optimum.record for r in result.results}
    for label in FIG6:
        low, high = optima[label]["band_80"]
        assert optima[label]["optimum_value"] > 0 and high - low <= 2.0, label
    assert optima[FIG6[0]]["optimum"] < 0.5 * 80.0


def test_the_pulse_shape_study_of_the_fig6_page_is_valid():
    study = rpdrill.load_study(ROOT / "docs" / "fig6" / "pulse_shapes.yaml")
    assert len(study.points) == 3 * 2 * 81
