"""The exact event-driven solution (models.solvers.exact_model) as the reference formulation.

(a) agreement with the tight-tolerance ODE formulation on crushing scenes, both feed arrangements
and both rock damping modes; (b) energy conserved to round-off without damping; (c) a switch just
after a sub-grid point is found at the same time; (d) chattering contact runs to the end, and an
exceeded switch limit is reported; (e) the compiled event loop (models.solvers.exact_kernels) gives the
answer of the former pure-Python implementation and of its own Python execution; a diverged run is
reported at its first bad sample.
Unit tests of models.solvers.exact_model and models.solvers.exact_kernels, with the divergence check of
models.evaluation.stability and the prepared simulation's pulse (models.solvers.simulation): they import them."""

from __future__ import annotations

import dataclasses
import functools
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from scenes import PAPER_BASE, PER_BODY, crushing_scene, read_yaml, result_of, scene

import rpdrill
import rpdrill.models.evaluation.stability
import rpdrill.models.solvers.exact_model
from rpdrill import Result, Scene, SimulationFailed
from rpdrill.models.solvers.exact_kernels import (
    BRENT_RTOL,
    BRENT_XTOL,
    brent,
    first_crossing,
    horner,
    run_events,
)
from rpdrill.models.solvers.simulation import prepare

# unit tests of: the exact formulation, its compiled kernels, its divergence check; a prepared scene's pulse
UNITS = ("rpdrill.models.evaluation.stability", "rpdrill.models.solvers.exact_kernels",
         "rpdrill.models.solvers.exact_model", "rpdrill.models.solvers.simulation")

BLOWS = 12
SHORT_METRICS = {"metrics__transient_blows": 2, "metrics__block_blows": 2}
FEEDS = {
    "carriage": {},
    "per_body": {k.replace(".", "__"): v for k, v in PER_BODY.items()},
}
UNDAMPED = {
    "drill_string__connectors__shock_absorber__damping_n_s_per_m": 0.0,
    "drill_string__connectors__shank_collar_joint__damping_n_s_per_m": 0.0,
    "drill_string__connectors__collar_bit_joint__damping_n_s_per_m": 0.0,
    "rock__damping_n_s_per_m": 0.0,
    "torsion__damping_n_m_s_per_rad": 0.0,
}
ODE_RTOL, ODE_ATOL = 1e-12, 1e-15
# the tight ODE's window against the exact solution: its cost grows with every blow. Four blows hold every event
# of the per-body drill (its last switch is in its fourth: six blows had the same switches and bottom) and
# four crushing blows of the carriage drill, each with its contact, lift-off and re-strike; the differences
# do not grow with the blows (bottom 7.4e-13 at four blows, 8.8e-13 at six). Over four blows the ODE at
# relative_tolerance 1e-8, or with the rock threshold 1e-7 higher, fails the 1e-9 agreement in every case below
ODE_BLOWS = 4
AGREEMENT = 1e-9


def crushing(feed: str, damping_mode: str, blows: int = BLOWS, **changes: object) -> Scene:
    """The test drill made to crush (400 kN at 45 Hz) for ``blows`` blows."""
    return crushing_scene(rock__damping_mode=damping_mode, solver__end_time_s=blows / 45.0,
                          **SHORT_METRICS, **FEEDS[feed], **changes)


@functools.cache
def exact(feed: str, damping_mode: str) -> Result:
    return result_of(crushing(feed, damping_mode), "exact")


def held_at(result: Result, values: np.ndarray, times_s: np.ndarray) -> np.ndarray:
    """Last stored value at or before each time (both formulations store every pulse switch)."""
    index = np.searchsorted(result.time_s, times_s + 1e-12, side="right") - 1
    return values[index]


def pulse_switches(scene_: Scene) -> np.ndarray:
    """Blow starts and pulse ends, where x_n is stored by both formulations."""
    period, tau = scene_.impact.period_s, scene_.impact.duration_s
    starts = np.arange(1, math.floor(scene_.solver.end_time_s / period + 1e-9)) * period
    return np.sort(np.concatenate([starts, starts - period + tau]))


def relative_error(result: Result, reference: Result, column: str) -> float:
    times, exact_values = pulse_switches(reference.scene), getattr(reference, column)
    difference = held_at(result, getattr(result, column), times) - held_at(reference, exact_values, times)
    return float(np.max(np.abs(difference)) / np.max(np.abs(exact_values)))


def test_does_not_import_exudyn() -> None:
    code = "import rpdrill.models.solvers.exact_model, sys; assert 'exudyn' not in sys.modules"
    subprocess.run([sys.executable, "-c", code], check=True)


def test_checking_and_estimating_a_run_does_not_load_the_kernels() -> None:
    """A study's points are checked and their cost estimated (models.solvers.exact_system) before any runs,
    in the command's own process: numba (0.25 s to import) is for the workers that run them."""
    code = ("import sys; from rpdrill.models.solvers.cost import run_cost; from rpdrill.studies.inputs.reading import load_scene, "
            f"prepare_scene; run_cost(prepare_scene(load_scene({str(PAPER_BASE)!r}).with_solver('exact'), 'test')); "
            "assert 'numba' not in sys.modules and 'rpdrill.models.solvers.exact_system' in sys.modules")
    subprocess.run([sys.executable, "-c", code], check=True)


@pytest.mark.slow
@pytest.mark.parametrize("damping_mode", ["contact", "always"])
@pytest.mark.parametrize("feed", list(FEEDS))
def test_agrees_with_tight_ode(feed: str, damping_mode: str) -> None:
    """At every pulse switch of ODE_BLOWS blows: the carriage drill crushes in each; the per-body drill,
    held on the rock by the feed on every body, makes its last switch in its fourth blow, the window's last."""
    reference = result_of(crushing(feed, damping_mode, blows=ODE_BLOWS), "exact")
    ode = result_of(reference.scene, "ode", method="DOP853", relative_tolerance=ODE_RTOL, absolute_tolerance=ODE_ATOL)
    assert reference.solver.switches_into.get("crushing", 0) >= 2
    assert reference.bottom_m[-1] > 2.5e-4  # the bottom advanced by crushing (2.8e-4 m: the carriage drill's four blows)
    assert relative_error(ode, reference, "bottom_m") < AGREEMENT
    assert relative_error(ode, reference, "bit_position_m") < AGREEMENT
    end = (ode.torsion_angle_rad[-1], reference.torsion_angle_rad[-1])
    assert abs(end[0] - end[1]) < AGREEMENT * abs(end[1])


@pytest.mark.slow
@pytest.mark.parametrize("shape", ["rectangular", "triangular"])
def test_other_pulse_shapes_agree_with_tight_ode(shape: str) -> None:
    """The rectangular pulse (constant state) and the triangular one (ramp state, two phases), over
    ODE_BLOWS blows (the triangular pulse crushes in each of them)."""
    reference = result_of(crushing("carriage", "contact", blows=ODE_BLOWS, impact__shape=shape), "exact")
    ode = result_of(reference.scene, "ode", method="DOP853", relative_tolerance=ODE_RTOL, absolute_tolerance=ODE_ATOL)
    assert reference.solver.switches_into.get("crushing", 0) >= 4
    assert relative_error(ode, reference, "bottom_m") < AGREEMENT
    assert relative_error(ode, reference, "bit_position_m") < AGREEMENT


def test_torsion_without_stiffness_matches_closed_form() -> None:
    """k_x = 0 makes the torsion matrix defective (expm path): phi' = (M/c)(1 - exp(-c t / J))."""
    result = result_of(crushing("carriage", "contact", blows=6, torsion__stiffness_n_m_per_rad=0.0), "exact")
    tor, t = result.scene.torsion, result.time_s
    rate = tor.damping_n_m_s_per_rad / tor.inertia_kg_m2
    terminal = (tor.drive_torque_n_m - tor.resisting_torque_n_m) / tor.damping_n_m_s_per_rad
    expected_rate = terminal * (1 - np.exp(-rate * t))
    expected_angle = terminal * (t - (1 - np.exp(-rate * t)) / rate)
    assert np.max(np.abs(result.torsion_rate_rad_per_s - expected_rate)) < 1e-12 * terminal
    assert np.max(np.abs(result.torsion_angle_rad - expected_angle)) < 1e-12 * expected_angle[-1]


@pytest.mark.parametrize("feed", list(FEEDS))
def test_result_feeds_energy_and_metrics(feed: str) -> None:
    result = exact(feed, "contact")
    assert np.all(np.diff(result.time_s) >= 0.0)
    assert np.all(np.diff(result.bottom_m) >= -1e-15)
    metrics = result.metrics
    assert metrics["penetration_rate_m_per_s"] > 0
    assert metrics["window_blows"] == BLOWS - 2
    fine = result_of(result.scene, "exact", sample_interval_s=2e-6)
    assert fine.energy.relative_residual() < 1e-4  # trapezoidal rule on the samples


@pytest.mark.parametrize("threshold_n", [1e9, None], ids=["no_crushing", "crushing"])
def test_energy_conserved_to_round_off_without_damping(threshold_n: float | None) -> None:
    """Without dampers, T + V + F_spring^2/2k_n - W_feed + F_th x_n is constant between pulses (to
    round-off of its largest terms, thousands of J here against 160 J of impact work)."""
    changes = UNDAMPED | ({"rock__threshold_n": threshold_n} if threshold_n else {})
    result = result_of(crushing("carriage", "contact", blows=8, **changes), "exact")
    energy = result.energy
    total = energy.kinetic_j + energy.elastic_j - energy.feed_work_j + energy.crushing_work_j
    impact = result.scene.impact
    blow = np.floor(result.time_s / impact.period_s + 1e-12)
    between = result.time_s - blow * impact.period_s >= impact.duration_s - 1e-15
    spread = max(np.ptp(total[between & (blow == b)]) for b in np.unique(blow[between]))
    assert (result.bottom_m[-1] > 0) == (threshold_n is None)
    assert result.solver.mode_switches > 8
    largest_term = np.max(energy.kinetic_j + energy.elastic_j + np.abs(energy.feed_work_j))
    assert spread < 1e-12 * largest_term


def test_switch_just_after_a_grid_point_is_found() -> None:
    """Shift the sub-grid so that a point lies 1e-6 sub-steps before a contact event."""
    base = exact("carriage", "contact")
    times, modes = base.solver.switch_times_s, base.solver.switch_modes
    contact_made = next(t for t, mode, before in zip(times[1:], modes[1:], modes)
                        if mode[0] == "contact" and before[0] == "free")
    step = base.solver.sub_step_s
    per_sample = round(base.solver.sample_interval_s / step)
    points = math.floor(contact_made / step)
    shifted_step = (contact_made - 1e-6 * step) / points
    shifted = result_of(base.scene, "exact", sample_interval_s=shifted_step * per_sample)
    assert shifted.solver.sub_step_s == pytest.approx(shifted_step, rel=1e-14)
    assert 0 < contact_made - points * shifted.solver.sub_step_s < 2e-6 * step
    assert shifted.solver.switch_modes == modes
    assert np.max(np.abs(shifted.solver.switch_times_s - times)) < 1e-13
    assert abs(shifted.bottom_m[-1] - base.bottom_m[-1]) < 1e-12 * base.bottom_m[-1]


@pytest.mark.parametrize(("peak", "expected"), [(0.01, 0.4), (-0.01, math.inf)])
def test_a_crossing_and_its_return_between_two_points_is_found(peak: float, expected: float) -> None:
    """p(s) = peak - (s - 0.5)^2 is below zero at both ends of [0, 1]: above zero at its maximum it
    crosses at 0.4 and returns at 0.6 (a sign test at the points sees neither); below, never."""
    coefficients = np.array([peak - 0.25, 1.0, -1.0, 0.0])
    found = first_crossing(coefficients, np.empty(4), 0.0, 1.0)
    assert found == pytest.approx(expected, rel=1e-14)


# An exit function of the 64-segment wave rod (studies/scenes/wave_rod.yaml) far from the wave, at 1e-290:
# Brent's inverse quadratic step divides by a product that underflows to 0 (once a ZeroDivisionError).
UNDERFLOWING_EXIT = [7.788371615881117e-290, 4.124835374249013e-283, -2.862719303340617e-276, -4.17270827535055e-269,
                     -1.633151127953158e-262, -3.438384844349407e-256, -3.138989670558964e-250, -9.993503771441705e-245,
                     -2.233829228423664e-238, 1.030536368331734e-235, 1.3117665095211989e-225, 3.920775038924378e-219,
                     3.3944288107501604e-213, 1.9913821534458496e-207, 1.0146212589486395e-201,
                     -2.1784445545650176e-195, -1.4468496034364281e-189, -1.2690657502050154e-183,
                     -4.169700916125896e-178, 3.0114328558827614e-172, -3.184844854080616e-166, 0.0]


def test_a_root_of_an_exit_function_near_underflow_is_found() -> None:
    """Brent's method returns the sign change of p (within its tolerance), not an exception."""
    coefficients = np.array(UNDERFLOWING_EXIT)
    root = brent(coefficients, 0.0, 2.5e-7)
    tolerance = BRENT_XTOL + BRENT_RTOL * root
    assert horner(coefficients, root - tolerance) > 0.0 > horner(coefficients, root + tolerance)


def test_switches_do_not_depend_on_the_sample_interval() -> None:
    """The bilinear rock's brief loading episodes (one of 8 us on this drill, within a 14 us sub-step at
    1e-4 s samples) are found whatever the sub-grid: the same switches as on a 2 us sub-grid."""
    s = crushing_scene(rock=BILINEAR, solver__end_time_s=0.1, **SHORT_METRICS)
    sparse, dense = (result_of(s, "exact", sample_interval_s=interval) for interval in (1e-4, 2e-6))
    assert sparse.solver.sub_step_s > 5 * dense.solver.sub_step_s
    assert sparse.solver.switch_modes == dense.solver.switch_modes
    np.testing.assert_allclose(sparse.solver.switch_times_s, dense.solver.switch_times_s, rtol=0, atol=1e-12)


# a light bit loosely held by a light collar on a stiff rock, little feed: ~70 switches per blow
CHATTER = {"drill_string__bodies__bit__mass_kg": 0.5, "drill_string__bodies__collar__mass_kg": 30.0, "rock__stiffness_n_per_m": 5e10,
           "drill_string__connectors__collar_bit_joint__stiffness_n_per_m": 1e7, "feed__force_n": 200.0}


def test_chattering_contact_runs_to_the_end() -> None:
    chatter = scene(solver__end_time_s=10 / 65, **SHORT_METRICS, **CHATTER)
    result = result_of(chatter, "exact")
    assert result.time_s[-1] == pytest.approx(chatter.solver.end_time_s)
    assert result.solver.mode_switches > 30 * 10
    assert np.min(np.diff(result.solver.switch_times_s)) >= result.solver.min_switch_interval_s
    assert result.cpu_time_s < 10.0
    with pytest.raises(SimulationFailed, match="chattering"):
        result_of(chatter, "exact", max_switches_per_blow=5)


# The former pure-Python event loop (scipy brentq, before models.solvers.exact_kernels) on crushing("carriage",
# "contact"): x_n, x_bit and phi at the end, and the switches.
FORMER = {"bottom_m": 0.0011440227133556172, "bit_position_m": 0.0008398162377740555,
          "torsion_angle_rad": 0.0019999992542496306}
FORMER_SWITCHES = {"contact": 27, "clipped": 12, "free": 12, "crushing": 15}
FORMER_SWITCH_TIMES_S = [1e-12, 0.009807456435317762, 0.009811421691948697, 0.016781296050915915]


def test_compiled_loop_gives_the_former_answer() -> None:
    result = exact("carriage", "contact")
    for column, former in FORMER.items():
        assert getattr(result, column)[-1] == pytest.approx(former, rel=1e-12)
    assert result.solver.switches_into == FORMER_SWITCHES
    np.testing.assert_allclose(result.solver.switch_times_s[:4], FORMER_SWITCH_TIMES_S, rtol=1e-12, atol=1e-15)


def test_compiled_loop_matches_its_python_execution(monkeypatch: pytest.MonkeyPatch) -> None:
    """The same kernel run by the interpreter (numba's py_func) gives the same samples."""
    short = crushing("carriage", "contact", blows=4)
    compiled = result_of(short, "exact", sample_interval_s=1e-4)
    monkeypatch.setattr(rpdrill.models.solvers.exact_model, "run_events", run_events.py_func)
    interpreted = result_of(short, "exact", sample_interval_s=1e-4)
    assert compiled.solver.switch_modes == interpreted.solver.switch_modes
    np.testing.assert_array_equal(compiled.time_s, interpreted.time_s)
    for column in ("position_m", "velocity_m_per_s", "bottom_m", "rock_force_n", "torsion_angle_rad"):
        values, reference = getattr(compiled, column), getattr(interpreted, column)
        assert np.max(np.abs(values - reference)) <= 1e-12 * np.max(np.abs(reference))


def test_divergence_is_reported_at_the_first_bad_sample(monkeypatch: pytest.MonkeyPatch) -> None:
    """With a position limit of 0.1 mm the drill "diverges" when a body first moves that far."""
    limit = 1e-4
    short = crushing("carriage", "contact", blows=4)
    free = result_of(short, "exact")
    first = np.argmax(np.any(np.abs(free.position_m) > limit, axis=1))
    for module in (rpdrill.models.solvers.exact_model, rpdrill.models.evaluation.stability):
        monkeypatch.setattr(module, "POSITION_LIMIT_M", limit)
    with pytest.raises(SimulationFailed, match=f"diverged at t = {free.time_s[first]:.6g} s"):
        result_of(short, "exact")


SCENES = Path(__file__).resolve().parents[1] / "studies" / "scenes"
FOUR_ROD = SCENES / "four_rod_string.yaml"


@pytest.mark.slow
@pytest.mark.parametrize("path", sorted(SCENES.glob("*.yaml")), ids=lambda path: path.stem)
def test_every_shipped_scene_runs_exact_and_agrees_with_the_ode(path: Path) -> None:
    """The exact formulation takes every shipped scene (its laws, couplings, torsion, rods of many
    segments); over its first two blows (at most the scene's end time) every body's velocity and the
    borehole bottom agree with the tight ODE at the pulse switches and the end, which both store. A scene
    with wave rods the ODE refuses, naming the keys (tests/test_waves.py checks it against Exudyn's)."""
    data = read_yaml(path)
    scene_ = Scene.model_validate(data)
    period_s, end_s = scene_.impact.period_s, min(scene_.solver.end_time_s, 2 * scene_.impact.period_s)
    duration_s = prepare(scene_).pulse_duration_s  # the pulse's, or a piston's contact time
    data["solver"] = {"end_time_s": end_s, "output_interval_s": min(1e-5, duration_s / 20)}
    data["metrics"] = {"transient_blows": 0, "block_blows": 1}
    short = Scene.model_validate(data)
    exact_run = result_of(short, "exact")
    if prepare(short).dynamic_chain.waves:
        with pytest.raises(ValueError, match=r"drill_string\.bodies\.\w+\.model.* is waves: the ode formulation"):
            result_of(short, "ode")
        return
    ode = result_of(short, "ode", relative_tolerance=ODE_RTOL, absolute_tolerance=ODE_ATOL)
    pulse_ends_s = np.arange(2) * period_s + duration_s if scene_.impact.piston is None else []  # a piston: strikes only
    switches_s = np.concatenate([np.arange(1, 2) * period_s, pulse_ends_s])
    stored_s = np.append(switches_s[switches_s < end_s - 1e-9], exact_run.time_s[-1])
    assert ode.time_s[-1] == exact_run.time_s[-1] == pytest.approx(end_s)
    for column in ("velocity_m_per_s", "bottom_m"):
        reference = held_at(ode, getattr(ode, column), stored_s)
        difference = held_at(exact_run, getattr(exact_run, column), stored_s) - reference
        assert np.max(np.abs(difference)) <= AGREEMENT * max(np.max(np.abs(getattr(ode, column))), 1e-9), column  # measured <= 8e-12


def four_rods_with_couplings() -> Scene:
    """The four-rod string with compression-only couplings on soft limestone, 400 kN blows: it crushes
    in its first blow; one blow (the rattle of loose couplings is chaotic over many blows), its first
    10 ms (at 100 Hz): the crushing ends at 3.7 ms, the couplings switch 73 times. The 20 ms of the scene's
    50 Hz (180 switches) ended with the same bottom to 1e-12 at 2.5 times the cost; over either window an
    ODE at relative_tolerance 1e-8 misses the bottom by 1.6e-7."""
    data = read_yaml(FOUR_ROD)
    for name in ("shank_coupling", "coupling1", "coupling2", "coupling3", "bit_coupling"):
        data["drill_string"]["connectors"][name]["type"] = "coupling"
    data["rock"], data["impact"]["amplitude_n"], data["impact"]["frequency_hz"] = {"name": "soft_limestone"}, 400e3, 100.0
    data["metrics"] = {"transient_blows": 0, "block_blows": 1}
    data["solver"] = {"end_time_s": 0.01, "output_interval_s": 1e-5}
    return Scene.model_validate(data)


BILINEAR = {"law": "bilinear", "loading_stiffness_n_per_m": 2e8, "unloading_stiffness_n_per_m": 1e9}


@pytest.mark.parametrize("make", [
    pytest.param(lambda: crushing_scene(rock=BILINEAR, solver__end_time_s=0.1, **SHORT_METRICS), id="bilinear_law"),
    pytest.param(four_rods_with_couplings, id="four_rods_with_couplings", marks=pytest.mark.slow)])
@pytest.mark.slow
def test_piecewise_laws_agree_with_the_ode_to_1e_9_in_the_bottom(make):
    """The exact formulation runs every declared law: the bilinear rock (two states, resets on entering
    loading and free) and compression-only couplings (modes of five links at once)."""
    s = make()
    exact = result_of(s, "exact")
    ode = result_of(s, "ode", relative_tolerance=1e-12, absolute_tolerance=1e-15)
    assert exact.bottom_m[-1] > 0 and exact.solver.mode_switches == ode.solver.mode_switches
    assert abs(exact.bottom_m[-1] - ode.bottom_m[-1]) <= 1e-9 * exact.bottom_m[-1]


@pytest.mark.parametrize("make", [
    lambda: crushing("carriage", "contact", blows=8),
    lambda: crushing_scene(rock=BILINEAR, solver__end_time_s=0.1, **SHORT_METRICS)], ids=["jenkins", "bilinear"])
def test_works_from_the_propagators_close_the_energy_balance_at_sparse_samples(make) -> None:
    """With the energy outputs the impact work and what the links, the rock and the torsion line absorb
    are integrated exactly from the propagators: the balance closes to round-off at the output
    interval's samples (every damper, contact clipping, crushing and torsion in the run), and the works
    agree with the trapezoidal rule on samples 50 and 100 times finer, Richardson-extrapolated
    ((4 T(h / 2) - T(h)) / 3: the trapezoid's h^2 error removed)."""
    scene_ = make()
    sparse = result_of(scene_, "exact")
    assert sparse.works_j is not None and sparse.solver.sample_interval_s == scene_.solver.output_interval_s
    account = sparse.energy
    assert account.relative_residual() < 1e-8
    assert account.crushing_work_j[-1] > 0 and account.damping_j[-1] > 0
    finer = (result_of(scene_, "exact", sample_interval_s=scene_.solver.output_interval_s / n) for n in (50, 100))
    coarse, fine = (Result(run.scene, dataclasses.replace(run.raw, works_j=None)).energy for run in finer)
    for name in ("impact_work_j", "damping_j"):
        extrapolated = (4 * getattr(fine, name)[-1] - getattr(coarse, name)[-1]) / 3
        assert abs(getattr(account, name)[-1] - extrapolated) < 1e-7 * extrapolated


def test_a_scan_reuses_the_propagators_and_its_results_are_those_of_a_fresh_build():
    """models.solvers.exact_model.OPERATOR_CACHE: a run at another impact frequency builds no key again (the
    propagators depend on the matrices, not on the frequency), and a run from cached propagators is bit
    for bit the run that built them."""
    cache = rpdrill.models.solvers.exact_model.OPERATOR_CACHE
    base = crushing_scene(solver__end_time_s=0.2, **SHORT_METRICS).with_solver("exact")
    cache.clear()
    fresh = result_of(base)
    keys = len(cache.entries)
    assert keys == fresh.solver.operator_keys > 0
    again = result_of(base)
    other = result_of(base.model_copy(update={"impact": base.impact.model_copy(update={"frequency_hz": 47.0})}))
    assert len(cache.entries) == keys and other.solver.operator_keys <= keys
    for name in ("time_s", "position_m", "velocity_m_per_s", "bottom_m", "rock_force_n"):
        assert np.array_equal(getattr(fresh, name), getattr(again, name)), name
    assert all(np.array_equal(fresh.works_j[k], again.works_j[k]) for k in fresh.works_j)


def test_keys_larger_than_the_cache_are_not_kept_and_the_run_is_the_same(monkeypatch):
    """A key whose arrays exceed the whole cache (0.24 GB a key for the 290-body rod piston of test_piston) is
    neither copied nor kept; the run is bit for bit the one that cached its keys."""
    cache = rpdrill.models.solvers.exact_model.OPERATOR_CACHE
    base = crushing_scene(solver__end_time_s=0.2, **SHORT_METRICS).with_solver("exact")
    cache.clear()
    cached = result_of(base)
    assert len(cache.entries) > 0
    cache.clear()
    monkeypatch.setattr(cache, "max_bytes", 1)
    offered = []
    monkeypatch.setattr(cache, "put", lambda key, arrays: offered.append(key))
    uncached = result_of(base)
    assert offered == [] and len(cache.entries) == 0  # not even copied to be offered
    for name in ("time_s", "position_m", "bottom_m", "rock_force_n"):
        assert np.array_equal(getattr(cached, name), getattr(uncached, name)), name
