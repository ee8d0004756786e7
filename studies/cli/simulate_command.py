"""Run one scene: time histories, summary figures and a plot.

Writes DIR/timeseries.csv, DIR/summary.json, DIR/scene.resolved.yaml, DIR/timeseries.png (and
.svg): the whole run beside its last blows, and DIR/drill.png: the drill string (studies.drawings.drill_drawing).
``--animate``: DIR/drill.gif, the last blows magnified, and for the Exudyn formulation Exudyn's
solution file DIR/solution.txt (studies.drawings.drill_animation.view_solution opens it in Exudyn's SolutionViewer). DIR must be new or empty (``--overwrite``: write over
what it holds). The run's steps and memory are checked against the budgets (studies.runtime.budgets)
before it starts.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import warnings
from pathlib import Path

from ...models.definition.formulations import FORMULATIONS
from ...models.evaluation.run_status import UnsettledWarning
from ...models.evaluation.stability import SimulationFailed
from ..api import save_result, simulate
from ..display.catalogue import metric
from ..drawings.drill_animation import SOLUTION_FILE
from ..inputs.arguments import choice_problem, cli_type
from ..inputs.reading import load_scene
from ..runtime.interrupts import raise_if_stopped
from ..runtime.output_files import (
    check_out,
    staged_directory,
)
from ..runtime.progress import time_progress
from .options import add_allow_code_argument, add_budget_arguments, budget

HEADLINE = ("penetration_rate_m_per_s", "advance_per_blow_m", "energy_transfer_efficiency",
            "energy_balance_relative_error")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("scene", help="scene YAML file")
    parser.add_argument("--out", required=True, help="output directory (new or empty)")
    parser.add_argument("--overwrite", action="store_true", help="write into --out although it holds other files")
    parser.add_argument("--formulation", type=cli_type(choice_problem(FORMULATIONS, "formulation")),
                        metavar="{" + ",".join(FORMULATIONS) + "}",
                        help="run with this formulation (default: the scene's solver.formulation; the scene's "
                             "options of another formulation are dropped)")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    parser.add_argument("--animate", action="store_true",
                        help="also drill.gif (the last blows, displacements magnified) and, with the exudyn formulation, "
                             "Exudyn's solution file solution.txt for its SolutionViewer")
    add_budget_arguments(parser, many_runs=False)
    add_allow_code_argument(parser)


def run(args: argparse.Namespace) -> int:
    check_out(args.out, args.overwrite)
    scene = load_scene(args.scene, args.allow_code)
    with tempfile.TemporaryDirectory() as scratch:  # the solution file, kept until the animation is drawn
        try:
            with time_progress(scene.solver.end_time_s, scene.name, enabled=not args.quiet) as progress:
                solution = Path(scratch) / SOLUTION_FILE if args.animate else None
                result = simulate(args.scene, args.formulation, progress, budget(args), solution_file=solution,
                                  allow_code=args.allow_code)
                solution = solution if solution is not None and solution.exists() else None
        except SimulationFailed as err:
            raise_if_stopped()  # the run was cut by Ctrl-C or SIGTERM
            print(f"{args.scene}: {err}", file=sys.stderr)
            return 1
        status, why = result.status, result.status_why
        if status not in ("ok", "unstable"):  # (an unstable step was said as the run started: models.solvers.exudyn_model)
            warnings.warn(why, UnsettledWarning, stacklevel=1)
        with staged_directory(args.out) as stage:
            save_result(result, stage, animate=args.animate)
            if solution is not None:
                (stage / SOLUTION_FILE).write_bytes(solution.read_bytes())
    shown = ", ".join(f"{metric(name).name} {metric(name).show_with_unit(value)}"
                      for name, value in result.metrics.items() if name in HEADLINE)
    steady = result.steady_state
    regime = "" if steady.requested != "periodic" else (
        f", {steady.regime_name}" + (f" (|mu|max {steady.floquet_max_abs:.4g})" if steady.orbit is not None else
                                     f": {steady.note}"))
    print(f"{result.scene.name} ({result.formulation}{regime}): {shown or 'no metrics asked for'}; wrote {args.out}")
    if solution is not None:
        print(f"Exudyn's viewer: python -c \"from rpdrill.studies.drawings.drill_animation import view_solution; "
              f"view_solution('{args.out}'{f', allow_code={args.allow_code!r}' if args.allow_code else ''})\"")
    return 0
