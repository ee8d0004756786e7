"""The cases of tests/test_crosscheck.py measured: Exudyn against the ODE of Eq. 4 and the exact formulation.

Usage: python benchmarks/bench_crosscheck.py
For every case of tests/test_crosscheck.py (variants of the test drill over 15 blows from rest, Exudyn
at the cross-check's default step with the scene's solver type, rk44), prints the ODE's borehole
bottom at the window end and its rock mode switches, then the Exudyn run against the ODE at its
reference preset (DOP853, rtol 1e-10): x_n at the window end relative to max(|x_n|, F_th / k_n), bit
velocity and rock force relative to their ranges; the exact formulation's x_n against the ODE's; and
the CPU seconds of the ODE and the Exudyn run (one run each, one BLAS thread).
"""

from __future__ import annotations

import os

# one BLAS thread, as in a study's workers: set before NumPy loads
for _variable in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_variable, "1")

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
from scenes import simulate  # the frozen test drill
from test_crosscheck import CASES, scene_from_base

from rpdrill.models.evaluation.compare import compare_bottom_at, compare_runs


def main() -> None:
    print(f"{'case':<26}{'ODE x_n(end) [m]':<18}{'switches':<10}{'x_n rel':<10}{'bit velocity':<14}"
          f"{'rock force':<12}{'exact x_n rel':<15}{'ODE CPU s':<11}Exudyn CPU s")
    for case, (changes, _, _) in CASES.items():
        scene = scene_from_base(**changes)
        end = scene.solver.end_time_s
        ode = simulate(scene, "ode", preset="reference")
        exudyn, exact = simulate(scene), simulate(scene, "exact")
        report = compare_runs(ode, exudyn, end)
        histories = report["histories"]
        print(f"{case:<26}{ode.bottom_m[-1]:<18.4g}{ode.solver.mode_switches:<10}"
              f"{report['bottom_at_window_end']['rel']:<10.2e}"
              f"{histories['bit_velocity_m_per_s']['max_rel_to_range']:<14.2e}"
              f"{histories['rock_force_n']['max_rel_to_range']:<12.2e}"
              f"{compare_bottom_at(ode, exact, end)['rel']:<15.2e}"
              f"{ode.cpu_time_s:<11.3g}{exudyn.cpu_time_s:.3g}",
              flush=True)


if __name__ == "__main__":
    main()
