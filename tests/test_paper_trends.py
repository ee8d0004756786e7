"""The paper's trends on a frozen drill with a heavy drill pipe above a damped shock sub
(tests/pipe_drill.yaml), through the exact formulation; and that arrangement in all three
formulations: the Exudyn model against the exact solution and the ODE, the exact solution against the
ODE, the energy balance. Runs through rpdrill; the rock mode, the curve's optimum and the comparison of two
runs are the units below."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import rpdrill
from rpdrill.models.drill.modal import rock_mode_frequency_hz
from rpdrill.models.evaluation.compare import compare_runs, verdict
from rpdrill.models.solvers.simulation import prepare
from rpdrill.studies.scan.curve_optima import curve_optimum

# The rock mode of a prepared drill (the main lobe's guide), a scanned curve's main-lobe optimum and the
# comparison of two runs within the cross-check's tolerances.
UNITS = ("rpdrill.models.drill.modal", "rpdrill.models.evaluation.compare", "rpdrill.models.solvers.simulation",
         "rpdrill.studies.scan.curve_optima")

PIPE_DRILL = Path(__file__).resolve().parent / "pipe_drill.yaml"
SOFT_ROCK = {"rock.stiffness_n_per_m": 8.93e7, "rock.damping_n_s_per_m": 683.0, "rock.threshold_n": 123e3}


def pipe_drill(**overrides: object) -> rpdrill.Scene:
    return rpdrill.load_scene(PIPE_DRILL).with_(overrides)


def main_lobe_optimum_hz(frequencies_hz: np.ndarray, metric: str, **overrides: object) -> float:
    """The main-lobe optimum (studies.scan.curve_optima, the lobe nearest the rock mode) of a frequency scan."""
    values, resonance = [], None
    for frequency in frequencies_hz:
        point = pipe_drill(**overrides, **{"impact.frequency_hz": float(frequency), "outputs": {"metrics": [metric]}})
        if not resonance:
            simulation = prepare(point)
            resonance = rock_mode_frequency_hz(simulation.chain, simulation.rock)
        values.append(rpdrill.simulate(point, budget=None).metrics[metric])
    found = curve_optimum(frequencies_hz, values, resonance, metric=metric).optimum
    assert found is not None, f"no optimum of {metric} with {overrides}"
    return found


def test_the_optimum_rises_with_the_impulse():
    """3.1 b): 160, 220, 280 kN put the penetration-rate optimum at rising frequencies (the paper:
    55-65, 60-70, 75-85 Hz), by more than the 2 Hz grid."""
    frequencies = np.arange(50.0, 82.0, 2.0)
    optima = [main_lobe_optimum_hz(frequencies, "penetration_rate_m_per_s", **{"impact.amplitude_n": amplitude})
              for amplitude in (160e3, 220e3, 280e3)]
    assert optima[1] - optima[0] > 2.0 and optima[2] - optima[1] > 2.0, optima


def test_the_optimum_rises_with_the_rock_stiffness():
    """3.2: the collar-velocity optimum moves from about 32 Hz on the softest rock (k = 8.93e7 N/m) to
    about 69 Hz on the stiffest (conglomerate, 8.4e8 N/m); here within 15 % of both."""
    frequencies = np.arange(20.0, 82.0, 2.0)
    soft = main_lobe_optimum_hz(frequencies, "collar_velocity_peak_m_per_s", **SOFT_ROCK)
    stiff = main_lobe_optimum_hz(frequencies, "collar_velocity_peak_m_per_s", rock={"name": "conglomerate"})
    assert soft == pytest.approx(32.0, rel=0.15) and stiff == pytest.approx(69.0, rel=0.15)


def crushing_window() -> rpdrill.Scene:
    """Ten blows of the pipe drill crushing at 65 Hz (every output: energies too)."""
    return pipe_drill(**{"solver.end_time_s": 10 / 65.0, "metrics": {"transient_blows": 4, "block_blows": 3}})


@pytest.fixture(scope="module")
def runs():
    """The crushing window by the exact formulation (the reference, to round-off) and the Exudyn model."""
    scene = crushing_window()
    return {"exact": rpdrill.simulate(scene, budget=None),
            "exudyn": rpdrill.simulate(scene.with_solver("exudyn", type="rk44", step_s=5e-6), budget=None)}


def test_the_arrangement_crushes_and_balances_its_energy(runs):
    for name, result in runs.items():
        assert result.bottom_m[-1] > 1e-4, name  # it drills
        assert result.energy.relative_residual() < 1e-3, name


def test_exudyn_model_agrees_with_the_exact_solution_within_the_crosscheck_tolerances(runs):
    report = compare_runs(runs["exact"].raw, runs["exudyn"].raw, runs["exact"].scene.solver.end_time_s)
    assert all(check["passed"] for check in verdict(report).values()), verdict(report)


@pytest.mark.slow
def test_the_ode_crushes_balances_its_energy_and_agrees_with_exact_and_exudyn(runs):
    """The independent formulation on the arrangement (tight tolerance): it drills, closes its energy
    balance, ends with the exact solution's bottom to 1e-9 and agrees with the Exudyn model within the
    cross-check's tolerances."""
    ode = rpdrill.simulate(crushing_window().with_solver("ode", relative_tolerance=1e-11, absolute_tolerance=1e-14),
                           budget=None)
    assert ode.bottom_m[-1] > 1e-4 and ode.energy.relative_residual() < 1e-3
    assert abs(runs["exact"].bottom_m[-1] - ode.bottom_m[-1]) <= 1e-9 * runs["exact"].bottom_m[-1]
    report = compare_runs(ode.raw, runs["exudyn"].raw, ode.scene.solver.end_time_s)
    assert all(check["passed"] for check in verdict(report).values()), verdict(report)
