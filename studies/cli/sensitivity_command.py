"""``rpdrill sensitivity FILE.yaml --out DIR``: how the frequency optima move when each scene parameter
changes by +-10 % (the paper's section 3.3), and optionally SALib's global indices (the library's
``rpdrill.sensitivity``: studies.sensitivity.sensitivity_run; the analyses studies.sensitivity.sensitivity_study).

Writes DIR/results.csv (one row per scanned variation; resumable, studies.runtime.resumable), DIR/study.json,
DIR/one_at_a_time.csv (optimum and peak changes), DIR/trends.csv (whether each variation keeps the
trends), DIR/global.csv (with a ``global`` analysis), DIR/summary.json (the paper's claim measured)
and a tornado figure per scan and metric (PNG and SVG). Exit 1 when some point failed.
"""

from __future__ import annotations

import argparse
import sys

from ..sensitivity.sensitivity_run import TAKES, sensitivity
from .options import add_resumable_arguments, run_options


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_resumable_arguments(parser, "sensitivity", "sensitivity YAML file (studies/paper/sensitivity.yaml)")


def run(args: argparse.Namespace) -> int:
    result = sensitivity(args.sensitivity, run_options(args, *TAKES), allow_code=args.allow_code)
    name, summary = result.study.spec.name, result.summary
    for metric, figures_of in summary["metrics"].items():
        top = ", ".join(f"{p} {v:.1%}" for p, v in list(figures_of["parameters_by_peak_change"].items())[:4])
        print(f"{name}: {metric}: +-{result.study.spec.relative_step:.0%} moves the optimum by at most "
              f"{figures_of['largest_optimum_shift']:.1%} and the peak by at most {figures_of['largest_peak_change']:.1%} "
              f"(median {figures_of['median_peak_change']:.1%}); largest: {top}", file=sys.stderr)
    print(f"{name}: {summary['variations_keeping_every_trend']} of {summary['variations']} variations keep "
          f"every trend; wrote {result.out} ({len(result.figures)} figures)", file=sys.stderr)
    return 1 if len(result.failed) else 0
