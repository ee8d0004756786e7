"""Run one scene: time histories, summary figures and a plot.

Writes DIR/timeseries.csv, DIR/summary.json, DIR/scene.resolved.yaml and DIR/timeseries.png (and
.svg): the whole run beside its last blows. DIR must be new or empty (``--overwrite``: write over
what it holds). The run's steps and memory are checked against the budgets (studies.runtime.budgets)
before it starts.
"""

from __future__ import annotations

import argparse
import sys
import warnings

from ...models.cost import Cause
from ...models.formulations import FORMULATIONS
from ...models.metrics import summary_metrics
from ...models.run_status import UnsettledWarning, run_status
from ...models.stability import SimulationFailed
from ..display.catalogue import metric
from ..figures.timeseries_figure import plot_timeseries
from ..inputs.reading import load_scene, prepare_scene
from ..runtime.interrupts import raise_if_stopped
from ..runtime.output_files import (
    check_out,
    staged_directory,
    write_columns_csv,
    write_json,
    write_resolved,
)
from ..runtime.progress import time_progress
from .options import add_budget_arguments, budget

HEADLINE = ("penetration_rate_m_per_s", "advance_per_blow_m", "energy_transfer_efficiency",
            "energy_balance_relative_error")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("scene", help="scene YAML file")
    parser.add_argument("--out", required=True, help="output directory (new or empty)")
    parser.add_argument("--overwrite", action="store_true", help="write into --out although it holds other files")
    parser.add_argument("--formulation", choices=tuple(FORMULATIONS),
                        help="run with this formulation (default: the scene's solver.formulation; the scene's "
                             "options of another formulation are dropped)")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    add_budget_arguments(parser, many_runs=False)


def run(args: argparse.Namespace) -> int:
    check_out(args.out, args.overwrite)
    scene = load_scene(args.scene)
    if args.formulation:
        scene = scene.with_solver(args.formulation)
    simulation = prepare_scene(scene, args.scene)
    budget(args).check_run(simulation, args.scene, resampled=Cause("solver.output_interval_s", scene.solver.output_interval_s))
    try:
        with time_progress(scene.solver.end_time_s, scene.name, enabled=not args.quiet) as progress:
            result = simulation.run(progress)
    except SimulationFailed as err:
        raise_if_stopped()  # the run was cut by Ctrl-C or SIGTERM
        print(f"{args.scene}: {err}", file=sys.stderr)
        return 1
    summary = summary_metrics(result)
    status, why = run_status(result)
    if status == "unsettled":  # (an unstable step was said as the run started: models.exudyn_model)
        warnings.warn(why, UnsettledWarning, stacklevel=1)
    columns = result.resampled(scene.solver.output_interval_s)
    with staged_directory(args.out) as stage:
        write_columns_csv(stage / "timeseries.csv", columns)
        write_json(stage / "summary.json", {"scene": scene.name, "formulation": result.formulation,
                                            "status": status, "metrics": summary, "run": result.info})
        write_resolved(stage / "scene.resolved.yaml", simulation.resolved_scene())
        plot_timeseries(columns, scene, stage / "timeseries.png")
    shown = ", ".join(f"{metric(name).name} {metric(name).show_with_unit(value)}" for name, value in summary.items()
                      if name in HEADLINE)
    print(f"{scene.name} ({result.formulation}): {shown}; wrote {args.out}")
    return 0
