"""``rpdrill hole HOLE.yaml [B.yaml] --out DIR``: drill a hole over its depth, rod by rod and layer by layer
(studies.hole); with two or more hole files each into DIR/<file name without .yaml> and one comparison figure.

Every hole file is read and every depth's scene checked against the budgets before anything runs; running again
into the same DIR reads the runs already done and runs the rest (a Ctrl-C keeps them). What DIR holds: FILES below.
"""

from __future__ import annotations

import argparse
import sys

from ..hole.drill import HOLE_OPTIONS, drill_holes
from ..hole.hole_spec import load_hole
from .options import add_resumable_arguments, run_options

FILES = """files written to DIR (to DIR/<file name without .yaml> for each of several holes):
  hole.csv            one row a depth: rods, layer, rate, time to the depth, energy per blow reaching the
                      rock and lost in each coupling, largest rod stresses and where, efficiencies, regime
  hole.json           the summary: total time, mean rate, energy per metre, the depth where the rate falls
                      below half its start, the largest stresses and where
  hole.png            rate, time, largest rod stress and rock energy against depth (depth down), layers shaded
  scenes/*.yaml       each depth's scene (rpdrill simulate runs it)
  runs/*.json         each run's record (a rerun reads them)
  comparison.png      with several holes, in DIR: all of them on one figure"""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.formatter_class = argparse.RawDescriptionHelpFormatter
    parser.epilog = FILES
    add_resumable_arguments(parser, "hole", "hole YAML file(s) (or a shipped hole's name)", many=True)
    parser.add_argument("--overwrite", action="store_true", help="run into a DIR that holds another hole's runs")


def run(args: argparse.Namespace) -> int:
    holes = [load_hole(path, tuple(args.allow_code)) for path in args.hole]
    results = drill_holes(holes, run_options(args, *HOLE_OPTIONS), comparison=len(holes) > 1)
    for result in results:
        s = result.summary
        half = "never" if s["half_rate_depth_m"] is None else f"at {s['half_rate_depth_m']:g} m"
        print(f"{s['name']}: {s['depth_m']:g} m in {s['total_time_s'] / 60:.4g} min ({s['drilling_time_s'] / 60:.4g} "
              f"drilling, {s['rods_added']} rods added); rate {1e3 * s['start_rate_m_per_s']:.4g} -> "
              f"{1e3 * s['end_rate_m_per_s']:.4g} mm/s (mean {1e3 * s['mean_rate_m_per_s']:.4g}), half its start "
              f"{half}; {s['hammer_energy_per_m_j'] / 1e3:.4g} kJ/m from the hammer, "
              f"{s['rock_energy_per_m_j'] / 1e3:.4g} kJ/m into the rock; largest stress "
              f"{s['largest_compression']['stress_mpa']:.4g} MPa compression ({s['largest_compression']['rod']}, "
              f"{s['largest_compression']['position_m']:.3g} m below its top, at {s['largest_compression']['depth_m']:g} m "
              f"depth), {s['largest_tension']['stress_mpa']:.4g} MPa tension; "
              f"wrote {result.out}")
    for result in results:
        if "time_gained_s" in result.summary:
            print(f"{result.name}: the advised points save {result.summary['time_gained_s'] / 60:.4g} min against the "
                  f"rig's own ({result.summary['fixed_total_time_s'] / 60:.4g} min)")
    unsettled = [r.name for r in results if any(not g.startswith("settled") for g in r.summary["regimes"])]
    for name in unsettled:
        print(f"{name}: some depths did not settle (regime, settle_blows and last_change in "
              "hole.csv: their figures are their time runs' windows)", file=sys.stderr)
    return 0
