"""Cost of the core Exudyn model: CPU s per simulated second, symbolic vs Python user functions, the
build of the system with and without the bodies' graphics, and the accuracy of x_n(0.3 s) against step
size.

Usage: python benchmarks/bench_core.py [SCENE.yaml] [--repeats N]
Prints medians over N repeats and ratios measured in this one run (the machine is shared).
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

from rpdrill.models.definition.scene import Scene
from rpdrill.models.runs.scene_run import run as run_simulation
from rpdrill.models.solvers import exudyn_model
from rpdrill.models.solvers.simulation import prepare
from rpdrill.studies.inputs.reading import load_scene

ROOT = Path(__file__).resolve().parents[1]


def with_solver(scene: Scene, **solver: float | str) -> Scene:
    """The scene with these Exudyn solver settings, metrics over every blow."""
    return scene.model_copy(update={"metrics": scene.metrics.model_copy(
        update={"transient_blows": 0, "block_blows": 1})}).with_solver("exudyn", **solver)


def cpu_per_simulated_second(scene: Scene, repeats: int, symbolic: bool = True) -> float:
    simulation = prepare(scene)
    runs = [exudyn_model.simulate(simulation, symbolic=symbolic).cpu_time_s for _ in range(repeats)]
    return statistics.median(runs) / scene.solver.end_time_s


def build_cpu_s(scene: Scene, repeats: int, graphics: bool) -> float:
    """Median CPU seconds of building (not running) the scene's Exudyn system."""
    simulation = prepare(scene)
    times = []
    for _ in range(repeats):
        start = time.process_time()
        exudyn_model.build_exudyn(simulation, graphics=graphics)
        times.append(time.process_time() - start)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", nargs="?", default=ROOT / "studies" / "scenes" / "paper_base.yaml")
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    scene = load_scene(args.scene)
    step = prepare(scene).settings.step_s
    timing = with_solver(scene, end_time_s=1.0)
    symbolic = cpu_per_simulated_second(timing, args.repeats, symbolic=True)
    python = cpu_per_simulated_second(timing, max(1, args.repeats // 2), symbolic=False)
    print(f"scene {scene.name}, solver {prepare(timing).settings.type}, step {step:g} s, 1 s simulated")
    print(f"symbolic user functions: {symbolic:.3f} CPU s per simulated s (median of {args.repeats})")
    print(f"python user functions:   {python:.3f} CPU s per simulated s")
    print(f"ratio python / symbolic: {python / symbolic:.2f}")
    drawn, bare = (build_cpu_s(timing, 10 * args.repeats, graphics) for graphics in (True, False))
    print(f"build of the system: {drawn * 1e3:.1f} ms with the bodies' graphics (rpdrill.build_exudyn), "
          f"{bare * 1e3:.1f} ms without (a run's own system; median of {10 * args.repeats})")

    reference_step = step / 32
    reference = run_simulation(prepare(with_solver(scene, end_time_s=0.3, step_s=reference_step))).raw.bottom_m[-1]
    print(f"\nx_n(0.3 s) against rk44 at step {reference_step:g} s: {reference * 1e3:.6f} mm")
    print("step_s      x_n(0.3 s) [mm]   relative error   CPU s per simulated s")
    for factor in (4, 2, 1, 0.5, 0.25):
        run = run_simulation(prepare(with_solver(scene, end_time_s=0.3, step_s=step * factor))).raw
        error = abs(run.bottom_m[-1] - reference) / abs(reference) if reference else float("nan")
        print(f"{step * factor:<10.3g}  {run.bottom_m[-1] * 1e3:<16.6f}  {error:<15.2e}  {run.cpu_time_s / 0.3:.3f}")


if __name__ == "__main__":
    main()
