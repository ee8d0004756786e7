"""``rpdrill calibrate CALIBRATION.yaml --out DIR``: fit scene parameters so that frequency scans
put their main-lobe optima where the paper does (studies.calibration.calibration_search, file format in
studies.calibration.calibration_spec).

Every evaluation is appended to DIR/evaluations.jsonl as it finishes; a rerun into the same DIR
replays them and continues (a different calibration, and a DIR holding anything else, are refused
unless ``--overwrite``, which starts afresh there). Every run's budget, and the search's, are
checked before it starts (studies.runtime.budgets). At the end DIR holds calibrated_scene.yaml,
targets.csv, targets.md, pareto.csv, best_curves.csv and calibration.json
(studies.calibration.calibration_report). Exit status 1, and no scene, when every simulation failed or every
run of a target did.
"""

from __future__ import annotations

import argparse
import contextlib
import shutil
import sys

from tqdm import tqdm

from ..calibration.calibration_report import write_report
from ..calibration.calibration_search import calibrate
from ..calibration.calibration_spec import load_calibration
from ..runtime.budgets import duration
from ..runtime.evaluation_log import CHECKPOINT, EvaluationLog, Record
from ..runtime.output_files import check_out, staged_directory
from ..runtime.pools import pool
from .options import add_resumable_arguments, budget


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_resumable_arguments(parser, "calibration", "calibration YAML file")
    parser.add_argument("--overwrite", action="store_true",
                        help="start afresh in --out although it holds other files or another calibration")


def run(args: argparse.Namespace) -> int:
    out = check_out(args.out, args.overwrite, CHECKPOINT)
    calibration = load_calibration(args.calibration, budget(args))
    new = not out.exists() or all(p.name.startswith(".") for p in out.iterdir())  # (its lock: studies.runtime.out_lock)
    spec = calibration.spec
    with contextlib.closing(EvaluationLog(out, calibration.identity, calibration.source, args.overwrite)) as log, \
            pool(args.dask, args.workers) as (label, runner), \
            tqdm(total=calibration.evaluations, desc=spec.name, unit="eval", disable=args.quiet) as bar:
        print(f"{spec.name}: {len(calibration.names)} parameters, {len(spec.targets)} targets x "
              f"{len(calibration.frequencies_hz)} frequencies, {len(log.records)} of {calibration.evaluations} "
              f"evaluations recorded earlier (estimated {duration(calibration.cpu_s)} of CPU for all), on {label}",
              file=sys.stderr)
        best = [float("inf")]

        def progress(record: Record, replayed: bool) -> None:
            best[0] = min(best[0], record["objective"])
            bar.update(1)
            bar.set_postfix(best=f"{best[0]:.4g}", replayed="yes" if replayed else "no")

        result = calibrate(calibration, runner, log, progress, label)
    if result.best is None:
        failed = [i for i, label in enumerate(calibration.labels) if label in result.failed_targets]
        which = f"targets {', '.join(result.failed_targets)}: every run" if result.failed_targets else "every simulation"
        error = next((r["targets"][i]["error"] for r in result.records for i in failed or range(len(spec.targets))
                      if r["targets"][i]["error"]), "none")
        print(f"{args.calibration}: {which} of all {len(result.records)} evaluations failed; first error: {error}; "
              "no scene written", file=sys.stderr)
        if new:  # nothing worth keeping: a rerun would replay the failures
            shutil.rmtree(out)
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
