"""``rpdrill rotation-report RUNS_DIR --out DIR``: the rotation-speed note from the two rotation studies
(``rpdrill study studies/rotation/{rpm_frequency_map,dth_example}.yaml --out RUNS_DIR/<name>``):
``rotation.md`` and the rpm x frequency map of one rock, into DIR; with ``--docs DIR`` also copied there
(``--docs docs`` in a checkout). The library's ``rpdrill.rotation_report`` (studies.pages.rotation_note)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..pages.rotation_note import rotation_report


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("runs", type=Path, help="directory with rpm_frequency_map/ and dth_example/")
    parser.add_argument("--out", required=True, type=Path, help="output directory: new, empty, or an earlier report's")
    parser.add_argument("--overwrite", action="store_true", help="write into --out although it holds other files")
    parser.add_argument("--rock", default="sandstone", help="the rock whose map goes into the note")
    parser.add_argument("--docs", type=Path, help="also copy the note and its figure into this folder (e.g. docs)")


def run(args: argparse.Namespace) -> int:
    report = rotation_report(args.runs, args.out, args.rock, args.docs, args.overwrite)
    print(f"wrote {', '.join(map(str, report.files))}" + (f" and copied them into {args.docs}" if args.docs else ""),
          file=sys.stderr)
    return 0
