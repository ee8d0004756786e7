"""Cross-check of the Exudyn model against the exact formulation and the ODE of Eq. 4
(models.evaluation.compare, rpdrill crosscheck).

Every case runs 15 blows from rest (the shortest window the default metrics accept), Exudyn at
the cross-check's default step, the references at their reference preset.
"""

from __future__ import annotations

import inspect
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from commands import main
from scenes import PAPER_BASE, PER_BODY, scene_dict, simulate

import rpdrill
from rpdrill import Scene
from rpdrill.models.evaluation.compare import compare_runs, verdict

# the comparison of two runs and its verdict, which rpdrill.crosscheck reports
UNITS = ("rpdrill.models.evaluation.compare",)
DEFAULT_STEP_S = inspect.signature(rpdrill.crosscheck).parameters["step_s"].default

BLOWS = 15
LIFT_OFF_M = 1e-9  # a gap below this (round-off of the start from rest, ~1e-19 m) is no lift-off


def scene_from_base(**changes: object) -> Scene:
    """The test drill over BLOWS periods at the cross-check step, ``changes`` as 'section.key' -> value."""
    data = scene_dict(**changes)
    data["solver"]["end_time_s"] = BLOWS / data["impact"]["frequency_hz"]
    data["solver"].pop("preset", None)
    data["solver"]["step_s"] = DEFAULT_STEP_S
    return Scene.model_validate(data)


def table_1(name: str) -> dict[str, object]:
    """Changes selecting a Table 1 rock by name (its k_n, c_n, F_th, not paper_base's)."""
    return {"rock.name": name, "rock.stiffness_n_per_m": None, "rock.damping_n_s_per_m": None,
            "rock.threshold_n": None}


# case: (changes, crushes, lifts off); crushing = x_n advanced in the window.
CASES = {
    "conglomerate_400kN": ({**table_1("conglomerate"), "impact.amplitude_n": 400e3}, False, True),
    "sandstone_400kN": ({**table_1("sandstone"), "impact.amplitude_n": 400e3}, True, True),
    "soft_limestone_220kN": (table_1("soft_limestone"), False, True),
    "impulse_120kN": ({"impact.amplitude_n": 120e3}, False, True),
    "impulse_280kN": ({"impact.amplitude_n": 280e3}, True, True),
    "never_crushes": ({"rock.threshold_n": 1e7}, False, True),
    "per_body_feed": (PER_BODY, True, False),
    "carriage_contact_damping": ({"rock.threshold_n": 60e3}, True, True),
    "carriage_always_damping": ({"rock.threshold_n": 60e3, "rock.damping_mode": "always"}, True, True),
}


# Every case against the exact formulation (cheap, exact to round-off) in the fast set. Against the ODE of
# Eq. 4, the cross-check's own reference, in the slow set (CI runs both): one case of each feed arrangement
# and rock damping mode, crushing (the exact formulation agrees with the ODE to 1e-9 on both feeds and
# damping modes: tests/test_exact_model.py, so the other cases would repeat the check). The drill that does
# not crush against the ODE is the command's own run (test_cli_writes_report_and_passes): the test drill over
# 15 blows, lifting off in each and crushing 0.35 um once, with never_crushes' margins (bit velocity 5 % of
# its tolerance, 119 % at five times the step, never_crushes 4 % and 180 %), so a never_crushes-ode case
# would repeat it.
ODE_CASES = ["sandstone_400kN", "per_body_feed", "carriage_always_damping"]
REFERENCES = [pytest.param(case, "exact", id=f"{case}-exact") for case in CASES] + \
    [pytest.param(case, "ode", id=f"{case}-ode", marks=pytest.mark.slow) for case in ODE_CASES]


@pytest.fixture(scope="module")
def exudyn_runs() -> dict[str, Any]:
    """Exudyn's run of each case by name, made once: a case in ODE_CASES is checked against both references."""
    return {}


@pytest.mark.parametrize("case, reference", REFERENCES)
def test_exudyn_agrees_with_the_reference(case: str, reference: str, exudyn_runs: dict[str, Any]) -> None:
    changes, crushes, lifts_off = CASES[case]
    scene = scene_from_base(**changes)
    if case not in exudyn_runs:
        exudyn_runs[case] = simulate(scene)
    expected, exudyn = simulate(scene, reference, preset="reference"), exudyn_runs[case]
    report = compare_runs(expected, exudyn, scene.solver.end_time_s)
    checks = verdict(report)
    assert all(c["passed"] for c in checks.values()), checks
    for r in (expected, exudyn):
        assert bool(r.bottom_m[-1] > 1e-6) is crushes, r.bottom_m[-1]
        assert bool(np.min(r.bit_position_m - r.bottom_m) < -LIFT_OFF_M) is lifts_off
    if not crushes:
        assert expected.bottom_m.max() == 0.0 and "crushing" not in expected.solver.switches_into
    np.testing.assert_allclose(exudyn.torsion_angle_rad[-1], expected.torsion_angle_rad[-1], rtol=1e-6)


def test_cli_bad_input_exits_2(tmp_path: Path) -> None:
    assert main(["crosscheck", str(tmp_path / "missing.yaml")]) == 2
    assert main(["crosscheck", str(PAPER_BASE), "--blows", "3"]) == 2  # fewer blows than the metrics need


@pytest.mark.slow
def test_cli_writes_report_and_passes(tmp_path: Path) -> None:
    out = tmp_path / "cc"
    assert main(["crosscheck", str(PAPER_BASE), "--blows", str(BLOWS), "--out", str(out)]) == 0
    report = json.loads((out / "crosscheck.json").read_text(encoding="utf-8"))
    assert report["passed"] and report["blows"] == BLOWS
    assert set(report["histories"]) == {"borehole_bottom_m", "bit_velocity_m_per_s", "rock_force_n"}
    assert report["cpu_time_s"]["ode"] > 0 and report["cpu_time_s"]["exudyn"] > 0
    assert (out / "crosscheck.png").stat().st_size > 0
