"""Fit scene parameters so that frequency scans peak where the targets say.

Writes DIR/calibration.json (every evaluation: parameters, optima, objective) and
DIR/calibrated_scene.yaml (the base scene with the best parameters).
"""

from __future__ import annotations

import argparse
import contextlib
import sys
from pathlib import Path

import yaml
from tqdm import tqdm

from rpdrill.studies.calibrate import calibrate, load_calibration
from rpdrill.studies.outputs import staged_directory, write_json
from rpdrill.studies.runners import process_pool, sequential


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("calibration", help="calibration YAML file")
    parser.add_argument("--out", required=True, help="output directory")
    parser.add_argument("--workers", type=int, default=None, help="worker processes (default: all cores)")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")


def run(args: argparse.Namespace) -> int:
    calibration = load_calibration(args.calibration)
    spec = calibration.spec
    with tqdm(total=spec.max_evaluations, desc=spec.name, unit="eval", disable=args.quiet) as bar, \
            (contextlib.nullcontext(sequential) if args.workers == 1 else process_pool(args.workers)) as runner:
        def progress(record: dict) -> None:
            bar.update(1)
            bar.set_postfix(objective=f"{record['objective']:.3g}")
        best = calibrate(calibration, runner, progress)
    scene = calibration.scene(best["parameters"])
    with staged_directory(args.out) as stage:
        write_json(stage / "calibration.json", {
            "calibration": spec.model_dump(mode="json", by_alias=True), "best": best,
            "targets_hz": [t.optimum_hz for t in spec.targets], "history": calibration.history})
        (stage / "calibrated_scene.yaml").write_text(yaml.safe_dump(scene, sort_keys=False), encoding="utf-8")
    optima = ", ".join("none" if f is None else f"{f:.1f}" for f in best["optima_hz"])
    targets = ", ".join(f"{t.optimum_hz:g}" for t in spec.targets)
    print(f"{spec.name}: best objective {best['objective']:.3g} after {len(calibration.history)} evaluations; "
          f"optima {optima} Hz (targets {targets} Hz); wrote {Path(args.out)}", file=sys.stdout)
    return 0
