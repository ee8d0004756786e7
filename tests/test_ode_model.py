"""The plain ODE of Eq. 4 (models.solvers.ode_model): law, energy, events, methods, failures.
Unit tests of models.solvers.ode_model: they import it."""

from __future__ import annotations

import functools
import subprocess
import sys

import numpy as np
import pytest
from scenes import PAPER_BASE, read_yaml, simulate

import rpdrill
import rpdrill.models.solvers.ode_model
from rpdrill import Scene, SimulationFailed

# unit tests of: the ODE formulation (its solver's failure injected)
UNITS = ("rpdrill.models.solvers.ode_model",)


def scene_from_base(blows: float = 15, **changes: object) -> Scene:
    """The test drill ending after ``blows`` periods, with ``changes`` given as 'section.key' -> value."""
    data = read_yaml(PAPER_BASE)
    for path, value in changes.items():
        section, key = path.split(".")
        data.setdefault(section, {})[key] = value
    data["solver"]["end_time_s"] = blows / data["impact"]["frequency_hz"]
    return Scene.model_validate(data)


CASES = {
    "crushing_contact": {"rock.threshold_n": 60e3},
    "crushing_always": {"rock.threshold_n": 60e3, "rock.damping_mode": "always"},
    "lift_off_no_crushing": {"impact.amplitude_n": 120e3},
}


@functools.cache
def result(case: str) -> rpdrill.Result:
    """Six blows of a case at the reference preset: the crushing cases switch into crushing seven times and
    lift off (in their first blow, the only one: eight blows add three crushings and no lift-off), the other
    lifts off in every blow, the torsion line's overshoot peaks at 14 ms (what the tests below check holds
    from the first blows on; eight blows cost 1.4 times as much)."""
    s = scene_from_base(blows=6, **{"metrics.transient_blows": 4, "metrics.block_blows": 2}, **CASES[case])
    return rpdrill.simulate(s.with_solver("ode", preset="reference"), budget=None)  # tests/scenes.py's simulate


def test_does_not_import_exudyn() -> None:
    code = "import rpdrill.models.solvers.ode_model, sys; assert 'exudyn' not in sys.modules"
    subprocess.run([sys.executable, "-c", code], check=True)


@pytest.mark.parametrize("case", list(CASES))
def test_energy_balances(case: str) -> None:
    assert result(case).energy.relative_residual() < 1e-4


@pytest.mark.parametrize("case", list(CASES))
def test_bottom_never_decreases_and_ends_at_window(case: str) -> None:
    r = result(case)
    assert np.all(np.diff(r.bottom_m) >= -1e-15)
    assert np.all(np.diff(r.time_s) >= 0)
    assert r.time_s[-1] == pytest.approx(r.scene.solver.end_time_s)


def test_rock_force_never_negative_in_contact_mode() -> None:
    assert result("crushing_contact").rock_force_n.min() >= 0.0


def test_damping_always_pulls_off_the_bottom() -> None:
    r = result("crushing_always")
    off = r.bit_position_m < r.bottom_m
    assert off.any()
    rock = r.scene.rock
    np.testing.assert_allclose(r.rock_force_n[off], rock.damping_n_s_per_m * r.bit_velocity_m_per_s[off], atol=1e-9)


def test_crushing_runs_at_threshold_and_lift_off_without_crushing() -> None:
    r = result("crushing_contact")
    crushing = np.diff(r.bottom_m) > 0
    assert r.bottom_m[-1] > 1e-4 and r.solver.switches_into["crushing"] > 5
    spring = r.simulation.rock.spring_force(r.bit_position_m, r.rock_states())
    np.testing.assert_allclose(spring[1:][crushing], r.scene.rock.threshold_n, rtol=1e-9)
    lift = result("lift_off_no_crushing")
    assert lift.bottom_m.max() == 0.0 and "crushing" not in lift.solver.switches_into
    assert (lift.bit_position_m < lift.bottom_m).any()


def test_torsion_line_matches_closed_form_static_angle() -> None:
    r = result("crushing_contact")
    tor = r.scene.torsion
    static = (tor.drive_torque_n_m - tor.resisting_torque_n_m) / tor.stiffness_n_m_per_rad
    assert 0.0 < r.torsion_angle_rad.max() <= 2.0 * static * (1 + 1e-9)  # step response overshoots at most 2x


def _one_blow(**changes: object) -> Scene:
    return scene_from_base(blows=1, **{"metrics.transient_blows": 0, "metrics.block_blows": 1, **changes})


@pytest.mark.slow
@pytest.mark.parametrize("method", ["Radau", "LSODA"])
def test_methods_agree_with_dop853(method: str) -> None:
    scene = _one_blow(**{"rock.threshold_n": 60e3})
    reference = simulate(scene, "ode", preset="reference")
    other = simulate(scene, "ode", method=method, relative_tolerance=1e-9, absolute_tolerance=1e-12)
    assert other.solver.mode_switches == reference.solver.mode_switches
    assert other.bottom_m[-1] == pytest.approx(reference.bottom_m[-1], rel=1e-5)
    v = np.interp(reference.time_s, other.time_s, other.bit_velocity_m_per_s)
    assert np.max(np.abs(v - reference.bit_velocity_m_per_s)) < 1e-4 * np.ptp(reference.bit_velocity_m_per_s)


def test_rectangular_pulse_is_evaluated_on_each_side_of_its_switches() -> None:
    scene = _one_blow(**{"impact.shape": "rectangular"})
    r = simulate(scene, "ode", preset="reference")
    on = r.time_s < scene.impact.duration_s * (1 - 1e-9)
    assert np.all(r.impact_force_n[on] == scene.impact.amplitude_n)
    assert np.all(r.impact_force_n[r.time_s > scene.impact.duration_s * (1 + 1e-9)] == 0.0)


def test_unknown_method_is_rejected() -> None:
    with pytest.raises(ValueError, match="RK45"):
        simulate(_one_blow(), "ode", preset="reference", method="RK45")


def test_solver_failure_raises_simulation_failed(monkeypatch: pytest.MonkeyPatch) -> None:
    ode_model = rpdrill.models.solvers.ode_model
    real = ode_model.solve_ivp

    def failing(*args, **kwargs):
        sol = real(*args, **kwargs)
        sol.status, sol.message = -1, "Required step size is less than spacing between numbers."
        return sol

    monkeypatch.setattr(ode_model, "solve_ivp", failing)
    with pytest.raises(SimulationFailed, match="ODE solver DOP853 failed"):
        simulate(_one_blow(), "ode", preset="reference")
