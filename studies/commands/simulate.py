"""Run one scene: time histories, summary figures and a plot.

Writes DIR/timeseries.csv, DIR/summary.json, DIR/scene.resolved.yaml and DIR/timeseries.png (and
.svg): the whole run beside its last blows.
"""

from __future__ import annotations

import argparse
import sys

from rpdrill.models.formulations import FORMULATIONS
from rpdrill.models.metrics import summary_metrics
from rpdrill.models.stability import SimulationFailed
from rpdrill.studies.catalogue import metric
from rpdrill.studies.loading import load_scene, prepare_scene
from rpdrill.studies.plots.timeseries import plot_timeseries
from rpdrill.studies.progress import time_progress
from rpdrill.studies.run_files import staged_directory, write_columns_csv, write_json, write_resolved

HEADLINE = ("penetration_rate_m_per_s", "advance_per_blow_m", "energy_transfer_efficiency",
            "energy_balance_relative_error")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("scene", help="scene YAML file")
    parser.add_argument("--out", required=True, help="output directory")
    parser.add_argument("--formulation", choices=tuple(FORMULATIONS),
                        help="run with this formulation (default: the scene's solver.formulation; the scene's "
                             "options of another formulation are dropped)")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")


def run(args: argparse.Namespace) -> int:
    scene = load_scene(args.scene)
    if args.formulation:
        scene = scene.with_solver(args.formulation)
    simulation = prepare_scene(scene, args.scene)
    try:
        with time_progress(scene.solver.end_time_s, scene.name, enabled=not args.quiet) as progress:
            result = simulation.run(progress)
    except SimulationFailed as err:
        print(f"rpdrill: {err}", file=sys.stderr)
        return 1
    summary = summary_metrics(result)
    columns = result.resampled(scene.solver.output_interval_s)
    with staged_directory(args.out) as stage:
        write_columns_csv(stage / "timeseries.csv", columns)
        write_json(stage / "summary.json", {"scene": scene.name, "formulation": result.formulation,
                                            "metrics": summary, "run": result.info})
        write_resolved(stage / "scene.resolved.yaml", simulation.resolved_scene())
        plot_timeseries(columns, scene, stage / "timeseries.png")
    shown = ", ".join(f"{metric(name).name} {metric(name).show_with_unit(value)}" for name, value in summary.items()
                      if name in HEADLINE)
    print(f"{scene.name} ({result.formulation}): {shown}; wrote {args.out}")
    return 0
