"""A rigid piston that reproduces the paper's prescribed pulse (issue #31, item 5): the mass m_p, strike
speed v_p and contact stiffness k_c whose contact force on the shank of studies/scenes/paper_base.yaml
comes closest to the paper's 220 kN half-sine of 3.79 ms, fitted by Nelder-Mead on the exact
formulation over the first blow (least squares over the period), the residual, and the penetration
rate of the paper's scene with the prescribed pulse and with the fitted piston.

The piston's mass is that of the shank, the struck body (``--free-mass``: fitted too, within BOUNDS).
A free mass makes the fit run off to a light piston at the fastest speed allowed on a soft spring: a
force source that reproduces any pulse and keeps almost all its energy (the rebound energy printed),
no hammer's piston; a piston of the shank's mass gives up its energy to it.

    python benchmarks/bench_piston_paper.py
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np
from scipy import optimize

from rpdrill.models.definition.scene import Scene
from rpdrill.models.drill.pulse import impact_force
from rpdrill.models.evaluation.metrics import summary_metrics
from rpdrill.models.runs.scene_run import run as run_simulation
from rpdrill.models.solvers.simulation import prepare
from rpdrill.studies.inputs.reading import read_yaml

SCENE = Path(__file__).resolve().parents[1] / "studies" / "scenes" / "paper_base.yaml"
BOUNDS = ((5.0, 500.0), (1.0, 30.0), (1e6, 1e10))  # m_p [kg], v_p [m/s], k_c [N/m]


def piston_scene(base: dict, mass_kg: float, velocity_m_per_s: float, stiffness_n_per_m: float,
                 blows: int | None = None) -> Scene:
    """The paper's scene with the fitted piston in place of its pulse (one blow, or its own run)."""
    impact = {"frequency_hz": base["impact"]["frequency_hz"],
              "piston": {"mass_kg": mass_kg, "velocity_m_per_s": velocity_m_per_s,
                         "contact_stiffness_n_per_m": stiffness_n_per_m}}
    data = {**base, "impact": impact, "solver": {**base["solver"], "formulation": "exact"}}
    data["solver"].pop("preset", None)
    if blows is not None:
        data["solver"] = {"formulation": "exact", "end_time_s": blows / impact["frequency_hz"],
                          "output_interval_s": 1e-5}
        data["metrics"] = {"transient_blows": 0, "block_blows": blows}
        data["outputs"] = {"metrics": ["window_blows"], "timeseries": ["piston_contact_force_n"]}
    return Scene.model_validate(data)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--free-mass", action="store_true", help="fit the piston's mass too")
    args = parser.parse_args()
    base = read_yaml(SCENE)
    paper = Scene.model_validate(base)
    amplitude, tau = paper.impact.amplitude_n, paper.impact.duration_s
    bodies = paper.drill_string.bodies
    struck = sum(bodies[name].mass_kg for name in ("shank", "collar", "bit"))  # glued by k2, k3 during the pulse
    reduced = bodies["shank"].mass_kg * struck / (bodies["shank"].mass_kg + struck)
    omega = math.pi / tau
    guess = np.log([bodies["shank"].mass_kg, amplitude / (reduced * omega), reduced * omega**2])

    fixed = [] if args.free_mass else [guess[0]]

    def residual(logs: np.ndarray) -> float:
        result = run_simulation(prepare(piston_scene(base, *np.exp([*fixed, *logs]), blows=1))).raw
        target = impact_force(paper.impact, result.time_s)
        return float(np.sqrt(np.mean((result.piston.contact_force_n - target) ** 2)) / amplitude)

    start = residual(guess[len(fixed):])
    fit = optimize.minimize(residual, guess[len(fixed):], method="Nelder-Mead", bounds=np.log(BOUNDS[len(fixed):]),
                            options={"xatol": 1e-4, "fatol": 1e-6, "maxiter": 300})
    mass, speed, stiffness = np.exp([*fixed, *fit.x])
    one = run_simulation(prepare(piston_scene(base, mass, speed, stiffness, blows=1))).raw
    print(f"guess (a shank-mass piston on shank + collar + bit, free): m_p {math.exp(guess[0]):.4g} kg, "
          f"v_p {math.exp(guess[1]):.4g} m/s, k_c {math.exp(guess[2]):.4g} N/m: RMS residual {start:.2%} of 220 kN")
    print(f"fitted ({fit.nfev} runs): m_p {mass:.4g} kg, v_p {speed:.4g} m/s, k_c {stiffness:.4g} N/m, blow energy "
          f"{0.5 * mass * speed**2:.4g} J: RMS residual {fit.fun:.2%} of 220 kN; peak "
          f"{one.piston.contact_force_n.max() / 1e3:.4g} kN; impulse "
          f"{np.trapezoid(one.piston.contact_force_n, one.time_s):.4g} N s against the pulse's "
          f"{2 / math.pi * amplitude * tau:.4g} N s; rebound energy {one.piston.rebounds[0, 1]:.4g} J")
    for label, scene in (("prescribed pulse", paper.with_solver("exact")),
                         ("fitted piston", piston_scene(base, mass, speed, stiffness))):
        metrics = summary_metrics(run_simulation(prepare(scene)).raw)
        print(f"{label}: penetration rate {metrics['penetration_rate_m_per_s'] * 1e3:.4g} mm/s, impact energy in the "
              f"window {metrics['impact_energy_j']:.4g} J")


if __name__ == "__main__":
    main()
