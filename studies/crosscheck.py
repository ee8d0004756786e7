"""Cross-check the Exudyn model against the plain ODE of the paper's Eq. 4 over the first blows.

Both formulations run the scene over a window of ``--blows`` impact periods from rest (default
20): the Exudyn model with the scene's solver type at ``--step`` (default 5e-6 s; measured on
paper_base, the rk44 bit velocity differs from the ODE by 1.1e-3 of its range at 2e-5 s, 9.5e-5 at
1e-5 s, 6.0e-5 at 5e-6 s; see docs/crosscheck.md), the ODE (models.ode_model) with event-located
rock switches at a tight tolerance. Only a window of early blows is compared: the rock law switches
(contact, crushing) amplify tiny differences from blow to blow, so after many blows two correct
solutions drift apart in phase and a pointwise comparison stops measuring accuracy.

Prints the largest differences of x_n(t), bit velocity and rock force (relative to each signal's
range), of x_n at the window's end, and of every summary metric, with the CPU time of each run.
Exit 0 if x_n at the window's end agrees to 1e-4 and the bit velocity to 1e-3 of its range,
1 if not (or a run failed), 2 for bad input. With ``--out DIR``: DIR/crosscheck.json and an
overlay plot DIR/crosscheck.png.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from rpdrill.models.compare import compare_runs, verdict
from rpdrill.models.formulations import ODE_METHODS
from rpdrill.models.results import SimulationResult
from rpdrill.models.scene import Scene
from rpdrill.models.stability import SimulationFailed
from rpdrill.studies.loading import load_scene, parse, prepare_scene
from rpdrill.studies.outputs import staged_directory, write_json

DEFAULT_STEP_S = 5e-6


def _positive(text: str) -> float:
    value = float(text)
    if not value > 0:
        raise argparse.ArgumentTypeError(f"{text}: must be a positive number")
    return value


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("scene", help="scene YAML file")
    parser.add_argument("--out", help="output directory for crosscheck.json and crosscheck.png")
    parser.add_argument("--blows", type=int, default=20, help="compared window in impact periods (default 20)")
    parser.add_argument("--step", type=_positive, default=DEFAULT_STEP_S,
                        help=f"Exudyn step [s] (default {DEFAULT_STEP_S:g}; solver type from the scene)")
    parser.add_argument("--method", choices=ODE_METHODS, default="DOP853", help="ODE method (default DOP853)")
    parser.add_argument("--rtol", type=_positive, default=1e-10, help="ODE relative tolerance (default 1e-10)")


def window_scenes(scene: Scene, args: argparse.Namespace, source: str) -> tuple[Scene, Scene]:
    """The scene ending after ``--blows`` periods as (Exudyn at ``--step`` with the scene's solver type,
    the ODE with ``--method`` at ``--rtol``, absolute tolerance 1e-3 rtol); InputError if invalid."""
    data = scene.model_dump(by_alias=True, exclude_none=True)
    data.pop("outputs", None)  # every output: the comparison needs forces and energies of every step
    window = {"end_time_s": args.blows * scene.impact.period_s, "output_interval_s": scene.solver.output_interval_s}
    solvers = ({"formulation": "exudyn", "type": scene.solver.type or "rk44", "step_s": args.step},
               {"formulation": "ode", "method": args.method, "relative_tolerance": args.rtol,
                "absolute_tolerance": args.rtol * 1e-3})
    where = f"{source} (cross-check: --blows {args.blows}, --step {args.step:g}, --rtol {args.rtol:g})"
    return tuple(parse(Scene, {**data, "solver": {**window, **solver}}, where) for solver in solvers)


def _table(report: dict, checks: dict) -> str:
    lines = [f"{'quantity':40s} {'ode':>13s} {'exudyn':>13s} {'max |diff|':>11s} {'rel':>9s}"]
    for name, h in report["histories"].items():
        lines.append(f"{name + ' (history)':40s} {'':>13s} {'':>13s} {h['max_abs']:11.3e} {h['max_rel_to_range']:9.2e}")
    b = report["bottom_at_window_end"]
    lines.append(f"{'borehole_bottom_m at window end':40s} {b['reference_m']:13.6e} {b['other_m']:13.6e} "
                 f"{b['abs_m']:11.3e} {b['rel']:9.2e}")
    for name, m in report["metrics"].items():
        lines.append(f"{name:40s} {m['reference']:13.6g} {m['other']:13.6g} {m['abs']:11.3e} {m['rel']:9.2e}")
    cpu = report["cpu_time_s"]
    lines.append(f"{'cpu_time_s':40s} {cpu['ode']:13.4g} {cpu['exudyn']:13.4g}")
    for name, c in checks.items():
        lines.append(f"check {name}: {c['value']:.2e} <= {c['tolerance']:g}: {'pass' if c['passed'] else 'FAIL'}")
    return "\n".join(lines)


def plot_overlay(ode: SimulationResult, exudyn: SimulationResult, title: str, path: Path) -> None:
    """x_n, bit velocity and rock force of both formulations against time."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    panels = [("bottom_m", 1e3, "borehole bottom x_n [mm]"), ("bit_velocity_m_per_s", 1.0, "bit velocity [m/s]"),
              ("rock_force_n", 1e-3, "rock force [kN]")]
    fig, axes = plt.subplots(len(panels), 1, sharex=True, figsize=(9, 8))
    for ax, (name, scale, label) in zip(axes, panels):
        ax.plot(ode.time_s, getattr(ode, name) * scale, lw=1.6, label="ODE (Eq. 4, events)")
        ax.plot(exudyn.time_s, getattr(exudyn, name) * scale, lw=0.8, ls="--", label="Exudyn")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    axes[0].legend(loc="best")
    axes[0].set_title(title)
    axes[-1].set_xlabel("time [s]")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def run(args: argparse.Namespace) -> int:
    exudyn_scene, ode_scene = window_scenes(load_scene(args.scene), args, args.scene)
    scene = exudyn_scene
    try:
        exudyn = prepare_scene(exudyn_scene, args.scene).run()
        ode = prepare_scene(ode_scene, args.scene).run()
    except SimulationFailed as err:
        print(f"rpdrill: {err}", file=sys.stderr)
        return 1
    report = compare_runs(ode, exudyn, scene.solver.end_time_s)
    checks = verdict(report)
    passed = all(c["passed"] for c in checks.values())
    print(f"{scene.name}: {args.blows} blows, exudyn {exudyn.simulation.settings.type} at {args.step:g} s, "
          f"ode {args.method} at rtol {args.rtol:g} ({ode.info['mode_switches']} rock mode switches)")
    print(_table(report, checks))
    if args.out:
        with staged_directory(args.out) as stage:
            write_json(stage / "crosscheck.json", {"scene": scene.name, "blows": args.blows,
                                                    "exudyn": {"solver": exudyn.simulation.settings.type,
                                                               "step_s": args.step,
                                                               **exudyn.info},
                                                    "ode": ode.info, "checks": checks, "passed": passed, **report})
            plot_overlay(ode, exudyn, f"{scene.name}: first {args.blows} blows", stage / "crosscheck.png")
        print(f"wrote {args.out}")
    return 0 if passed else 1
