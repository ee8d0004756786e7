"""``rpdrill calibrate CALIBRATION.yaml --out DIR``: fit scene parameters so that frequency scans
put their main-lobe optima where the paper does (studies.calibration, file format in
studies.calibration_spec).

Every evaluation is appended to DIR/evaluations.jsonl as it finishes; a rerun into the same DIR
replays them and continues (a different calibration is refused). At the end DIR holds
calibrated_scene.yaml, targets.csv, targets.md, pareto.csv, best_curves.csv and calibration.json
(studies.calibration_report). Exit status 1, and no scene, when every simulation failed.
"""

from __future__ import annotations

import argparse
import contextlib
import sys
from pathlib import Path

from tqdm import tqdm

from rpdrill.studies.calibration import calibrate, planned_evaluations
from rpdrill.studies.calibration_log import EvaluationLog, Record
from rpdrill.studies.calibration_report import write_report
from rpdrill.studies.calibration_spec import load_calibration
from rpdrill.studies.commands import add_runner_arguments
from rpdrill.studies.run_files import staged_directory
from rpdrill.studies.runners import pool


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("calibration", help="calibration YAML file")
    parser.add_argument("--out", required=True, help="output directory (reused to resume)")
    add_runner_arguments(parser)


def run(args: argparse.Namespace) -> int:
    calibration = load_calibration(args.calibration)
    spec, out = calibration.spec, Path(args.out)
    with contextlib.closing(EvaluationLog(out, calibration)) as log, pool(args.dask, args.workers) as (label, runner), \
            tqdm(total=planned_evaluations(calibration), desc=spec.name, unit="eval", disable=args.quiet) as bar:
        print(f"{spec.name}: {len(calibration.names)} parameters, {len(spec.targets)} targets x "
              f"{len(calibration.frequencies_hz)} frequencies, {len(log.records)} evaluations recorded earlier, "
              f"on {label}", file=sys.stderr)
        best = [float("inf")]

        def progress(record: Record, replayed: bool) -> None:
            best[0] = min(best[0], record["objective"])
            bar.update(1)
            bar.set_postfix(best=f"{best[0]:.4g}", replayed="yes" if replayed else "no")

        result = calibrate(calibration, runner, log, progress, label)
    if result.best is None:
        print(f"{spec.name}: every simulation of all {len(result.records)} evaluations failed; first error: "
              f"{next((t['error'] for r in result.records for t in r['targets'] if t['error']), 'none')}; "
              "no scene written",
              file=sys.stderr)
        return 1
    with staged_directory(out) as stage:
        write_report(stage, calibration, result, log.checkpoint["sessions"])
    reached = ", ".join(f"{r['label']}: {'none' if r['main_hz'] is None else format(r['main_hz'], '.1f')}"
                        for r in result.final.results)
    session = result.session
    print(f"{spec.name}: best objective {result.best['objective']:.4g} of {len(result.records)} evaluations "
          f"({session['evaluations_run']} run, {session['evaluations_replayed']} replayed, "
          f"{session['wall_time_s']:.0f} s); main-lobe optima [Hz] {reached}; wrote {out}", file=sys.stderr)
    return 0
