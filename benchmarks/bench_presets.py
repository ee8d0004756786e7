"""The Exudyn accuracy presets against their targets, measured in one run.

Usage: python benchmarks/bench_presets.py [--repeats N] [--presets fast,standard,reference] [--front [--sweeps S,...] | --modules]
With ``--modules``: each preset's CPU seconds per simulated second on the paper scene with Exudyn's
regular compiled module (``EXUDYN_MODULE=regular``) and with the fast one the rpdrill command loads
(rocklaw.exudyn_module), each in its own child process, alternated three times; the medians, their
ratio and the largest relative difference of the penetration rate between the two.
With ``--front``: the work-precision fronts the presets are picked from, one per bound of their step
rule (:func:`front`): rk44, rk67 and generalized-alpha at step = min(1e-4 s, pulse / 10, c x the
bound's time scale) over a range of c, on the scenes the bound governs; printed per candidate: its
CPU seconds per simulated second (median of N runs after a warm-up), its largest penetration-rate and
energy-balance errors over those scenes, the candidates on the front (no other both cheaper and more
accurate) marked; then the automatic-step dopri5 and ode23 at a few tolerances on every scene
(:func:`automatic`). ``--sweeps`` picks some of them (stability, ringing, damper, automatic).
Otherwise prints, for each preset of models.evaluation.solver_settings: its solver and step on the shipped paper scene,
the CPU seconds per simulated second there (1 s simulated, every output, median of N runs after a
warm-up, results dropped between runs), and on the paper scene and every hard scene of
tests/stability/hard_scenes.py (the frozen test drill varied) the penetration-rate error against the
exact formulation and the energy-balance error; then the largest errors over the scenes against
what the preset states, and the cost against the issue's targets (fast 0.05, standard 0.1); last, how
much the undamped scene's exact penetration rate moves for a 1e-9 change of the impact amplitude.
"""

from __future__ import annotations

import os

# one BLAS thread, as in a study's workers (studies.runtime.pools.WORKER_ENVIRONMENT): set before NumPy loads
for _variable in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_variable, "1")

import argparse
import json
import math
import statistics
import subprocess
import sys
import warnings
from collections.abc import Callable
from pathlib import Path

from rpdrill.models.definition.scene import Scene
from rpdrill.models.evaluation.metrics import summary_metrics
from rpdrill.models.evaluation.solver_settings import EXUDYN_PRESETS
from rpdrill.models.evaluation.stability import StepScales
from rpdrill.models.evaluation.workprecision import pareto_front
from rpdrill.models.solvers.simulation import prepare
from rpdrill.studies.inputs.reading import load_scene

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))  # the hard scenes of the stability suite
from stability.hard_scenes import HARD_SCENES, hard_scene

from rpdrill.models.runs.scene_run import run as run_simulation

COST_TARGETS = {"fast": 0.05, "standard": 0.1}


def rate_error(metrics: dict[str, float], exact: dict[str, float]) -> float:
    reference = exact["penetration_rate_m_per_s"]
    return abs(metrics["penetration_rate_m_per_s"] - reference) / max(abs(reference), 1e-9)


def cost(scene: Scene, repeats: int) -> float:
    simulation = prepare(scene)
    run_simulation(simulation)  # warm-up
    runs = []
    for _ in range(repeats):
        runs.append(run_simulation(simulation).raw.cpu_time_s)  # the result is dropped at once
    return statistics.median(runs) / scene.solver.end_time_s


UNDAMPED, CRITICAL = "no_damping", "critical_damping"
SOLVERS = ("rk44", "rk67", "generalized_alpha")
# (what the factor c multiplies, the scenes the bound governs, the rate it divides by, the factors)
SWEEPS: dict[str, tuple[str, tuple[str, ...] | None, Callable[[StepScales], float], tuple[float, ...]]] = {
    "stability": ("1 / |lambda|_max", None, lambda scales: scales.spectral_radius_per_s, (2.2, 1.9, 1.5, 1.0, 0.7, 0.5)),
    "ringing": ("1 / |lambda| of the fastest mode ringing at the next blow", (UNDAMPED,),
                lambda scales: scales.ringing_radius_per_s, (0.5, 0.4, 0.3, 0.2, 0.1)),
    "damper": ("m_bit / c_n", (CRITICAL,), lambda scales: scales.damper_rate_per_s, (0.1, 0.07, 0.05, 0.03, 0.02)),
}


AUTOMATIC = tuple((solver, tolerance) for solver in ("dopri5", "ode23") for tolerance in (1e-2, 1e-3, 1e-4))


def measure(candidates: dict[str, Scene], exact: dict[str, dict[str, float]],
            repeats: int) -> tuple[float, dict[str, float], float]:
    """(CPU seconds per simulated second of the first candidate, median of ``repeats`` runs after a
    warm-up; each scene's penetration-rate error, inf for a run that failed; the largest energy-balance
    error) of the candidate scenes, by scene name."""
    per_second, errors, energy = float("nan"), {}, 0.0
    for name, candidate in candidates.items():
        try:
            metrics = summary_metrics(run_simulation(prepare(candidate)).raw)
        except Exception:  # noqa: BLE001 - a diverged or failed candidate is off the front
            errors[name] = energy = float("inf")
            continue
        if math.isnan(per_second):
            per_second = cost(candidate, repeats)
        errors[name] = rate_error(metrics, exact[name])
        energy = max(energy, metrics["energy_balance_relative_error"])
    return per_second, errors, energy


def automatic(scenes: dict[str, Scene], exact: dict[str, dict[str, float]], repeats: int) -> None:
    """The automatic-step solvers (their largest step min(1e-4 s, pulse / 10), absolute tolerance
    1e-12, the default) at each relative tolerance: CPU seconds per simulated second on paper_base,
    the largest rate and energy errors over every scene and the scene of the largest rate error."""
    print("\nautomatic: dopri5 and ode23, largest step min(1e-4 s, pulse / 10), on every scene; CPU on paper_base")
    print(f"{'solver':<10}{'rtol':<8}{'CPU s / sim s':<15}{'rate error':<14}{'energy error':<14}worst scene")
    for solver, tolerance in AUTOMATIC:
        per_second, errors, energy = measure(
            {name: scene.with_solver("exudyn", type=solver, relative_tolerance=tolerance,
                                     step_s=min(1e-4, scene.impact.duration_s / 10)) for name, scene in scenes.items()},
            exact, repeats)
        worst = max(errors, key=errors.__getitem__)
        print(f"{solver:<10}{tolerance:<8g}{per_second:<15.4f}{errors[worst]:<14.2e}{energy:<14.2e}{worst}")


def front(scenes: dict[str, Scene], exact: dict[str, dict[str, float]], repeats: int,
          sweeps: list[str]) -> None:
    """Per bound of the presets' step rule (models.evaluation.solver_settings.ExudynPreset.step_limits), every
    solver at step = min(1e-4 s, pulse / 10, c x the bound's time scale) on the scenes that bound
    governs: ``stability`` on paper_base and the damped hard scenes, ``ringing`` on the undamped one,
    ``damper`` on the critically damped one. Printed: the CPU seconds per simulated second on the first
    scene (median of ``repeats`` runs after a warm-up), the largest penetration-rate and energy-balance
    errors over the scenes, ``*`` on the front of cost against rate error."""
    for bound, (scale, names, rate_per_s, factors) in SWEEPS.items():
        if bound not in sweeps:
            continue
        chosen = {name: scenes[name] for name in names} if names else \
            {name: scene for name, scene in scenes.items() if name != UNDAMPED}
        print(f"\n{bound}: step = min(1e-4 s, pulse / 10, c x {scale}) on {', '.join(chosen)}; CPU on {next(iter(chosen))}")
        print(f"{'solver':<20}{'c':<6}{'CPU s / sim s':<15}{'rate error':<14}{'energy error':<14}front")
        steps = {name: prepare(scene).step_scales for name, scene in chosen.items()}
        rows = []
        for solver in SOLVERS:
            for factor in factors:
                per_second, errors, energy = measure(
                    {name: scene.with_solver("exudyn", type=solver, step_s=min(
                        1e-4, scene.impact.duration_s / 10, factor / rate_per_s(steps[name])))
                     for name, scene in chosen.items()}, exact, repeats)
                rows.append((solver, factor, per_second, max(errors.values()), energy))
        on_front = set(pareto_front([r[2] for r in rows], [r[3] for r in rows]))
        for i, (solver, factor, per_second, rate, energy) in enumerate(rows):
            print(f"{solver:<20}{factor:<6g}{per_second:<15.4f}{rate:<14.2e}{energy:<14.2e}{'*' if i in on_front else ''}")
    if "automatic" in sweeps:
        automatic(scenes, exact, repeats)


def paper_costs(presets: list[str], repeats: int) -> dict[str, tuple[float, float]]:
    """(CPU s per simulated s, penetration rate) of each preset on the paper scene, in this process."""
    paper = load_scene(ROOT / "studies" / "scenes" / "paper_base.yaml")
    return {preset: (cost(paper.with_solver("exudyn", preset=preset), repeats), summary_metrics(
        run_simulation(prepare(paper.with_solver("exudyn", preset=preset))).raw)["penetration_rate_m_per_s"]) for preset in presets}


def modules(presets: list[str], repeats: int, rounds: int = 3) -> None:
    """The presets' cost with Exudyn's regular and fast modules (module doc), a child process each."""
    measured: dict[str, list[dict[str, list[float]]]] = {"regular": [], "fast": []}
    for _ in range(rounds):
        for module, runs in measured.items():
            environment = {k: v for k, v in os.environ.items() if k != "EXUDYN_MODULE"}
            environment["EXUDYN_MODULE"] = module  # "fast": as the rpdrill command runs (studies.cli.main.choose_exudyn_build)
            child = subprocess.run([sys.executable, __file__, "--presets", ",".join(presets), "--repeats",
                                    str(repeats), "--one-module"], env=environment, check=True,
                                   capture_output=True, text=True)
            runs.append(json.loads(child.stdout.splitlines()[-1]))
    print(f"{'preset':<12}{'regular CPU s / sim s':<24}{'fast CPU s / sim s':<22}{'fast / regular':<17}"
          "rate difference")
    for preset in presets:
        regular, fast = (statistics.median(run[preset][0] for run in measured[m]) for m in ("regular", "fast"))
        rates = [run[preset][1] for m in measured for run in measured[m]]
        spread = (max(rates) - min(rates)) / abs(statistics.median(rates))
        print(f"{preset:<12}{regular:<24.4f}{fast:<22.4f}{fast / regular:<17.3f}{spread:.1e}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--presets", default=",".join(EXUDYN_PRESETS))
    parser.add_argument("--front", action="store_true", help="measure the candidates' front instead")
    parser.add_argument("--sweeps", default=",".join([*SWEEPS, "automatic"]),
                        help="the fronts to measure with --front (default: all)")
    parser.add_argument("--modules", action="store_true", help="the regular against the fast Exudyn module")
    parser.add_argument("--one-module", action="store_true", help=argparse.SUPPRESS)  # a child of --modules
    args = parser.parse_args()
    warnings.simplefilter("ignore")  # step-limit warnings of the explicit solvers: errors are measured
    if args.one_module:
        print(json.dumps(paper_costs(args.presets.split(","), args.repeats)))
        return
    if args.modules:
        modules(args.presets.split(","), args.repeats)
        return
    scenes = {"paper_base": load_scene(ROOT / "studies" / "scenes" / "paper_base.yaml")}
    scenes.update({name: hard_scene(overrides) for name, overrides in HARD_SCENES.items()})
    exact = {name: summary_metrics(run_simulation(prepare(scene.with_solver("exact"))).raw) for name, scene in scenes.items()}
    if args.front:
        front(scenes, exact, args.repeats, args.sweeps.split(","))
        return
    for preset in args.presets.split(","):
        stated = EXUDYN_PRESETS[preset]
        paper = scenes["paper_base"].with_solver("exudyn", preset=preset)
        settings = prepare(paper).settings
        per_second = cost(paper, args.repeats)
        print(f"\npreset {preset}: {settings.type}, step {settings.step_s:.3g} s on paper_base; "
              f"{per_second:.4f} CPU s per simulated s (median of {args.repeats})"
              + (f", target {COST_TARGETS[preset]}: ratio {per_second / COST_TARGETS[preset]:.2f}"
                 if preset in COST_TARGETS else ""))
        print(f"  {'scene':<28}{'step [s]':<12}{'rate error':<14}{'energy error':<14}CPU s / sim s")
        worst = {"rate": 0.0, "energy": 0.0}
        for name, scene in scenes.items():
            simulation = prepare(scene.with_solver("exudyn", preset=preset))
            result = run_simulation(simulation).raw
            metrics = summary_metrics(result)
            error, energy = rate_error(metrics, exact[name]), metrics["energy_balance_relative_error"]
            worst = {"rate": max(worst["rate"], error), "energy": max(worst["energy"], energy)}
            print(f"  {name:<28}{simulation.settings.step_s:<12.3g}{error:<14.2e}{energy:<14.2e}"
                  f"{result.cpu_time_s / scene.solver.end_time_s:.4f}")
        print(f"  largest: rate {worst['rate']:.2e} (stated {stated.penetration_rate_error:g}), energy "
              f"{worst['energy']:.2e} (stated {stated.energy_balance_error:g})")
    undamped = scenes[UNDAMPED]
    nudged = undamped.model_copy(update={"impact": undamped.impact.model_copy(
        update={"amplitude_n": undamped.impact.amplitude_n * (1 + 1e-9)})})
    change = rate_error(summary_metrics(run_simulation(prepare(nudged.with_solver("exact"))).raw), exact[UNDAMPED])
    print(f"\n{UNDAMPED}: the exact penetration rate changes by {change:.1e} (relative) for a 1e-9 relative change "
          "of the impact amplitude (the scene is not sensitive: its preset errors are the solvers')")


if __name__ == "__main__":
    main()
