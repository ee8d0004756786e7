"""The bilinear loading/unloading rock law: the pure law, its scene keys, and the Exudyn model
against the exact formulation with it (both closing the energy balance).
Unit tests of models.evaluation.compare (the runs compared) and models.solvers.simulation (the law and the
effects a scene builds): they import them."""

from __future__ import annotations

import functools
import inspect

import numpy as np
import pytest
import yaml
from commands import main
from scenes import result_of, scene, scene_dict

import rpdrill
from rpdrill.models.evaluation.compare import compare_runs, verdict
from rpdrill.models.solvers.simulation import prepare
from rpdrill.rocklaw import BilinearRock, force_and_state

# unit tests of: two runs compared and their verdict; the rock law and effects a prepared scene holds
UNITS = ("rpdrill.models.evaluation.compare", "rpdrill.models.solvers.simulation")

STEP_S = inspect.signature(rpdrill.crosscheck).parameters["step_s"].default  # the cross-check step

K_LOAD, K_UNLOAD = 2e8, 1e9
LAW = BilinearRock(K_LOAD, K_UNLOAD)
ROCK = {"law": "bilinear", "loading_stiffness_n_per_m": K_LOAD, "unloading_stiffness_n_per_m": K_UNLOAD}
BLOWS = 15  # the shortest window the default metrics accept


def walk(path_m: np.ndarray, law: BilinearRock = LAW, state: tuple[float, ...] | None = None
         ) -> tuple[np.ndarray, np.ndarray]:
    state, forces, states = state or law.initial_state(), [], []
    for x in path_m:
        force, state = force_and_state(law, x, 0.0, state)
        forces.append(force)
        states.append(state)
    return np.array(forces), np.array(states)


def test_loading_unloading_slopes_and_permanent_indentation():
    u_max = 3e-4
    up, down = np.linspace(0.0, u_max, 301), np.linspace(u_max, -1e-4, 401)
    force, states = walk(np.concatenate([up, down]))
    np.testing.assert_allclose(force[:301], K_LOAD * up)  # loading along k_l
    indentation = u_max * (1 - K_LOAD / K_UNLOAD)
    assert states[300, LAW.bottom_index] == pytest.approx(indentation)
    assert states[-1, LAW.bottom_index] == pytest.approx(indentation)  # kept after the bit left
    touching = down > indentation
    np.testing.assert_allclose(force[301:][touching], K_UNLOAD * (down[touching] - indentation), rtol=1e-9)
    assert np.all(force[301:][~touching] == 0.0)
    assert tuple(states[-1]) == (0.0, pytest.approx(indentation))  # off the rock: the crater is remembered


def test_reload_follows_unloading_line_to_the_maximum_then_loads_on():
    u_max, partial = 3e-4, 2.7e-4  # p = 2.4e-4: still in contact at the turn
    path = np.concatenate([np.linspace(0, u_max, 101), np.linspace(u_max, partial, 51), np.linspace(partial, 4e-4, 101)])
    force, states = walk(path)
    p = u_max * (1 - K_LOAD / K_UNLOAD)
    below_max = path[101:] < u_max
    np.testing.assert_allclose(force[101:][below_max], K_UNLOAD * (path[101:][below_max] - p), rtol=1e-9)
    np.testing.assert_allclose(force[-1], K_LOAD * 4e-4)  # beyond the maximum: on the first loading line
    assert states[-1, 1] == pytest.approx(4e-4 * (1 - K_LOAD / K_UNLOAD))


def test_second_blow_loads_afresh_from_the_indentation():
    """Ideal indexing (eta = 1) at the blow start: the next blow loads along k_l from the indentation."""
    first = np.concatenate([np.linspace(0, 3e-4, 101), np.linspace(3e-4, 0.0, 101)])
    second = np.linspace(0.0, 5e-4, 201)
    _, states = walk(first)
    fresh = LAW.start_blow(0.0, tuple(states[-1]))
    force, states = walk(second, state=fresh)
    p1 = 3e-4 * (1 - K_LOAD / K_UNLOAD)
    assert fresh == (pytest.approx(p1), pytest.approx(p1))
    contact = second > p1
    np.testing.assert_allclose(force[contact], K_LOAD * (second[contact] - p1), rtol=1e-9, atol=1e-6)
    assert states[-1, 1] == pytest.approx(p1 + (5e-4 - p1) * (1 - K_LOAD / K_UNLOAD))
    assert np.all(np.diff(states[:, 1]) >= 0) and np.all(states[:, 0] <= states[:, 1])


def test_contact_regained_within_a_blow_reloads_stiffly_to_the_previous_peak():
    """Crater memory: a bit that rings off the rock and comes back (no blow start between) reloads along
    k_u up to the previous maximum force, then loads on along k_l; nothing moves while it is off."""
    u_max = 3e-4
    p1 = u_max * (1 - K_LOAD / K_UNLOAD)
    path = np.concatenate([np.linspace(0, u_max, 101), np.linspace(u_max, p1 - 5e-5, 101), np.linspace(p1 - 5e-5, 5e-4, 301)])
    force, states = walk(path)
    back = np.arange(len(path)) > 201
    below_peak = back & (path < u_max) & (path > p1)
    np.testing.assert_allclose(force[below_peak], K_UNLOAD * (path[below_peak] - p1), rtol=1e-9)
    assert np.all(states[back & (path < u_max), 1] == pytest.approx(p1))  # no indentation below the peak
    np.testing.assert_allclose(force[-1], K_LOAD * 5e-4)  # beyond it: on the first loading line again
    assert states[-1, 0] == 0.0


def test_start_blow_keeps_the_force_and_moves_the_surface_a_share_eta_to_fresh_rock():
    """On the rock at a blow start (resting on the unloading line), the reset keeps the force and sets
    the loading line a share eta of the way to the one through the current point: the less fresh rock,
    the stiffer the next load (re-crushing the old crater)."""
    up, down = np.linspace(0, 3e-4, 101), np.linspace(3e-4, 2.6e-4, 21)
    force, states = walk(np.concatenate([up, down]))
    state, fresh = tuple(states[-1]), 2.6e-4 - force[-1] / K_LOAD
    resistance = []
    for eta in (0.01, 0.3, 1.0):
        law = BilinearRock(K_LOAD, K_UNLOAD, fresh_fraction=eta)
        new = law.start_blow(2.6e-4, state)
        assert new[1] == state[1] and new[0] == pytest.approx(state[0] + eta * (fresh - state[0]))
        assert law.spring_force(2.6e-4, new) == pytest.approx(force[-1], rel=1e-12)
        resistance.append(law.spring_force(3.2e-4, new))
    assert resistance[0] > resistance[1] > resistance[2]
    assert resistance[2] == pytest.approx(force[-1] + K_LOAD * 0.6e-4)  # eta = 1: on the k_l line at once


def test_dissipated_energy_per_loading():
    """int F dp over a load-unload cycle = k_l u^2 (1 - k_l/k_u) / 2 = work put in - energy given back."""
    u_max = 3e-4
    path = np.concatenate([np.linspace(0.0, u_max, 2001), np.linspace(u_max, 0.0, 2001)])
    force, states = walk(path)
    dissipated = LAW.plastic_work_j(force, states[:, 1])[-1]
    assert dissipated == pytest.approx(0.5 * K_LOAD * u_max**2 * (1 - K_LOAD / K_UNLOAD), rel=1e-9)
    net_work = np.trapezoid(force, path)
    assert dissipated == pytest.approx(net_work, rel=1e-5)


def test_invalid_and_elastic_parameters():
    with pytest.raises(ValueError):
        BilinearRock(2e8, 1e8)
    elastic = BilinearRock(2e8, 2e8)
    force, states = walk(np.concatenate([np.linspace(0, 3e-4, 51), np.linspace(3e-4, -1e-4, 51)]), elastic)
    assert not elastic.crushes and np.all(states == 0.0)
    np.testing.assert_allclose(force, 2e8 * np.maximum(np.concatenate([np.linspace(0, 3e-4, 51),
                                                                          np.linspace(3e-4, -1e-4, 51)]), 0.0))


def test_scene_builds_the_law_and_its_effects():
    s = prepare(scene(rock=ROCK))
    assert s.rock == LAW and not s.effects.rock_damping and s.effects.rock_plasticity
    assert s.rock.name == "bilinear"
    elastic = prepare(scene(rock=ROCK, effects={"joint_damping": True}, outputs={"metrics": ["bit_velocity_peak_m_per_s"]}))
    assert not elastic.effects.rock_plasticity and elastic.rock == BilinearRock(K_LOAD, K_LOAD)
    with pytest.raises(ValueError, match="has no rock damping"):
        scene(rock=ROCK, effects={"rock_damping": True})


BAD = [
    ("jenkins key", {**ROCK, "threshold_n": 138e3},
     ["rock.threshold_n", "138000.0", "rock law 'jenkins'", "loading_stiffness_n_per_m, unloading_stiffness_n_per_m"]),
    ("bilinear key", {"name": "sandstone", "unloading_stiffness_n_per_m": 1e9},
     ["rock.unloading_stiffness_n_per_m", "rock law 'bilinear'", "threshold_n"]),
    ("softer unloading", {**ROCK, "unloading_stiffness_n_per_m": 1e8},
     ["rock.unloading_stiffness_n_per_m", "100000000.0", "greater than loading_stiffness_n_per_m (2e+08)"]),
    ("missing", {"law": "bilinear", "loading_stiffness_n_per_m": K_LOAD}, ["rock.unloading_stiffness_n_per_m", "needs"]),
]


@pytest.mark.parametrize("label, rock, expected", BAD, ids=[b[0] for b in BAD])
def test_bad_rock_keys_one_message_exit_2(tmp_path, capsys, label, rock, expected):
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(scene_dict(rock=rock)))
    assert main(["simulate", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert str(path) in err and "Traceback" not in err
    for fragment in expected:
        assert fragment in err


def window(**overrides: object):
    """The test drill on the bilinear rock over BLOWS blows, Exudyn at the cross-check step."""
    return scene(**{"rock": ROCK, **overrides}, solver__end_time_s=BLOWS / 65.0, solver__step_s=STEP_S)


@pytest.fixture(scope="module", params=["rest", "preloaded"])
def runs(request):
    """(the exact formulation, the Exudyn model) of the window; the exact formulation against the ODE on
    this law: tests/test_exact_model.py."""
    s = window(start=request.param)
    return result_of(s, "exact", sample_interval_s=STEP_S), result_of(s)  # both on the same grid


def test_exudyn_agrees_with_exact(runs):
    exact, exudyn = runs
    report = compare_runs(exact.raw, exudyn.raw, exact.scene.solver.end_time_s)
    checks = verdict(report)
    assert all(c["passed"] for c in checks.values()), checks
    rate = report["metrics"]["penetration_rate_m_per_s"]
    assert rate["reference"] > 0 and rate["rel"] < 1e-4
    for r in (exact, exudyn):
        surface, bottom = r.rock_state_m.T  # never backwards (the exact solution's to round-off of its events)
        assert np.all(np.diff(bottom) >= -1e-15) and np.all(surface <= bottom)
        assert np.min(r.bit_position_m - r.bottom_m) < -1e-6  # the bit lifts off between blows
    assert {"loading", "unloading", "lifted"} <= set(exact.solver.switches_into)


BOUNCING = {**ROCK, "unloading_stiffness_n_per_m": 5e9}  # a stiff unloading: the bit rings off and comes back


@functools.cache
def bouncing(formulation: str):
    """The window on the bouncing rock in a formulation (Exudyn: the window's, at the cross-check step)."""
    s = window(rock=BOUNCING)
    if formulation == "ode":
        return result_of(s, "ode", preset="reference")
    return result_of(s, None if formulation == "exudyn" else formulation)


def assert_remembers_its_crater(r) -> None:
    """From each regain of contact within a blow until the force passes the blow's earlier peak, the
    bottom stays and F = k_u (x - p); most blows bounce."""
    period, t, x, force = r.scene.impact.period_s, r.time_s, r.bit_position_m, r.rock_force_n
    bottom = r.rock_state_m[:, 1]
    regained = 0
    for k in range(round(t[-1] / period)):
        blow = np.flatnonzero((t > k * period + 1e-12) & (t < (k + 1) * period - 1e-12))
        touching = blow[x[blow] > bottom[blow] + 1e-9]
        off = blow[(x[blow] < bottom[blow] - 1e-9) & (blow > (touching[0] if len(touching) else blow[-1]))]
        if not len(off):
            continue
        peak = force[blow[0]:off[0]].max()
        later = blow[blow > off[0]]
        past_peak = np.flatnonzero(force[later] >= 0.99 * peak)
        later = later[:past_peak[0]] if len(past_peak) else later  # until the force passes the earlier peak
        back = later[x[later] > bottom[later] + 1e-9]
        if len(back):
            regained += 1
            np.testing.assert_allclose(bottom[back], bottom[off[0]], rtol=0, atol=1e-12)
            np.testing.assert_allclose(force[back], 5e9 * (x[back] - bottom[back]), rtol=1e-6, atol=1e-2)
    assert regained >= 10, r.formulation  # the check is not vacuous: most blows bounce


@pytest.mark.parametrize("formulation", ["exact", "exudyn"])
def test_bouncing_bit_remembers_its_crater_within_a_blow(formulation):
    """The bit rings off the rock and comes back within a blow: from the regain until the force passes
    the blow's earlier peak, the bottom stays and F = k_u (x - p) (no soft re-indentation from a reset
    surface), in every formulation (the ODE: below; the Exudyn cross-check is
    test_exudyn_agrees_with_exact: its per-step return map on this 5e9 N/m unloading is 8e-4 off)."""
    assert_remembers_its_crater(bouncing(formulation))


@pytest.mark.slow
def test_bouncing_bit_in_the_ode_and_the_exact_rate_agrees():
    """The same crater memory in the ODE (reference preset), and the exact formulation and the ODE
    agree on the penetration rate."""
    ode = bouncing("ode")
    assert_remembers_its_crater(ode)
    rates = [r.metrics["penetration_rate_m_per_s"] for r in (ode, bouncing("exact"))]
    assert rates[1] == pytest.approx(rates[0], rel=1e-6)


def test_start_state_is_consistent_with_the_preload(runs):
    exact, exudyn = runs
    x0 = exact.bit_position_m[0]
    expected = LAW.return_map(x0, LAW.initial_state())  # (0, 0) from rest
    for r in (exact, exudyn):
        np.testing.assert_allclose(r.rock_state_m[0], expected, rtol=1e-12, atol=0)
        assert r.rock_force_n[0] == pytest.approx(K_LOAD * x0, abs=1e-6)
    if exact.scene.start == "preloaded":
        assert K_LOAD * x0 == pytest.approx(exact.scene.feed.force_n)  # the carriage's feed rests on the rock


def test_energy_balance_closes_in_both_formulations(runs):
    for r in runs:
        account = r.energy
        assert account.crushing_work_j[-1] > 0.3 * account.impact_work_j[-1]
        assert account.relative_residual() < 1e-4, r.formulation
        assert 0 < r.metrics["energy_transfer_efficiency"] < 1


def test_exudyn_state_is_the_return_map_of_the_bit_path(runs):
    """Every stored step's state is the return map at that step's bit position, then at the first step
    of a blow the fresh start (eta = 1) (the pre-step update stamped with the step's start, not the end
    time Exudyn passes; no step starts at the end time)."""
    exudyn = runs[1]
    state, expected, blows = tuple(exudyn.rock_state_m[0]), [], 0
    for t, x in zip(exudyn.time_s, exudyn.bit_position_m, strict=True):
        state = LAW.return_map(x, state)
        if exudyn.time_s[-1] > t >= (blows - 1e-9) * exudyn.scene.impact.period_s:
            state, blows = LAW.start_blow(x, state), blows + 1
        expected.append(state)
    np.testing.assert_allclose(exudyn.rock_state_m, np.array(expected), rtol=0, atol=1e-15)
