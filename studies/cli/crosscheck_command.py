"""``rpdrill crosscheck SCENE.yaml``: the Exudyn model against the paper's Eq. 4 as a plain ODE over the
first blows (studies.crosscheck.crosscheck_windows); exit 0 when they agree within the paper tolerances, 1 if not."""

from __future__ import annotations

import argparse
import sys

from ...models.definition.formulations import ODE_METHODS
from ...models.evaluation.stability import SimulationFailed
from ..crosscheck.crosscheck_run import crosscheck
from ..crosscheck.crosscheck_windows import DEFAULT_STEP_S
from ..figures.crosscheck_figure import plot_overlay
from ..inputs.arguments import choice_problem, cli_type
from ..runtime.interrupts import raise_if_stopped
from ..runtime.output_files import check_out, staged_directory, write_json
from .options import add_allow_code_argument, add_budget_arguments, budget, positive_count, positive_number


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("scene", help="scene YAML file")
    parser.add_argument("--out", help="output directory for crosscheck.json and crosscheck.png and .svg (new or empty)")
    parser.add_argument("--overwrite", action="store_true", help="write into --out although it holds other files")
    parser.add_argument("--blows", type=positive_count, default=20, help="compared window in impact periods (default 20)")
    parser.add_argument("--step", type=positive_number, default=DEFAULT_STEP_S,
                        help=f"Exudyn step [s] (default {DEFAULT_STEP_S:g}; solver type from the scene)")
    parser.add_argument("--method", type=cli_type(choice_problem(ODE_METHODS, "method")), default="DOP853",
                        metavar="{" + ",".join(ODE_METHODS) + "}", help="ODE method (default DOP853)")
    parser.add_argument("--rtol", type=positive_number, default=1e-10, help="ODE relative tolerance (default 1e-10)")
    add_budget_arguments(parser, many_runs=False)
    add_allow_code_argument(parser)


def run(args: argparse.Namespace) -> int:
    if args.out:
        check_out(args.out, args.overwrite)
    try:
        check = crosscheck(args.scene, args.blows, args.step, args.method, args.rtol, budget(args), args.allow_code)
    except SimulationFailed as err:
        raise_if_stopped()  # the run was cut by Ctrl-C or SIGTERM
        print(f"{args.scene}: {err}", file=sys.stderr)
        return 1
    exudyn, ode = check.exudyn.raw, check.ode.raw
    print(f"{check.exudyn.scene.name}: {args.blows} blows, exudyn {exudyn.simulation.settings.type} at {args.step:g} s, "
          f"ode {args.method} at rtol {args.rtol:g} ({ode.solver.mode_switches} rock mode switches)")
    print(check.table())
    if args.out:
        with staged_directory(args.out) as stage:
            write_json(stage / "crosscheck.json", {"scene": check.exudyn.scene.name, "blows": args.blows,
                                                    "exudyn": {"solver": exudyn.simulation.settings.type,
                                                               "step_s": args.step,
                                                               "run": exudyn.solver},
                                                    "ode": ode.solver, "checks": check.checks, "passed": check.passed,
                                                    **check.report})
            plot_overlay(ode, exudyn, f"{check.exudyn.scene.name}: first {args.blows} blows", stage / "crosscheck.png")
        print(f"wrote {args.out}")
    return 0 if check.passed else 1
