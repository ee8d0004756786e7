"""``rpdrill shipped [--kind KIND]``: the scenes, studies and analyses that ship with rpdrill, each with its
kind, the name every command and ``rpdrill.load_scene`` / ``load_study`` open it by, and its description
(studies.inputs.shipped)."""

from __future__ import annotations

import argparse
import textwrap

from ..inputs.shipped import KINDS, shipped_files


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--kind", choices=KINDS, help="only the files of this kind")


def run(args: argparse.Namespace) -> int:
    files = [f for f in shipped_files() if args.kind in (None, f.kind)]
    width = max(len(f.name) for f in files)
    for kind in KINDS:
        of_kind = [f for f in files if f.kind == kind]
        if not of_kind:
            continue
        print(f"{kind}:")
        for f in of_kind:
            text = textwrap.shorten(f.description, 100, placeholder=" ...") or "-"
            print(f"  {f.name:<{width}}  {text}")
    print("open one by its name: rpdrill.load_scene('paper_base'), rpdrill study paper/frequency_scan --out DIR")
    return 0
