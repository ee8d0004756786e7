"""The steady-state solver (models.steady): periodic orbits by shooting, their stability and regimes.

(a) the exact map's Jacobian (products of matrix exponentials and saltation matrices) is the map's
derivative; (b) a period-1 orbit's advance per blow is the limit of a long exact time run; (c) a period
doubling: the period-2 orbit a long time run settles on is found, the unstable period-1 orbit is not the
rate; (d) a drill held to ground has no orbit relative to the bottom and says so; (e) a periodic run gives
every metric of the orbit through the public API, and results tables gain the regime columns; (f) the
Exudyn and ODE formulations' shooting agrees with the exact orbit; (g) continuation along a scan (a
neighbour's orbit Newton fails from is run on to the orbit), and the bifurcations read from a branch.
Unit tests of models.steady, of a run from a neighbour's orbit (models.runs.scene_run's guess) and of the
bifurcation diagram (UNITS); the time runs and what a run reports through rpdrill."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest
from scenes import PER_BODY, scene

import rpdrill
from rpdrill.models.evaluation.solver_settings import EXUDYN_PRESETS
from rpdrill.models.runs.scene_run import run as run_simulation
from rpdrill.models.solvers.simulation import prepare
from rpdrill.models.steady.continuation import BranchPoint, Continuation, changes, hysteresis
from rpdrill.models.steady.exact_map import exact_period_map
from rpdrill.models.steady.regimes import RegimeFinder, steady_state
from rpdrill.models.steady.shooting import NoConvergence, Shooter
from rpdrill.models.steady.steady_state import SteadyStateUnavailable

# The steady-state solver on prepared scenes, a run started from a guessed orbit, the standard preset's stated
# error, and the bifurcation diagram's data and figure.
UNITS = ("rpdrill.models.evaluation.solver_settings", "rpdrill.models.runs.scene_run",
         "rpdrill.models.solvers.simulation", "rpdrill.models.steady", "rpdrill.studies.figures.bifurcation_figure",
         "rpdrill.studies.scan.bifurcation_diagram")

PIPE_DRILL = Path(__file__).resolve().parent / "pipe_drill.yaml"
PAPER_BASE = Path(__file__).resolve().parents[1] / "studies" / "scenes" / "paper_base.yaml"
# a drill of the global calibration's first generation (studies/paper/calibration.yaml's search region):
# Newton from its 65 Hz orbit does not converge at 60 Hz (the blow's contact sequence differs)
SPREAD_DRILL = {"drill_string.bodies.pipe.length_m": 252.59, "drill_string.bodies.shank.mass_kg": 36.04,
                "drill_string.bodies.collar.mass_kg": 1011.09, "drill_string.bodies.bit.mass_kg": 13.794,
                "drill_string.connectors.shock_sub.stiffness_n_per_m": 9.9278e5,
                "drill_string.connectors.shock_sub.damping_n_s_per_m": 5.6686e4,
                "drill_string.connectors.shank_collar_joint.stiffness_n_per_m": 5.9092e9,
                "drill_string.connectors.shank_collar_joint.damping_n_s_per_m": 102.56,
                "drill_string.connectors.collar_bit_joint.stiffness_n_per_m": 5.0913e8,
                "drill_string.connectors.collar_bit_joint.damping_n_s_per_m": 778.38, "feed.force_n": 27427.5,
                "impact.duration_s": 1.7721e-3}
# the test drill at 400 kN on a lightly damped shock absorber: at 28 Hz every other blow crushes (a period-2
# orbit), the period-1 orbit is unstable through a multiplier below -1 (measured: -3.42) and barely drills
PERIOD_DOUBLING = {"impact.amplitude_n": 400e3, "drill_string.connectors.shock_absorber.damping_n_s_per_m": 2e3,
                   "impact.frequency_hz": 28.0, "solver.end_time_s": 1.5}


def pipe_drill(**changes: object):
    return rpdrill.load_scene(PIPE_DRILL).with_({"solver.formulation": "exact", **changes})


def settled_advance(scene_: rpdrill.Scene, settle_to: float = 1e-9, period_blows: int = 1) -> tuple[float, np.ndarray]:
    """The advance per blow of an exact time run long enough that its last blow agrees with the blow
    ``period_blows`` before it to ``settle_to`` (relative), and the advances of every blow (a period-2 run's
    consecutive blows never agree: compared so, it ran on to the 6400-blow cap)."""
    frequency = scene_.impact.frequency_hz
    blows = 400
    while True:
        run = rpdrill.simulate(scene_.with_({"solver.end_time_s": blows / frequency, "solver.steady_state": "time",
                                             "outputs": {"metrics": ["penetration_rate_m_per_s"]}}), budget=None)
        advances = np.diff(run.bottom_at(np.arange(blows + 1) / frequency))
        change = abs(advances[-1] - advances[-1 - period_blows])
        if change <= settle_to * abs(advances[-1]) or blows >= 6400:
            return float(advances[-1]), advances
        blows *= 2


@pytest.mark.parametrize(("frequency_hz", "blows"), [(65.0, 1), (45.0, 2), (65.0, 3)])
def test_the_exact_jacobian_is_the_derivative_of_the_map(frequency_hz, blows):
    # at 45 Hz the bit's flight between blows spans several batches of the solver's sub-steps (the
    # product's powers of E^(A B) by squaring); over 2 and 3 blows the switches of every blow
    simulation = prepare(pipe_drill(**{"impact.frequency_hz": frequency_hz}))
    period_map = exact_period_map(simulation, blows)
    section = period_map.section
    y = period_map.blow_states(np.concatenate([simulation.initial_positions_m, np.zeros(4),
                                               simulation.initial_rock_state]), 20)[-1]
    z = section.reduce(y)[0]
    image = section.reduce(period_map(y).end_state)[0]
    jacobian = section.jacobian(period_map(y).monodromy)
    for i in range(len(z)):  # central differences: error ~ step^2
        step = 1e-6 * max(abs(z[i]), 1e-4)
        moved = [section.reduce(period_map(section.embed(z + sign * step * np.eye(len(z))[i]),
                                           jacobian=False).end_state)[0] for sign in (1, -1)]
        column = (moved[0] - moved[1]) / (2 * step)
        assert np.allclose(jacobian[:, i], column, rtol=1e-5, atol=1e-7 * np.abs(jacobian).max()), i
    assert image.shape == z.shape


@pytest.mark.parametrize("frequency_hz", [30.0, 65.0, 110.0])
def test_a_period_one_orbit_is_the_limit_of_a_long_time_run(frequency_hz):
    scene_ = pipe_drill(**{"impact.frequency_hz": frequency_hz})
    state = steady_state(prepare(scene_))
    assert state.regime == "period-1" and state.orbit.stable and state.floquet_max_abs < 1
    limit, _ = settled_advance(scene_)
    assert state.orbit.advance_per_blow_m == pytest.approx(limit, rel=1e-6)
    # the event sequence of a crushing blow: contact, crushing, contact again, then the bit leaves
    assert "crushing" in state.orbit.event_sequence


@pytest.mark.slow
def test_a_period_doubling_the_time_run_shows_is_found_and_the_unstable_orbit_is_not_the_rate():
    scene_ = scene().with_solver("exact").with_(PERIOD_DOUBLING)
    simulation = prepare(scene_)
    state = steady_state(simulation)
    assert state.regime == "period-2" and state.period_blows == 2 and state.orbit.stable
    # the period-1 orbit it doubled from: unstable through a real multiplier below -1 (Newton from the
    # state after the transient blows, with more patience than a regime search spends)
    finder = RegimeFinder(simulation)
    parent = Shooter(finder.map(1), simulation).solve(finder.warm_state(), max_iterations=30, halvings=6,
                                                      stalled=30)
    assert not parent.stable and min(mu.real for mu in parent.multipliers if abs(mu.imag) < 1e-12) < -1
    # the blows two apart settled to 1e-9 (400 blows; measured 3.5e-10 there, the sum of the last two 1.0e-9 from
    # the orbit's advance): not 1e-12, below their round-off (2.4e-12 at 800 blows, 7.8e-12 at 1600), which ran the
    # time run on to the 6400-blow cap (12 400 blows in all, 3 s of this test's 3.4 s)
    _, advances = settled_advance(scene_, settle_to=1e-9, period_blows=2)
    # the time run alternates between a blow that crushes and one that does not
    assert advances[-1] * advances[-2] == 0 and advances[-1] + advances[-2] > 0
    assert advances[-1] + advances[-2] == pytest.approx(state.orbit.advance_m, rel=1e-6)
    # what a run reports is the attractor's rate, not the unstable orbit's (100 times smaller)
    result = rpdrill.simulate(scene_.with_({"solver.steady_state": "periodic"}))
    assert result.steady_state.regime_name == "period-2" and result.steady_state.period_blows == 2
    rate = result.metrics["penetration_rate_m_per_s"]
    assert rate == pytest.approx(state.orbit.penetration_rate_m_per_s, rel=1e-9)
    assert rate > 50 * parent.penetration_rate_m_per_s


def test_a_drill_held_to_ground_has_no_orbit_relative_to_the_bottom_and_says_so():
    held = scene(**{key.replace(".", "__"): value for key, value in PER_BODY.items()}).with_solver("exact")
    with pytest.raises(SteadyStateUnavailable, match="shock_absorber hold the drill string to ground"):
        steady_state(prepare(held))
    result = rpdrill.simulate(held.with_({"solver.steady_state": "periodic"}))
    assert result.steady_state.regime is rpdrill.Regime.REFUSED
    assert "no periodic orbit relative to the bottom" in result.steady_state.note
    assert result.time_s[-1] == pytest.approx(held.solver.end_time_s)  # the time run, as without it


def test_a_periodic_run_gives_every_metric_of_the_orbit():
    scene_ = pipe_drill(**{"impact.frequency_hz": 65.0, "solver.steady_state": "periodic"})
    result = rpdrill.simulate(scene_)
    steady, metrics = result.steady_state, result.metrics
    assert steady.requested == "periodic" and steady.regime_name == "period-1" and steady.period_blows == 1
    assert steady.regime is rpdrill.Regime.PERIODIC
    assert 0 < steady.floquet_max_abs < 1 and steady.orbit.residual < 1e-8
    assert all(isinstance(mu, complex) for mu in steady.orbit.multipliers)
    period_s = 1 / 65.0
    assert result.time_s[-1] == pytest.approx(period_s)  # one blow: the orbit
    assert metrics["penetration_rate_m_per_s"] == pytest.approx(metrics["advance_per_blow_m"] / period_s)
    assert abs(metrics["energy_balance_relative_error"]) < 1e-9  # the exact works over the orbit
    # the same figures as the last blows of a long time run (peaks and efficiency included)
    settled = rpdrill.simulate(scene_.with_({"solver.steady_state": "time", "solver.end_time_s": 800 * period_s,
                                             "metrics": {"transient_blows": 795, "block_blows": 5}}),
                               budget=None).metrics
    for name in ("penetration_rate_m_per_s", "collar_velocity_rms_m_per_s", "energy_transfer_efficiency",
                 "rock_force_max_n"):
        assert metrics[name] == pytest.approx(settled[name], rel=1e-6), name
    # a peak is the largest sample: the orbit's samples fall at other phases of a blow than the long run's
    # (the period is no multiple of the 1e-4 s output interval), which moves a sampled peak by up to
    # (omega dt)^2 / 8 of it
    assert metrics["bit_velocity_peak_m_per_s"] == pytest.approx(settled["bit_velocity_peak_m_per_s"], rel=5e-3)
    assert period_s - 1e-4 < result.timeseries["time_s"].iloc[-1] <= period_s  # the table spans the orbit's blow


def test_steady_state_is_a_solver_key_with_a_stated_default_and_a_clear_error():
    assert pipe_drill().solver.steady_state == "time"
    with pytest.raises(rpdrill.InputError, match=r"solver\.steady_state: 'orbit': Input should be 'time' or "
                                                 r"'periodic'"):
        pipe_drill(**{"solver.steady_state": "orbit"})
    time_run = rpdrill.simulate(pipe_drill(**{"solver.end_time_s": 0.25}))
    assert time_run.steady_state.regime_name == "time run" and np.isnan(time_run.steady_state.floquet_max_abs)


def test_exudyn_and_ode_shooting_agree_with_the_exact_orbit():
    scene_ = pipe_drill(**{"impact.frequency_hz": 65.0, "solver.steady_state": "periodic"})
    exact = rpdrill.simulate(scene_).metrics["penetration_rate_m_per_s"]
    exudyn = rpdrill.simulate(scene_, formulation="exudyn")
    assert exudyn.steady_state.regime_name == "period-1" and exudyn.steady_state.orbit.jacobian.startswith("exact model")
    stated = EXUDYN_PRESETS["standard"].penetration_rate_error
    assert exudyn.metrics["penetration_rate_m_per_s"] == pytest.approx(exact, rel=stated)
    ode = rpdrill.simulate(scene_, formulation="ode")
    assert ode.metrics["penetration_rate_m_per_s"] == pytest.approx(exact, rel=1e-6)


def test_continuation_follows_the_branch_of_independent_solves():
    branch, solved = Continuation(), []
    for frequency in (60.0, 61.0, 62.0, 63.0):
        simulation = prepare(pipe_drill(**{"impact.frequency_hz": frequency, "solver.steady_state": "periodic",
                                           "outputs": {"metrics": ["penetration_rate_m_per_s"]}}))
        guess = branch.guess(frequency)
        assert (guess is None) == (frequency == 60.0)
        result = run_simulation(simulation, guess=guess)
        branch.add(BranchPoint(frequency, result.steady_state.regime_name, 1, 0.0, result.steady_state.orbit.state,
                               np.array([]), ()))
        cold = run_simulation(simulation)
        solved.append((result.metrics["penetration_rate_m_per_s"], cold.metrics["penetration_rate_m_per_s"]))
    for followed, cold in solved:
        assert followed == pytest.approx(cold, rel=1e-8)


def test_a_neighbours_orbit_newton_fails_from_is_run_on_to_the_orbit_without_the_time_run(monkeypatch):
    base = rpdrill.load_scene(PAPER_BASE).with_({**SPREAD_DRILL, "solver.formulation": "exact",
                                                 "solver.steady_state": "periodic",
                                                 "outputs": {"metrics": ["penetration_rate_m_per_s"]}})
    at = lambda frequency_hz: prepare(base.with_({"impact.frequency_hz": frequency_hz}))
    neighbour = run_simulation(at(65.0)).steady_state.orbit.state
    simulation = at(60.0)
    with pytest.raises(NoConvergence):
        Shooter(exact_period_map(simulation), simulation).solve(neighbour)
    cold = run_simulation(simulation)  # from rest: the transient blows, then Newton
    never = lambda *args, **kwargs: pytest.fail("the scene's time run was run")
    monkeypatch.setattr("rpdrill.models.runs.scene_run.time_run", never)
    monkeypatch.setattr("rpdrill.models.steady.regimes.time_run", never)
    followed = run_simulation(simulation, guess=(neighbour, 1))
    assert cold.steady_state.regime_name == followed.steady_state.regime_name == "period-1"
    # the same orbit: the two Newton runs end within their tolerance (measured 3.7e-8 apart; the orbits'
    # agreement with long time runs is stated to 1e-6, docs/steady_state.md)
    rate = [run.metrics["penetration_rate_m_per_s"] for run in (followed, cold)]
    assert rate[0] == pytest.approx(rate[1], rel=1e-6) and rate[0] > 0


def point(value, regime="period-1", multipliers=(0.5,), events=("contact", "free"), advance=1e-4, periods=1):
    return BranchPoint(value, regime, periods, advance, np.zeros(3), np.array(multipliers, dtype=complex), events)


def test_bifurcations_are_read_from_neighbouring_orbits():
    found = changes([point(1.0, multipliers=(-0.9,)), point(2.0, multipliers=(-1.1,)),
                     point(3.0, multipliers=(0.8 + 0.5j, 0.8 - 0.5j)), point(4.0, multipliers=(0.9 + 0.6j, 0.9 - 0.6j)),
                     point(5.0, multipliers=(0.99,)), point(6.0, multipliers=(1.02,)),
                     point(7.0, events=("contact", "crushing", "contact", "free"), multipliers=(1.02,)),
                     point(8.0, regime="period-2", periods=2, multipliers=(0.3,))])
    kinds = [(change.kind, change.low, change.high) for change in found]
    assert ("period doubling", 1.0, 2.0) in kinds and ("torus", 3.0, 4.0) in kinds
    assert ("fold", 5.0, 6.0) in kinds and ("grazing", 6.0, 7.0) in kinds and ("period doubling", 7.0, 8.0) in kinds
    assert hysteresis([point(1.0), point(2.0, advance=2e-4)], [point(1.0), point(2.0)]) == [2.0]


def test_a_study_table_gains_the_regime_columns(tmp_path):
    study = tmp_path / "study.yaml"
    study.write_text(f"""name: periodic_scan
base_scene: {PIPE_DRILL}
base_overrides: {{solver.formulation: exact, solver.steady_state: periodic}}
scan:
  impact.frequency_hz: [50.0, 65.0]
metrics: [penetration_rate_m_per_s]
""", encoding="utf-8")
    table = rpdrill.run_study(study, workers=1)
    assert list(table["regime"]) == ["period-1", "period-1"] and list(table["steady_state"]) == ["periodic"] * 2
    assert list(table["period_blows"]) == [1, 1] and ((table["floquet_max_abs"] > 0) & (table["floquet_max_abs"] < 1)).all()


def test_a_continuation_study_follows_its_axis_both_ways_and_writes_what_changed(tmp_path):
    study = tmp_path / "study.yaml"
    drill = Path(__file__).resolve().parent / "test_drill.yaml"
    study.write_text(f"""name: doubling
base_scene: {drill}
base_overrides: {{solver: {{formulation: exact, end_time_s: 1.5}}, impact.amplitude_n: 400.0e+3,
                 drill_string.connectors.shock_absorber.damping_n_s_per_m: 2.0e+3}}
scan:
  impact.frequency_hz: [27.5, 28.0, 28.5, 29.5]
steady_state: continuation
metrics: [penetration_rate_m_per_s]
""", encoding="utf-8")
    out = tmp_path / "out"
    table = rpdrill.run_study(study, workers=1, out=out)
    assert list(table["regime"])[1:] == ["period-2", "period-2", "period-1"]  # up the axis
    assert set(table["steady_state"]) == {"periodic"}
    passes = rpdrill.table_frame(list(csv.DictReader((out / "continuation.csv").open())))
    assert list(passes["regime_down"])[1:3] == ["period-2", "period-2"] and len(passes) == 4
    changed = list(csv.DictReader((out / "bifurcations.csv").open()))
    assert any(row["kind"] == "period doubling" and row["impact.frequency_hz_from"] == "28.5" for row in changed)
    with pytest.raises(rpdrill.InputError, match="continuation_axis: 'rock.threshold_n': not a scan axis"):
        study.write_text(study.read_text() + "continuation_axis: rock.threshold_n\n")
        rpdrill.load_study(study)


def test_the_bifurcation_diagram_draws_time_runs_and_orbits(tmp_path):
    from rpdrill.studies.figures.bifurcation_figure import plot_bifurcation
    from rpdrill.studies.scan.bifurcation_diagram import bifurcation_data

    data = bifurcation_data(scene().with_solver("exact").with_({**PERIOD_DOUBLING}), "impact.frequency_hz",
                            [28.0, 28.5], settle_blows=60, last_blows=10)
    assert [f.regime for f in data.up] == ["period-2", "period-2"] and len(data.brute_force[0].advance_m) == 10
    assert len(data.up[0].advance_m) == 2 and data.up[0].advance_m[0] * data.up[0].advance_m[1] == 0
    written = plot_bifurcation(data, tmp_path / "diagram.png", "test")
    assert all(path.stat().st_size > 0 for path in written)
