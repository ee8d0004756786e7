"""``rpdrill rotation-report RUNS_DIR --out DIR``: the rotation-speed note from the two rotation studies
(``rpdrill study studies/rotation/{rpm_frequency_map,dth_example}.yaml --out RUNS_DIR/<name>``):
``rotation.md`` and the rpm x frequency map of one rock (studies.pages.rotation_note), into DIR; with
``--docs DIR`` also copied there (``--docs docs`` in a checkout)."""

from __future__ import annotations

import argparse
import shlex
import shutil
import sys
from pathlib import Path

from ..pages.rotation_note import check_runs, write_report
from ..runtime.output_files import check_out, staged_directory


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("runs", type=Path, help="directory with rpm_frequency_map/ and dth_example/")
    parser.add_argument("--out", required=True, type=Path, help="output directory: new, empty, or an earlier report's")
    parser.add_argument("--overwrite", action="store_true", help="write into --out although it holds other files")
    parser.add_argument("--rock", default="sandstone", help="the rock whose map goes into the note")
    parser.add_argument("--docs", type=Path, help="also copy the note and its figure into this folder (e.g. docs)")


def made_by(args: argparse.Namespace) -> str:
    """The command line that made the note, as the note states it."""
    words = ["rpdrill", "rotation-report", str(args.runs), "--out", str(args.out)]
    words += ["--rock", args.rock] if args.rock != "sandstone" else []
    words += ["--docs", str(args.docs)] if args.docs is not None else []
    return f"`{shlex.join(words)}`"


def run(args: argparse.Namespace) -> int:
    check_out(args.out, args.overwrite, "rotation.md")
    if args.docs is not None:
        check_out(args.docs, True, option="--docs")
    check_runs(args.runs, args.rock)
    with staged_directory(args.out) as stage:
        written = [args.out / p.name for p in write_report(args.runs, stage, args.rock, made_by(args))]
    if args.docs is not None:
        args.docs.mkdir(parents=True, exist_ok=True)
        for path in written:
            shutil.copy(path, args.docs / path.name)
    print(f"wrote {', '.join(map(str, written))}" + (f" and copied them into {args.docs}" if args.docs else ""),
          file=sys.stderr)
    return 0
