"""Drill strings beyond the paper: the stress wave in a segmented rod, and what a long string costs.

Usage: python benchmarks/bench_strings.py [--repeats N]
Prints (1) for the rod of studies/scenes/wave_rod.yaml split into N segments: the travel time of
the pulse's half-peak against L / c, the change of the transmitted pulse from N/2 segments (max
norm, relative to its peak), the peak rock force over the impact amplitude (2 for a fixed end),
and CPU time; (2) CPU seconds per simulated second (median of N repeats after a warm-up) of the paper scene
and of the four-rod string (studies/scenes/four_rod_string.yaml), Exudyn model at the scene's
preset and exact formulation, with their body counts and penetration rates.
"""

from __future__ import annotations

import os

# one BLAS thread, as in a study's workers (studies.runtime.pools.WORKER_ENVIRONMENT): set before NumPy loads
for _variable in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_variable, "1")

import argparse
import statistics
from pathlib import Path

import numpy as np

from rpdrill.models.definition.scene import Scene
from rpdrill.models.evaluation.metrics import summary_metrics
from rpdrill.models.evaluation.rod_outputs import transmitted_pulse_n, travel_time_s
from rpdrill.models.runs.scene_run import run as run_simulation
from rpdrill.models.solvers.simulation import prepare
from rpdrill.studies.inputs.reading import load_scene, read_yaml

SCENES = Path(__file__).resolve().parents[1] / "studies" / "scenes"


def wave_table(segment_counts: tuple[int, ...]) -> None:
    data = read_yaml(SCENES / "wave_rod.yaml")
    grid = np.linspace(0.0, 1.3e-3, 1301)
    previous = None
    print("segments  travel time [ms]  / (L/c) - 1  pulse change  peak / amplitude  CPU s")
    for n in segment_counts:
        data["drill_string"]["bodies"]["rod"]["segments"] = n
        scene = Scene.model_validate(data)
        run = run_simulation(prepare(scene)).raw
        rod = scene.drill_string.bodies["rod"]
        travel = travel_time_s(run)
        pulse = transmitted_pulse_n(run, grid)
        change = "" if previous is None else f"{np.max(np.abs(pulse - previous)) / np.max(pulse):.3f}"
        previous = pulse
        print(f"{n:<10}{travel * 1e3:<18.4f}{travel / (rod.length_m / rod.wave_speed_m_per_s) - 1:<+13.4f}"
              f"{change:<14}{run.rock_force_n.max() / scene.impact.amplitude_n:<18.3f}{run.cpu_time_s:.3f}")
    print(f"L / c = {rod.length_m / rod.wave_speed_m_per_s * 1e3:.4f} ms (c = {rod.wave_speed_m_per_s:.0f} m/s)")


def cost(name: str, formulation: str, repeats: int) -> float:
    simulation = prepare(load_scene(SCENES / f"{name}.yaml").with_solver(formulation))
    first = run_simulation(simulation).raw  # also the warm-up (the exact formulation's kernels load on the first call)
    bodies, rate = first.position_m.shape[1], summary_metrics(first)["penetration_rate_m_per_s"]
    del first  # each result is dropped before the next run, as in a study (docs/exact.md: page faults)
    end_time_s = simulation.settings.end_time_s
    cpu = statistics.median(run_simulation(simulation).raw.cpu_time_s for _ in range(repeats)) / end_time_s
    step = f"{simulation.settings.step_s:.3g}" if formulation == "exudyn" else "-"
    print(f"{name:<18}{formulation:<13}{bodies:<8}{step:<12}{cpu:<18.4f}{rate * 1e3:.4f}")
    return cpu


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    wave_table((8, 16, 32, 64, 128))
    print(f"\nscene             formulation  bodies  step [s]    CPU s per sim s   penetration rate [mm/s]"
          f"  (median of {args.repeats})")
    for formulation in ("exudyn", "exact"):
        paper = cost("paper_base", formulation, args.repeats)
        rods = cost("four_rod_string", formulation, args.repeats)
        print(f"  {formulation}: four-rod string / paper scene = {rods / paper:.1f} times the CPU per simulated second")

if __name__ == "__main__":
    main()
