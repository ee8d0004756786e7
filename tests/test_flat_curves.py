"""A scan whose figure of merit is zero everywhere says why: on the plot, in the printed summary and in
optima.csv (no silent flat lines)."""

import csv

import yaml
from commands import main
from scenes import PAPER_BASE

from rpdrill.studies.figures import scan_figures
from rpdrill.studies.scan.flat_curves import NO_CRUSHING, NO_RESULT, ZERO, why_no_optimum

# why a curve has no optimum, and the scan figure that says it
UNITS = ("rpdrill.studies.scan.flat_curves", "rpdrill.studies.figures")


def test_the_reason_of_a_flat_curve():
    assert why_no_optimum("penetration_rate_m_per_s", [0.0, 0.0, 0.0]) == NO_CRUSHING
    assert why_no_optimum("advance_per_blow_m", [0.0, float("nan"), 0.0]) == NO_CRUSHING
    assert why_no_optimum("bit_velocity_peak_m_per_s", [0.0, 0.0]) == ZERO
    assert why_no_optimum("penetration_rate_m_per_s", [float("nan")] * 3) == NO_RESULT
    assert why_no_optimum("penetration_rate_m_per_s", [0.0, 1e-6, 0.0]) is None


def test_a_scan_that_never_crushes_says_so_everywhere(tmp_path, monkeypatch, capsys):
    texts = []

    def keep_texts(fig, path, *args, **kwargs):
        texts.extend(t.get_text() for ax in fig.axes for t in ax.texts)
        texts.extend(t.get_text() for legend in fig.legends for t in legend.get_texts())
        return []

    monkeypatch.setattr(scan_figures, "save", keep_texts)
    study = tmp_path / "hard_rock.yaml"
    study.write_text(yaml.safe_dump({
        "name": "hard_rock", "base_scene": str(PAPER_BASE),
        "base_overrides": {"solver.end_time_s": 0.4, "rock.threshold_n": 5.0e6},  # far above any blow
        "scan": {"impact.frequency_hz": [40.0, 50.0, 60.0], "rock.stiffness_n_per_m": [2e8, 5e8]},
        "metrics": ["penetration_rate_m_per_s", "bit_velocity_peak_m_per_s"],
        "plots": [{"x": "impact.frequency_hz", "y": ["penetration_rate_m_per_s"], "curves": "rock.stiffness_n_per_m"},
                  {"kind": "map", "x": "impact.frequency_hz", "y": "rock.stiffness_n_per_m",
                   "z": "penetration_rate_m_per_s"}]}))
    out = tmp_path / "out"
    assert main(["study", str(study), "--out", str(out), "--workers", "1", "--quiet", "--formulation", "exact"]) == 0
    printed = capsys.readouterr().out
    assert f"no optimum on 2 curve(s): {NO_CRUSHING}" in printed
    with (out / "optima.csv").open() as handle:
        rows = [r for r in csv.DictReader(handle) if r["metric"] == "penetration_rate_m_per_s"]
    assert len(rows) == 2 and all(r["no_optimum_reason"] == NO_CRUSHING for r in rows)
    assert texts.count(NO_CRUSHING) == 2  # on the curves' panel and on the map
    assert any(text.endswith("(no crushing)") for text in texts)  # each flat curve's legend entry
