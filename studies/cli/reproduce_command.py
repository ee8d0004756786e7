"""``rpdrill reproduce --out DIR``: the paper reproduced on the shipped scene, and the generated docs (the
library's ``rpdrill.reproduce``: studies.pages.reproduction_run).

Scans every case of the reproduction file (default ``studies/paper/reproduction.yaml``) on a 1 Hz
grid with the exact formulation and writes into DIR: ``reproduction.md`` (the paper against rpdrill,
the trends, the sub-harmonic lobes), ``figures.md`` with the paper's Figs. 2-6 redrawn
(``figures/fig<N>.png``/``.svg``), ``parameters.md`` (the shipped scene's values, the bounds and reasons of
the reproduction file's ``calibration`` file, the rock-mode resonances, and the calibration run given by
``--calibration``),
``sensitivity.md`` when ``--sensitivity`` names a sensitivity run, ``cases.csv`` (every curve) and
``reproduction.json``. With ``--docs DIR`` the pages and figures are also copied into that folder
(``--docs docs`` in a checkout). Exit 1 when an optimum the paper states is not reached within the
tolerance or a trend does not hold.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..pages.reproduction_run import DEFAULT, reproduce
from .options import add_allow_code_argument, add_runner_arguments, run_options


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("reproduction", nargs="?", default=str(DEFAULT),
                        help="reproduction YAML file (default: the paper's, studies/paper/reproduction.yaml)")
    parser.add_argument("--out", required=True, help="output directory: new, empty, or an earlier reproduction's")
    parser.add_argument("--overwrite", action="store_true", help="write into --out although it holds other files")
    parser.add_argument("--calibration", type=Path, help="output directory of `rpdrill calibrate` for parameters.md")
    parser.add_argument("--sensitivity", type=Path, help="output directory of `rpdrill sensitivity` for sensitivity.md")
    parser.add_argument("--docs", type=Path, help="also copy the pages and figures into this folder (e.g. docs)")
    add_runner_arguments(parser)
    add_allow_code_argument(parser)


def run(args: argparse.Namespace) -> int:
    result = reproduce(args.reproduction, args.calibration, args.sensitivity, args.docs,
                       options=run_options(args, "workers", "dask", "out", "overwrite"), allow_code=args.allow_code)
    trends = result.trends
    print(f"{result.reproduction.spec.name}: {sum(t['rises'] for t in trends)} of {len(trends)} trends hold; "
          f"{len(result.reached)} of {len(result.stated)} optima the paper states reached within "
          f"{result.reproduction.spec.tolerance:.0%}; wrote {args.out}" + (f" and {args.docs}" if args.docs else ""),
          file=sys.stderr)
    return 0 if result.passed else 1
