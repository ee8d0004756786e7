"""``rpdrill calibrate CALIBRATION.yaml --out DIR``: fit scene parameters so that frequency scans
put their main-lobe optima where the paper does (the library's ``rpdrill.calibrate``:
studies.calibration.calibration_run; the search studies.calibration.calibration_search, file format in
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
import sys

from ..calibration.calibration_run import calibrate
from ..runtime.run_options import FIELDS
from .options import add_resumable_arguments, run_options


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_resumable_arguments(parser, "calibration", "calibration YAML file")
    parser.add_argument("--overwrite", action="store_true",
                        help="start afresh in --out although it holds other files or another calibration")


def run(args: argparse.Namespace) -> int:
    result = calibrate(args.calibration, run_options(args, *FIELDS), allow_code=args.allow_code)
    if result.best is None:
        which = f"targets {', '.join(result.failed_targets)}: every run" if result.failed_targets else "every simulation"
        print(f"{args.calibration}: {which} of all {len(result.records)} evaluations failed; first error: "
              f"{result.first_error}; no scene written", file=sys.stderr)
        return 1
    reached = ", ".join(f"{label}: {'none' if hz is None else format(hz, '.1f')}" for label, hz in result.optima_hz.items())
    session = result.session
    print(f"{result.calibration.spec.name}: best objective {result.best.objective:.4g} of {len(result.records)} "
          f"evaluations ({session['evaluations_run']} run, {session['evaluations_replayed']} replayed, "
          f"{session['wall_time_s']:.0f} s); main-lobe optima [Hz] {reached}; wrote {result.out}", file=sys.stderr)
    return 0
