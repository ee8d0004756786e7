"""``rpdrill advise SCENE.yaml --frequency-hz LOW HIGH --feed-kn LOW HIGH --out DIR``: the operating point
that maximises a metric within the bounds given (the library's ``rpdrill.advise``: studies.advice.advice_run; the search studies.advice.advice_search), for the scene's rock or for each
``--rock``. Bounds are in the units of the option names. Prints the best point and the metric
around it, one parameter at a time; exit status 1 when every run failed.
"""

from __future__ import annotations

import argparse
import shlex
import sys
from pathlib import Path

from ...rocklaw.catalog import TABLE_1
from ..advice.advice_report import advice_text, best_table
from ..advice.advice_run import ADVISE_OPTIONS, advise_scene
from ..advice.advice_search import METRICS, PARAMETERS, AdviceSearch, AdviseParameter, NoAllowedPoint
from ..display.catalogue import parameter
from ..inputs.arguments import choice_problem, cli_type
from ..runtime.evaluation_log import CHECKPOINT, EVALUATIONS
from ..runtime.output_files import check_file_target, check_out
from .options import (
    add_allow_code_argument,
    add_runner_arguments,
    positive_count,
    positive_number,
    run_options,
    seed,
)

FILES = f"""files written to DIR (an interrupted advice keeps its points there: the same command again
replays them and runs the rest):
  advice.json                   the command, and per rock: the best point, the metric there, the search
                                (runs, generations, wall time), the curves around the optimum, the
                                feed x frequency map and where along the feed the metric is highest (SI units)
  advice.md                     the table of best points and the feed-force response (display units)
  ROCK_curves.png               the metric along each parameter through the optimum (and .svg)
  ROCK_feed_frequency_map.png   the metric over feed force and impact frequency (and .svg)
  {EVALUATIONS:<30}every point run, as it returned (the checkpoint)
  {CHECKPOINT:<30}what determines the points (its hash) and the sessions"""


def _given(args: argparse.Namespace, entry: AdviseParameter) -> tuple[float, float] | None:
    """The bounds given for a parameter (display units), or None."""
    return getattr(args, entry.option.removeprefix("--").replace("-", "_"))


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.formatter_class = argparse.RawDescriptionHelpFormatter
    parser.epilog = FILES
    parser.add_argument("scene", help="scene YAML file")
    parser.add_argument("--out", required=True, help="output directory: new, empty, or earlier advice's")
    parser.add_argument("--overwrite", action="store_true", help="write into --out although it holds other files")
    for entry in PARAMETERS:
        q = parameter(entry.path)
        parser.add_argument(entry.option, nargs=2, type=float, metavar=("LOW", "HIGH"),
                            required=entry.required,
                            help=f"bounds of the {q.name} [{q.unit}]" + ("" if entry.required else
                                                                        " (default: fixed at the scene's value)"))
    parser.add_argument("--metric", type=cli_type(choice_problem(METRICS, "metric")), default=METRICS[0],
                        metavar="{" + ",".join(METRICS) + "}",
                        help=f"what to maximise (default {METRICS[0]}; {METRICS[1]}: penetration rate / impact power; "
                             f"{METRICS[2]}: penetration rate / hammer power, a piston scene)")
    parser.add_argument("--power-kw", type=positive_number, metavar="P",
                        help="a fixed hammer power [kW] (a piston scene): at every point the blow energy is P / f, "
                             "so the search trades frequency against blow energy")
    parser.add_argument("--rock", nargs="+", type=cli_type(choice_problem(TABLE_1, "Table 1 rock")), metavar="NAME",
                        help=f"search again for each Table 1 rock ({', '.join(TABLE_1)}; default: the scene's rock)")
    parser.add_argument("--max-thrust-ratio", type=positive_number, default=1.0,
                        help="run only points whose mean thrust (feed + frequency x impulse per blow) is below this "
                             "fraction of the rock's threshold F_th (default 1: the static limit, beyond which the "
                             "rock yields under the mean load)")
    parser.add_argument("--max-rod-stress-mpa", type=positive_number, metavar="S",
                        help="the best point whose rods stay below this stress [MPa] at their ends (compression or "
                             "tension, every blow of the window: rod_stress_max_pa); points above it are not allowed")
    parser.add_argument("--popsize", type=positive_count, default=AdviceSearch.popsize,
                        help=f"differential evolution: population per parameter (default {AdviceSearch.popsize})")
    parser.add_argument("--generations", type=positive_count, default=AdviceSearch.max_generations,
                        help=f"differential evolution: at most this many generations (default {AdviceSearch.max_generations})")
    parser.add_argument("--seed", type=seed, default=AdviceSearch.seed, help=f"random seed (default {AdviceSearch.seed})")
    parser.add_argument("--markdown", type=Path, help="also write advice.md to this file (e.g. docs/advice.md)")
    add_runner_arguments(parser)
    add_allow_code_argument(parser)


def command_line(args: argparse.Namespace) -> str:
    """The command as it could be typed again (the runner and progress options left out)."""
    words = ["rpdrill", "advise", args.scene]
    for entry in PARAMETERS:
        if _given(args, entry) is not None:
            words += [entry.option, *(f"{v:g}" for v in _given(args, entry))]
    words += ["--power-kw", f"{args.power_kw:g}"] if args.power_kw else []
    words += ["--metric", args.metric] + (["--rock", *args.rock] if args.rock else [])
    words += ["--max-thrust-ratio", f"{args.max_thrust_ratio:g}"]
    words += ["--max-rod-stress-mpa", f"{args.max_rod_stress_mpa:g}"] if args.max_rod_stress_mpa else []
    words += ["--popsize", str(args.popsize), "--generations", str(args.generations), "--seed", str(args.seed)]
    words += ["--out", args.out] + (["--markdown", str(args.markdown)] if args.markdown else [])
    return shlex.join(words)


def run(args: argparse.Namespace) -> int:
    check_out(args.out, args.overwrite, CHECKPOINT)  # (the library checks again: the options' order of messages)
    if args.markdown:
        check_file_target("--markdown", args.markdown)
    bounds = {e.path: e.si_bounds(_given(args, e)) for e in PARAMETERS if _given(args, e) is not None}
    try:
        advices = advise_scene(args.scene, bounds, args.metric, args.rock, args.power_kw, args.max_thrust_ratio,
                               AdviceSearch(popsize=args.popsize, max_generations=args.generations, seed=args.seed),
                               args.markdown, command_line(args),
                               max_rod_stress_pa=args.max_rod_stress_mpa * 1e6 if args.max_rod_stress_mpa else None,
                               options=run_options(args, *ADVISE_OPTIONS), allow_code=args.allow_code)
    except NoAllowedPoint as error:  # no advice: the points run are kept in --out (evaluations.jsonl)
        print(f"advise: {error}; the points run are in {args.out}", file=sys.stderr)
        return 1
    for advice in advices:
        print(advice_text(advice))
    print(best_table(advices))
    print(f"wrote {args.out}" + (f", {args.markdown}" if args.markdown else ""), file=sys.stderr)
    failed = [a for a in advices if a.failed_runs == a.runs]
    for advice in failed:
        why = advice.first_error or f"no point was run ({advice.beyond_limit} beyond the thrust limit)"
        print(f"advise: every run failed for {advice.rock or advice.scene}: {why}", file=sys.stderr)
    return 1 if failed else 0
