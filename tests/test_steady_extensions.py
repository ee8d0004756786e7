"""A periodic steady state of an extended drill is the extended drill's (models.steady.extension_section).

The coordinates a scene's Exudyn extension adds (a clamp: a mass on its own node, held on the collar by a
spring-damper) are in the Poincare section: every run of the blow map starts the clamp where the orbit has
it, so the orbit's rate is the extended drill's settled rate. Before, each run restarted the clamp at rest
on the collar: the orbit of another machine, 7.4 % slower here, and nothing said so. What the section cannot
hold (a coordinate no spring holds, a per-step function of one's own, a spring to ground) is refused by
name, and the result is the scene's time run; a coordinate held to ground only stays where its spring holds it.
Through rpdrill; units (UNITS): the standard preset's stated error, and the regime search with the
extension's coordinates taken out of its section.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import rpdrill
from rpdrill.models.evaluation.solver_settings import EXUDYN_PRESETS

# The Exudyn preset's stated error in the rate; the regime search, its section without the clamp's coordinates.
UNITS = ("rpdrill.models.evaluation.solver_settings", "rpdrill.models.steady.regimes")

PIPE_DRILL = Path(__file__).resolve().parent / "pipe_drill.yaml"
FREQUENCY_HZ = 65.0
CLAMP = {"mass_kg": 300.0, "stiffness_n_per_m": 1.0e9, "damping_n_s_per_m": 2.0e4}
# the Exudyn formulation's stated error in the rate at its standard preset: the time run and each map run
# carry it (the time run's blows scatter by 4e-5 with the phase of the step grid in the blow period)
STATED = EXUDYN_PRESETS["standard"].penetration_rate_error


def drill(**changes: object) -> rpdrill.Scene:
    return rpdrill.load_scene(PIPE_DRILL, allow_code=["user_rig"]).with_({  # the tests' rig: code of one's own
        "solver.formulation": "exudyn", "impact.frequency_hz": FREQUENCY_HZ, "solver.steady_state": "periodic",
        **changes})


def clamped(**changes: object) -> rpdrill.Scene:
    return drill(extensions={"clamp": {"function": "user_rig:add_clamp", "parameters": CLAMP}}, **changes)


def rate(result: rpdrill.Result) -> float:
    return result.metrics["penetration_rate_m_per_s"]


def test_the_clamp_is_in_the_section_and_its_orbit_is_the_clamped_drills_settled_rate(monkeypatch):
    result = rpdrill.simulate(clamped())
    orbit = result.steady_state.orbit
    assert result.steady_state.regime_name == "period-1" and orbit.residual < 1e-8
    labels, state = orbit.state_labels, orbit.state
    assert labels[-2:] == ("clamp_position", "clamp_velocity") and len(labels) == len(state)
    # the run over the orbit starts the clamp where the orbit has it (not at rest on the collar) and records it
    clamp = result.raw.extension_state
    assert clamp.shape == (len(result.time_s), 2)
    np.testing.assert_allclose(clamp[0], state[-2:], rtol=0, atol=1e-12)
    assert abs(state[-1]) > 1e-3 and np.ptp(clamp[:, 1]) > 0.05  # it moves against the collar
    # the last 10 of 200 blows of a time run of the same extended scene (measured: 1.1e-5 apart;
    # python benchmarks/bench_extensions.py --parts steady prints the figures of this test)
    time_run = rpdrill.simulate(clamped(**{"solver.steady_state": "time", "solver.end_time_s": 200 / FREQUENCY_HZ,
                                           "metrics.transient_blows": 190, "metrics.block_blows": 10}))
    assert rate(result) == pytest.approx(rate(time_run), rel=STATED)
    # the clamp as a body of the scene, the exact formulation's orbit (measured: 2.3e-5 apart)
    as_body = drill(**{"solver.formulation": "exact", "drill_string.bodies.clamp": {"mass_kg": CLAMP["mass_kg"]},
                       "drill_string.connectors.clamp_joint": {
                           "from": "collar", "to": "clamp", "stiffness_n_per_m": CLAMP["stiffness_n_per_m"],
                           "damping_n_s_per_m": CLAMP["damping_n_s_per_m"]}})
    assert rate(result) == pytest.approx(rate(rpdrill.simulate(as_body)), rel=STATED)
    # the section without the clamp (as before): each map run restarts it at rest on the collar, and the
    # orbit found is another machine's (measured: 7.4 % slower), which the tolerance above would not pass
    monkeypatch.setattr("rpdrill.models.steady.regimes.with_extension_coordinates", lambda simulation: simulation)
    restarted = rpdrill.simulate(clamped())
    assert restarted.steady_state.regime_name == "period-1" and "clamp_position" not in restarted.steady_state.orbit.state_labels
    assert abs(rate(restarted) / rate(time_run) - 1) > 100 * STATED


def test_coordinates_that_do_not_move_with_the_drill_stay_where_their_forces_hold_them():
    """An oscillator on ground drifts by 0 with the hole (K e = 0): the orbit holds it at rest where its spring
    is relaxed, not riding with the bit; it changes no motion (and says so), so the rate is the plain drill's."""
    oscillator = rpdrill.simulate(drill(extensions={"reference": {"function": "user_rig:add_ground_oscillator"}}))
    orbit = oscillator.steady_state.orbit
    assert oscillator.steady_state.regime_name == "period-1"
    assert orbit.state_labels[-2:] == ("oscillator_position", "oscillator_velocity")
    np.testing.assert_allclose(orbit.state[-2:], 0.0, atol=1e-9)  # it started at 1 mm: its orbit is rest
    assert rate(oscillator) == pytest.approx(rate(rpdrill.simulate(drill())), rel=1e-9)


@pytest.mark.parametrize(("function", "parameters", "why"), [
    ("add_loose_mass", {}, "add the coordinate(s) loose_mass, which no spring holds"),
    ("add_step_counter", {}, "add a per-step function to the Exudyn model"),
    ("add_anchor", {"stiffness_n_per_m": 1.0}, "hold the drill string to ground"),
])
def test_an_extension_the_section_cannot_hold_is_refused_by_name(function, parameters, why):
    scene = drill(**{"solver.end_time_s": 0.1, "metrics.transient_blows": 1, "metrics.block_blows": 3},
                  extensions={"rig": {"function": f"user_rig:{function}", "parameters": parameters}})
    result = rpdrill.simulate(scene)
    assert result.steady_state.regime is rpdrill.Regime.REFUSED  # the scene cannot have an orbit: said, with why
    assert result.steady_state.regime_name == "periodic orbit refused"
    assert result.steady_state.note.startswith(f"scene 'pipe_drill': extensions rig {why}")
    assert "use solver.steady_state: time" in result.steady_state.note
    assert result.time_s[-1] == pytest.approx(0.1)  # the scene's time run, as with steady_state: time


def test_a_built_model_of_a_periodic_scene_says_it_runs_in_time():
    model = rpdrill.build_exudyn(clamped())
    with pytest.raises(rpdrill.InputError, match="solver.steady_state: 'periodic': a built model runs in time"):
        model.run()
