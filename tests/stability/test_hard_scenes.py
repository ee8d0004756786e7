"""Hard scenes stay numerically stable with every preset and with the fixed-step explicit
solvers at the largest step the docs allow, and every preset keeps its stated errors against the
exact formulation; a too-large step is reported, never returned."""

from __future__ import annotations

import functools

import numpy as np
import pytest
from scenes import simulate

from rpdrill.models.evaluation.metrics import summary_metrics
from rpdrill.models.evaluation.results import SimulationResult
from rpdrill.models.evaluation.solver_settings import EXUDYN_PRESETS
from rpdrill.models.evaluation.stability import (
    STABLE_STEP_FACTOR,
    SimulationFailed,
    StepLimitWarning,
    largest_stable_step_s,
    step_scales,
)
from rpdrill.models.solvers.cost import run_cost
from rpdrill.models.solvers.simulation import prepare
from stability.hard_scenes import HARD_SCENES, LONG_RUN, hard_scene


@functools.cache
def run(name: str, preset: str) -> tuple[SimulationResult, dict]:
    result = simulate(hard_scene(HARD_SCENES[name], {"preset": preset}))
    return result, summary_metrics(result)


@functools.cache
def exact(name: str) -> dict:
    """The exact formulation's metrics of a hard scene: the reference of every preset's error."""
    return summary_metrics(simulate(hard_scene(HARD_SCENES[name], {"formulation": "exact"})))


def assert_physical(result: SimulationResult) -> None:
    assert np.isfinite(result.position_m).all() and np.isfinite(result.velocity_m_per_s).all()
    assert np.all(np.diff(result.bottom_m) >= 0.0)  # the borehole never closes
    assert result.rock_force_n.min() >= 0.0  # the rock never pulls (damping_mode contact)


def rate_error(metrics: dict, reference: dict) -> float:
    ref = reference["penetration_rate_m_per_s"]
    return abs(metrics["penetration_rate_m_per_s"] - ref) / max(abs(ref), 1e-9)


@pytest.mark.slow
@pytest.mark.parametrize("preset", list(EXUDYN_PRESETS))
@pytest.mark.parametrize("name", list(HARD_SCENES))
def test_preset_is_stable_and_within_its_stated_errors(name, preset):
    result, metrics = run(name, preset)
    assert_physical(result)
    stated = EXUDYN_PRESETS[preset]
    assert metrics["energy_balance_relative_error"] <= stated.energy_balance_error
    assert rate_error(metrics, exact(name)) <= stated.penetration_rate_error


def test_a_mode_sets_the_accuracy_step_while_it_rings_at_the_next_blow():
    """The test drill's stiffest mode decays by e^-(sigma T) over a blow, sigma ~ 50/s: it still rings at
    65 Hz (sigma T ~ 0.76), not at 45 Hz (~1.1); without damping it rings at any frequency."""
    simulation = prepare(hard_scene(HARD_SCENES["never_crushes"]))
    chain, rock = simulation.chain, simulation.rock
    at_65, at_45 = (step_scales(chain, rock, None, 1 / f) for f in (65.0, 45.0))
    assert at_65.ringing_radius_per_s == pytest.approx(at_65.spectral_radius_per_s)
    assert at_45.ringing_radius_per_s < 0.1 * at_45.spectral_radius_per_s
    undamped = prepare(hard_scene(HARD_SCENES["no_damping"], {"preset": "fast"}))
    ringing = undamped.step_scales.ringing_radius_per_s
    assert ringing == pytest.approx(undamped.step_scales.spectral_radius_per_s)
    assert undamped.settings.step_s == pytest.approx(EXUDYN_PRESETS["fast"].step_times_ringing_radius / ringing)


def test_standard_resolves_the_rock_dampers_jump_and_names_its_key():
    simulation = prepare(hard_scene(HARD_SCENES["critical_damping"], {"preset": "standard"}))
    rate = simulation.step_scales.damper_rate_per_s
    assert rate == pytest.approx(simulation.rock.damping_n_s_per_m / simulation.chain.bodies[simulation.chain.bit_body].mass_kg)
    assert simulation.settings.step_s == pytest.approx(EXUDYN_PRESETS["standard"].damper_step_share / rate)
    # of c_n / m_bit, the key that departs more from the drill's other values: the 30 kg bit beside a 3 t collar
    assert run_cost(simulation).steps_cause.key == "drill_string.bodies.bit.mass_kg"
    fast = prepare(hard_scene(HARD_SCENES["critical_damping"], {"preset": "fast"}))  # fast leaves the jump
    assert fast.settings.step_s > 10 * simulation.settings.step_s


@pytest.mark.parametrize("solver", [s for s, f in STABLE_STEP_FACTOR.items() if f is not None])
@pytest.mark.parametrize("name", list(HARD_SCENES))
def test_fixed_step_at_documented_limit_stays_stable(name, solver):
    base = hard_scene(HARD_SCENES[name])
    step = min(largest_stable_step_s(prepare(base), solver), base.impact.duration_s / 5, base.impact.period_s / 20)
    result = simulate(hard_scene(HARD_SCENES[name], {"type": solver, "step_s": step}))
    assert_physical(result)


def test_the_chattering_scene_chatters():
    result, _ = run("chattering_bit", "standard")
    made = np.flatnonzero(np.diff((result.bit_position_m > result.bottom_m).astype(int)) == 1)
    _, per_blow = np.unique(np.floor(result.time_s[made] * result.scene.impact.frequency_hz), return_counts=True)
    assert per_blow.max() >= 2  # re-contact within one blow


@pytest.mark.parametrize("name", ["stiffest_rock_stiff_joints", "crushes_on_every_contact", "no_damping"])
def test_crushing_scenes_do_crush(name):
    assert run(name, "standard")[0].bottom_m[-1] > 0


@pytest.mark.slow
def test_long_run_650_blows():
    """650 blows, each crushing and lifting off, on the fast and standard presets: physical, and within their
    stated energy and rate errors of the exact formulation (measured: rate 4.7e-5 and 1.6e-5 of the exact
    4.76 mm/s, against the stated 1e-3 and 1e-4)."""
    exact = simulate(hard_scene(LONG_RUN, {"formulation": "exact"}))
    assert exact.solver.switches_into["crushing"] >= 650 and exact.solver.switches_into["free"] >= 650
    reference = summary_metrics(exact)
    for preset in ("fast", "standard"):
        result = simulate(hard_scene(LONG_RUN, {"preset": preset}))
        assert_physical(result)
        assert result.time_s[-1] * result.scene.impact.frequency_hz >= 650
        metrics, stated = summary_metrics(result), EXUDYN_PRESETS[preset]
        assert metrics["energy_balance_relative_error"] <= stated.energy_balance_error
        assert rate_error(metrics, reference) <= stated.penetration_rate_error


def test_unstable_step_is_reported_with_time_and_remedy():
    limit = largest_stable_step_s(prepare(hard_scene(HARD_SCENES["no_damping"])), "rk44")
    scene = hard_scene(HARD_SCENES["no_damping"], {"type": "rk44", "step_s": 1.5 * limit})
    with pytest.warns(StepLimitWarning, match="exceeds the stability limit"), \
            pytest.raises(SimulationFailed) as failure:
        simulate(scene)
    message = str(failure.value)
    assert "diverged at t =" in message and "rk44" in message and "try solver.step_s" in message


def test_automatic_step_at_its_minimum_is_reported_not_returned():
    """DOPRI5 at a tolerance the rock's kinks cannot meet: Exudyn would go on at its minimum step
    (inaccurate, or for hours); the run is stopped and reported with a remedy."""
    scene = hard_scene(HARD_SCENES["stiffest_rock_stiff_joints"],
                       {"type": "dopri5", "step_s": 1e-4, "relative_tolerance": 1e-9, "absolute_tolerance": 1e-12})
    with pytest.raises(SimulationFailed, match="reached the minimum step") as failure:
        simulate(scene)
    assert "try relative_tolerance" in str(failure.value)
