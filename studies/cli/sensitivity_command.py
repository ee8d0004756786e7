"""``rpdrill sensitivity FILE.yaml --out DIR``: how the frequency optima move when each scene parameter
changes by +-10 % (the paper's section 3.3), and optionally SALib's global indices (studies.sensitivity.sensitivity_study).

Writes DIR/results.csv (one row per scanned variation; resumable, studies.runtime.resumable), DIR/study.json,
DIR/one_at_a_time.csv (optimum and peak changes), DIR/trends.csv (whether each variation keeps the
trends), DIR/global.csv (with a ``global`` analysis), DIR/summary.json (the paper's claim measured)
and a tornado figure per scan and metric (PNG and SVG). Exit 1 when some point failed.
"""

from __future__ import annotations

import argparse
import sys

from ..figures.tornado_figures import draw_tornados
from ..runtime.output_files import check_out, write_json, write_rows_csv
from ..runtime.pools import pool
from ..runtime.resumable import RECORD, run_points
from ..sensitivity.sensitivity_study import (
    ONE_AT_A_TIME_COLUMNS,
    TREND_COLUMNS,
    columns,
    global_indices,
    load_sensitivity,
    one_at_a_time,
    row_of,
    run_variation,
    summary,
    task,
    trends,
)
from .options import add_resumable_arguments, budget


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_resumable_arguments(parser, "sensitivity", "sensitivity YAML file (studies/paper/sensitivity.yaml)")


def run(args: argparse.Namespace) -> int:
    out = check_out(args.out, None, RECORD)
    study = load_sensitivity(args.sensitivity, budget(args))
    with pool(args.dask, args.workers) as runner:
        rows = run_points(study, out, "results.csv", columns(study), lambda p: task(study, p), run_variation,
                          runner, args.quiet, lambda outcome: row_of(study, outcome))
    changes, kept, indices = one_at_a_time(study, rows), trends(study, rows), global_indices(study, rows)
    write_rows_csv(out / "one_at_a_time.csv", changes, ONE_AT_A_TIME_COLUMNS)
    write_rows_csv(out / "trends.csv", [{**k, "shortfalls": "; ".join(k["shortfalls"])} for k in kept], TREND_COLUMNS)
    if indices:
        write_rows_csv(out / "global.csv", indices)
    result = summary(study, changes, kept)
    write_json(out / "summary.json", result)
    figures = draw_tornados(changes, study.spec.name, out, ("png", "svg"))
    for metric, figures_of in result["metrics"].items():
        top = ", ".join(f"{p} {v:.1%}" for p, v in list(figures_of["parameters_by_peak_change"].items())[:4])
        print(f"{study.spec.name}: {metric}: +-{study.spec.relative_step:.0%} moves the optimum by at most "
              f"{figures_of['largest_optimum_shift']:.1%} and the peak by at most {figures_of['largest_peak_change']:.1%} "
              f"(median {figures_of['median_peak_change']:.1%}); largest: {top}", file=sys.stderr)
    print(f"{study.spec.name}: {result['variations_keeping_every_trend']} of {result['variations']} variations keep "
          f"every trend; wrote {out} ({len(figures)} figures)", file=sys.stderr)
    failed = [row for row in rows if row["status"] != "ok"]
    return 1 if failed else 0
