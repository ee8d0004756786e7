"""The piston's closed-form checks under refinement (models.drill.piston, docs/model.md "The piston"):

* rod on rod: a 0.5 m, 45 mm steel piston rod striking a 45 mm steel rod at 9 m/s (both E = 2.1e11 Pa,
  rho = 7850 kg/m3, segments of the same length): the contact force's plateau against Z v_p / 2, the
  pulse length (time above half the plateau) against 2 L_p / c, the rebound energy against 0;
* rigid piston: 4.5 kg at 9 m/s on a 0.5 m rod through a contact of k_c = 100 Z^2 / m_p: the peak against
  Z v_p (and the closed form of the piston, the contact spring and the rod's impedance), the impulse up
  to the catch against m_p (v_p - v_after).

    python benchmarks/bench_piston.py [--formulations exudyn exact] [--quick] [--rod-only]

prints the convergence table as markdown (the one in docs/model.md). ``--rod-only`` leaves out the rigid
piston (the exact formulation's operators of a 960-body chain would take gigabytes).
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from typing import Any

import numpy as np

from rpdrill.models.definition.scene import Scene
from rpdrill.models.drill.piston import rigid_piston_pulse_n
from rpdrill.models.runs.scene_run import run as run_simulation
from rpdrill.models.solvers.simulation import prepare

E_PA, RHO = 2.1e11, 7850.0
DIAMETER_M, SPEED_M_PER_S = 0.045, 9.0
AREA_M2 = math.pi * DIAMETER_M**2 / 4
IMPEDANCE = AREA_M2 * math.sqrt(E_PA * RHO)  # Z = A sqrt(E rho)
WAVE_SPEED = math.sqrt(E_PA / RHO)
STEEL = {"diameter_m": DIAMETER_M, "youngs_modulus_pa": E_PA, "density_kg_per_m3": RHO}
PISTON_LENGTH_M, RIGID_MASS_KG, RIGID_ROD_M = 0.5, 4.5, 0.5
RIGID_CONTACT = 100.0 * IMPEDANCE**2 / RIGID_MASS_KG  # 100 Z^2 / m_p: the closed form peaks 3.6 % below Z v_p


def scene(piston: dict[str, Any], rod_length_m: float, rod_segments: int, formulation: str,
          end_time_s: float) -> Scene:
    """One blow of ``piston`` on a free steel rod resting on sandstone at its far end."""
    return Scene.model_validate({
        "name": "piston_check",
        "drill_string": {"bodies": {"rod": {"length_m": rod_length_m, "segments": rod_segments, **STEEL}},
                         "impact_body": "rod", "rock_body": "rod"},
        "feed": {"force_n": 0.0},
        "impact": {"frequency_hz": 1.0 / end_time_s, "piston": {**piston, "velocity_m_per_s": SPEED_M_PER_S}},
        "rock": {"name": "sandstone"},
        "solver": {"formulation": formulation, "preset": "reference", "end_time_s": end_time_s,
                   "output_interval_s": 1e-7},
        "metrics": {"transient_blows": 0, "block_blows": 1},
        "outputs": {"metrics": ["piston_rebound_energy_j"], "timeseries": ["piston_contact_force_n"]},
    })


def rod_on_rod(piston_segments: int, formulation: str) -> dict[str, float]:
    """Plateau, pulse length and rebound energy of the equal-impedance piston rod (relative errors)."""
    rod_segments = 8 * piston_segments  # a 4 m rod: segments as long as the piston's
    piston = {"length_m": PISTON_LENGTH_M, "segments": piston_segments, **STEEL}
    result = run_simulation(prepare(scene(piston, 8 * PISTON_LENGTH_M, rod_segments, formulation, 2e-3))).raw
    t, force = result.time_s, result.piston.contact_force_n
    duration = 2 * PISTON_LENGTH_M / WAVE_SPEED
    plateau = float(np.mean(force[(t > 0.25 * duration) & (t < 0.75 * duration)]))
    above = t[(force > 0.5 * plateau) & (t < 2 * duration)]
    blow = 0.5 * RHO * AREA_M2 * PISTON_LENGTH_M * SPEED_M_PER_S**2
    return {"plateau": plateau / (0.5 * IMPEDANCE * SPEED_M_PER_S) - 1,
            "length": (above.max() - above.min()) / duration - 1,
            "rebound": float(result.piston.rebounds[0, 1]) / blow,
            "cpu_s": result.cpu_time_s}


def contact_closed_form_n(t_s: np.ndarray) -> np.ndarray:
    """The rigid piston's pulse through the contact spring into the rod as its impedance (models.drill.piston)."""
    return rigid_piston_pulse_n(t_s, RIGID_MASS_KG, SPEED_M_PER_S, IMPEDANCE, RIGID_CONTACT)


def rigid(rod_segments: int, formulation: str, per_segment: float | None = None) -> dict[str, float]:
    """Peak and impulse of the rigid piston's pulse (relative errors); the contact RIGID_CONTACT, or
    ``per_segment`` times the rod segment's stiffness E A N / L."""
    segment = E_PA * AREA_M2 * rod_segments / RIGID_ROD_M
    contact = RIGID_CONTACT if per_segment is None else per_segment * segment
    piston = {"mass_kg": RIGID_MASS_KG, "contact_stiffness_n_per_m": contact}
    result = run_simulation(prepare(scene(piston, RIGID_ROD_M, rod_segments, formulation, 1e-3))).raw
    t, force = result.time_s, result.piston.contact_force_n
    v_after = float(result.piston.rebounds[0, 2])
    caught = t <= _catch_time(result)
    impulse = float(np.trapezoid(force[caught], t[caught]))
    returned = t < 2 * RIGID_ROD_M / WAVE_SPEED  # before the rock's reflection comes back
    closed = rigid_piston_pulse_n(t[returned], RIGID_MASS_KG, SPEED_M_PER_S, IMPEDANCE, contact)
    return {"peak": float(force.max()) / (IMPEDANCE * SPEED_M_PER_S) - 1,
            "peak_closed_form": float(force.max()) / float(closed.max()) - 1,
            "shape": float(np.max(np.abs(force[returned] - closed))) / (IMPEDANCE * SPEED_M_PER_S),
            "impulse": impulse / (RIGID_MASS_KG * (SPEED_M_PER_S - v_after)) - 1,
            "cpu_s": result.cpu_time_s}


def _catch_time(result: Any) -> float:
    """When the piston was caught: the first sample where its histories show it held away."""
    parked = np.flatnonzero(result.piston.mean_velocity_m_per_s == 0.0)
    return float(result.time_s[parked[parked > 0][0]]) if np.any(parked > 0) else float(result.time_s[-1])


def _percent(value: float, sign: str = "+") -> str:
    """A relative error as a signed percentage, '-' for a check not run."""
    return "-" if math.isnan(value) else f"{value:{sign}.2%}"


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--formulations", nargs="+", default=["exudyn"])
    parser.add_argument("--quick", action="store_true", help="the two coarser levels only")
    parser.add_argument("--rod-only", action="store_true", help="the rod piston only")
    parser.add_argument("--rigid-only", action="store_true", help="the rigid piston only")
    parser.add_argument("--rigid-contact-per-segment", type=float, metavar="X",
                        help="the rigid piston's contact X times the rod segment's stiffness (default 100 Z^2 / m_p)")
    args = parser.parse_args(argv)
    levels = [(8, 240), (16, 480), (32, 960)][: 2 if args.quick else 3]
    rigid_peak = 1 - float(contact_closed_form_n(np.linspace(0, 5 * RIGID_MASS_KG / IMPEDANCE, 100001)).max()) / (
        IMPEDANCE * SPEED_M_PER_S)
    print(f"Z = {IMPEDANCE:.5g} N s/m, c = {WAVE_SPEED:.5g} m/s, Z v_p / 2 = {IMPEDANCE * SPEED_M_PER_S / 2:.5g} N, "
          f"2 L_p / c = {2 * PISTON_LENGTH_M / WAVE_SPEED * 1e6:.4g} us; rigid: k_c = {RIGID_CONTACT:.4g} N/m, "
          f"closed-form peak {rigid_peak:.2%} below Z v_p")
    print()
    print("| formulation | piston / rod segments | plateau - Z v_p/2 | length - 2 L_p/c | rebound / E_blow | "
          "rod segments (rigid) | peak - Z v_p | peak - closed form | shape error / Z v_p | impulse - m_p dv | "
          "CPU s |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for formulation in args.formulations:
        for piston_segments, rod_segments in levels:
            start = time.process_time()
            a = {key: math.nan for key in ("plateau", "length", "rebound")} if args.rigid_only \
                else rod_on_rod(piston_segments, formulation)
            b = {key: math.nan for key in ("peak", "peak_closed_form", "shape", "impulse")} if args.rod_only \
                else rigid(rod_segments, formulation, args.rigid_contact_per_segment)
            cells = [_percent(a["plateau"]), _percent(a["length"]), _percent(a["rebound"], "")]
            cells += [_percent(b["peak"]), _percent(b["peak_closed_form"]), _percent(b["shape"], ""),
                      _percent(b["impulse"])]
            print(f"| {formulation} | {piston_segments} / {8 * piston_segments} | {' | '.join(cells[:3])} | "
                  f"{rod_segments} | {' | '.join(cells[3:])} | {time.process_time() - start:.1f} |", flush=True)


if __name__ == "__main__":
    sys.exit(main())
