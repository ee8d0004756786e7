"""The Exudyn model end to end: structure, the rock element in the system, feeds, energy."""

import warnings

import numpy as np
import pytest
from scenes import PER_BODY, crushing_scene, result_of, scene, simulate

import rpdrill
from rpdrill import build_exudyn

SHORT = {"solver__end_time_s": 0.3, "metrics__transient_blows": 4, "metrics__block_blows": 3}
PER_BODY_KW = {k.replace(".", "__"): v for k, v in PER_BODY.items()}


@pytest.fixture(scope="module")
def crushing_run():
    return result_of(crushing_scene(**SHORT))


@pytest.mark.parametrize(
    "overrides, coordinates",
    [
        ({}, 5),  # shank, collar, bit, carriage, torsion
        ({"torsion": None}, 4),
        ({**PER_BODY_KW, "torsion": None}, 3),
        ({**PER_BODY_KW, "effects": {"torsion": True}}, 4),
    ],
)
def test_coordinate_count(overrides, coordinates):
    assert build_exudyn(scene(**overrides)).coordinate_count == coordinates


def test_no_deprecation_warnings():
    with warnings.catch_warnings():
        warnings.simplefilter("error", DeprecationWarning)
        simulate(scene(solver__end_time_s=0.2, metrics__transient_blows=2, metrics__block_blows=2))


def test_bottom_is_return_mapping_of_bit_path(crushing_run):
    """x_n at every step is the running max of x_bit - F_th/k_n (Eq. 2 with per-step return mapping)."""
    r = crushing_run
    law = r.simulation.rock
    expected = np.maximum.accumulate(np.maximum(r.bit_position_m - law.crushing_penetration_m, 0.0))
    np.testing.assert_allclose(r.bottom_m, expected, rtol=0, atol=1e-15)
    advancing_blows = np.unique(np.floor(r.time_s[np.diff(r.bottom_m, prepend=0.0) > 0] * r.scene.impact.frequency_hz))
    assert len(advancing_blows) >= 10  # it crushed on many blows


def test_rock_force_never_pulls_and_is_capped(crushing_run):
    r = crushing_run
    law = r.simulation.rock
    assert r.rock_force_n.min() >= 0.0
    # spring part capped at F_th; the rest is the rock damper c_n v
    cap = law.threshold_n + law.damping_n_s_per_m * np.maximum(r.bit_velocity_m_per_s, 0.0)
    assert np.all(r.rock_force_n <= cap * (1 + 1e-9))
    off = r.bit_position_m < r.bottom_m
    assert off.any() and np.all(r.rock_force_n[off] == 0.0)


def test_symbolic_and_python_user_functions_agree():
    s = crushing_scene(solver__end_time_s=0.1, metrics__transient_blows=1, metrics__block_blows=2)
    symbolic, python = simulate(s), build_exudyn(s, symbolic=False, graphics=False).run().raw
    np.testing.assert_allclose(symbolic.position_m, python.position_m, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(symbolic.bottom_m, python.bottom_m, rtol=1e-12, atol=1e-15)


def test_energy_balance_within_one_percent_and_shrinking_with_step():
    errors = []
    for step in (2e-5, 1e-5, 5e-6):
        account = result_of(crushing_scene(solver__step_s=step, **SHORT)).energy
        assert account.crushing_work_j[-1] > 0.1 * account.impact_work_j[-1]
        errors.append(account.relative_residual())
    assert errors[0] < 0.01
    assert errors[1] < errors[0] and errors[2] < errors[1]


def test_carriage_carries_the_feed_and_anchored_absorber_takes_it_up():
    """Carriage: the shock absorber passes the feed force on (mean over the last blows ~ F_feed).
    Anchored to ground: k1 x_shank grows with depth and takes over the feed of the bodies."""
    carriage = simulate(crushing_scene(**SHORT))
    anchored = simulate(crushing_scene(**PER_BODY_KW, feed__force_n=10e3, **SHORT))
    for r in (carriage, anchored):
        assert r.bottom_m[-1] > 2 * r.simulation.rock.crushing_penetration_m  # both crushed
    k1 = carriage.scene.drill_string.connectors["shock_absorber"].stiffness_n_per_m
    last = carriage.time_s > carriage.time_s[-1] - 3 * carriage.scene.impact.period_s
    shank, rig = carriage.chain.index("shank"), carriage.chain.index("carriage")
    absorber = k1 * (carriage.position_m[:, rig] - carriage.position_m[:, shank])  # compression
    assert np.mean(absorber[last]) == pytest.approx(carriage.scene.feed.force_n, rel=0.1)
    held_by_k1 = k1 * anchored.position_m[:, anchored.chain.index("shank")]  # anchored at x = 0
    quarter = len(held_by_k1) // 4
    deepening = anchored.bottom_m[-1] - anchored.bottom_m[quarter]
    assert deepening > 0
    assert held_by_k1[-1] - held_by_k1[quarter] == pytest.approx(k1 * deepening, rel=0.3)


def test_metrics_are_consistent(crushing_run):
    m = crushing_run.metrics
    period = crushing_run.scene.impact.period_s
    assert m["advance_per_blow_m"] == pytest.approx(m["penetration_rate_m_per_s"] * period)
    assert m["penetration_rate_block_min_m_per_s"] <= m["penetration_rate_m_per_s"] <= \
        m["penetration_rate_block_max_m_per_s"]
    assert 0 < m["energy_transfer_efficiency"] < 1
    assert m["window_blows"] == 9  # 0.3 s at 45 Hz = 13 whole blows: skip 4, three blocks of 3
    assert m["rock_force_max_n"] >= crushing_run.scene.rock.threshold_n


def test_resampled_output_grid(crushing_run):
    columns = crushing_run.resampled(1e-3)
    assert np.allclose(np.diff(columns["time_s"]), 1e-3)
    assert set(columns) >= {"bit_velocity_m_per_s", "borehole_bottom_m", "rock_force_n", "impact_force_n",
                            "torsion_angle_rad", "carriage_position_m"}
    assert np.all(np.diff(columns["borehole_bottom_m"]) >= 0)


def test_preloaded_start_is_the_static_equilibrium_and_all_formulations_use_it():
    s = crushing_scene(start="preloaded", solver__end_time_s=0.1, metrics__transient_blows=1, metrics__block_blows=2)
    exudyn, exact = result_of(s), result_of(s, "exact")
    chain, q0 = exudyn.simulation.chain, exudyn.simulation.initial_positions_m  # the prepared scene's
    rock_force = s.rock.stiffness_n_per_m * q0[chain.bit_body]
    assert 0 < rock_force < s.rock.threshold_n
    residual = chain.stiffness_matrix() @ q0 - chain.constant_forces()
    residual[chain.bit_body] += rock_force
    np.testing.assert_allclose(residual, 0.0, atol=1e-6 * s.feed.force_n)  # K q0 + F_rock = F_feed
    assert rock_force == pytest.approx(s.feed.force_n)  # the carriage's feed rests on the rock
    np.testing.assert_allclose(exudyn.position_m[0], q0)
    np.testing.assert_allclose(exact.position_m[0], q0)
    assert exudyn.bottom_m[-1] == pytest.approx(exact.bottom_m[-1], rel=1e-3)
    assert exudyn.energy.relative_residual() < 0.01


def test_preload_that_would_crush_is_refused():
    with pytest.raises(ValueError, match="static feed alone crushes the rock"):
        rpdrill.simulate(scene(start="preloaded", feed__force_n=200e3))  # refused before it runs


MODULE_PROBE = """
import json, sys
from rpdrill import load_scene, simulate
from rpdrill.rocklaw.exudyn_module import FAST
scene = load_scene(sys.argv[1]).with_solver("exudyn", preset="fast", end_time_s=0.3)
rate = simulate(scene).metrics["penetration_rate_m_per_s"]
print(json.dumps({"fast": FAST, "loaded": sorted(m for m in sys.modules if m.startswith("exudyn.exudynCPP")),
                  "rate": rate, "numba": "numba" in sys.modules}))
"""


def _probe(environment: dict[str, str]) -> tuple[list[str], dict]:
    """The lines a process importing rpdrill's Exudyn model prints, and what it reports last."""
    import json
    import os
    import subprocess
    import sys
    from pathlib import Path

    paper = Path(__file__).resolve().parents[1] / "studies" / "scenes" / "paper_base.yaml"
    env = {k: v for k, v in os.environ.items() if k != "EXUDYN_MODULE"} | environment
    lines = subprocess.run([sys.executable, "-c", MODULE_PROBE, str(paper)], env=env, check=True,
                           capture_output=True, text=True).stdout.splitlines()
    return lines, json.loads(lines[-1])


def _has_avx2() -> bool:
    with open("/proc/cpuinfo", encoding="utf-8") as info:
        return any(line.startswith("flags") and "avx2" in line.split() for line in info)


@pytest.mark.slow
def test_exudyn_builds_as_the_process_chose_announced_by_exudyn_and_agreeing():
    """rocklaw.exudyn_module: importing rpdrill's Exudyn model loads Exudyn's regular build; a process that
    chose the fast one (EXUDYN_MODULE=fast, as the rpdrill command does for itself) the build without range
    checks where the CPU has AVX2 (Exudyn's own condition), Exudyn's own announcement on standard output
    left there (rpdrill swallows nothing); the two give the same penetration rate to round-off."""
    avx2 = _has_avx2()
    lines, fast = _probe({"EXUDYN_MODULE": "fast"})
    assert fast["fast"] is avx2 and fast["loaded"][0] == ("exudyn.exudynCPPfast" if avx2 else "exudyn.exudynCPP")
    assert any("exudyn" in line.lower() for line in lines[:-1]), lines  # Exudyn's note, not hidden by rpdrill
    regular_lines, regular = _probe({})
    assert regular_lines == regular_lines[-1:], regular_lines  # the regular build says nothing
    assert regular["fast"] is False and regular["loaded"][0] == "exudyn.exudynCPP"
    assert not any(name.startswith("exudyn.exudynCPPfast") for name in regular["loaded"])
    assert fast["rate"] > 0 and abs(fast["rate"] - regular["rate"]) <= 1e-12 * abs(regular["rate"])
    # a drill without wave rods loads neither the wave element nor numba (0.16 s of a command's 1.3 s of imports)
    assert fast["numba"] is regular["numba"] is False


USER_PROCESS = """
import json, sys
import rpdrill, rpdrill.studies.cli.main  # the API and the command line import no Exudyn: its entry point chooses
before = sorted(m for m in sys.modules if m.split(".")[0] == "exudyn")
rpdrill.build_exudyn  # a name of the API that needs Exudyn: loaded when first used
import exudyn
print(json.dumps({"before": before, "file": exudyn.__file__,
                  "loaded": sorted(m for m in sys.modules if m.startswith("exudyn.exudynCPP"))}))
"""

OWNED_PROCESS = """
import json, sys
from rpdrill.studies.cli.main import choose_exudyn_build
choose_exudyn_build()  # what the rpdrill program does first (studies.cli.main.console)
import rpdrill.models.solvers.exudyn_model
print(json.dumps({"loaded": sorted(m for m in sys.modules if m.startswith("exudyn.exudynCPP"))}))
"""


def test_importing_rpdrill_leaves_a_users_exudyn_the_regular_build():
    import json
    import os
    import subprocess
    import sys

    env = {k: v for k, v in os.environ.items() if k != "EXUDYN_MODULE"}
    user = json.loads(subprocess.run([sys.executable, "-c", USER_PROCESS], env=env, check=True, capture_output=True,
                                     text=True).stdout.splitlines()[-1])
    assert user["before"] == [] and user["loaded"][0] == "exudyn.exudynCPP", user
    assert not any(name.startswith("exudyn.exudynCPPfast") for name in user["loaded"]), user
    owned = subprocess.run([sys.executable, "-c", OWNED_PROCESS], env=env, check=True, capture_output=True,
                           text=True).stdout.splitlines()
    assert len(owned) == 1, owned  # the program's standard output holds its own lines only
    assert json.loads(owned[0])["loaded"][0] == ("exudyn.exudynCPPfast" if _has_avx2() else "exudyn.exudynCPP")
