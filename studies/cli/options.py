"""The ``rpdrill`` commands, one module each: ``add_arguments(parser)`` and ``run(args) -> exit status``.
A command parses, calls the domain modules of rpdrill.studies and prints; it holds no domain logic."""

from __future__ import annotations

import argparse

from ..inputs.arguments import (
    WORKERS_PER_CORE,
    cli_type,
    count_problem,
    dask_problem,
    module_problem,
    number,
    positive_problem,
    seed_problem,
    whole_number,
    workers_problem,
)
from ..runtime.budgets import DEFAULT_MAX_MEMORY_GB, DEFAULT_MAX_STEPS, MAX_CPU_HOURS, Budget
from ..runtime.run_options import RunOptions

# The options' types: the library's checks of the same arguments (studies.inputs.arguments), same words
positive_number = cli_type(positive_problem, number)  # a positive finite number
positive_count = cli_type(count_problem, whole_number)  # a whole number of at least 1
worker_count = cli_type(workers_problem, whole_number)  # 1 to WORKERS_PER_CORE x the machine's cores
seed = cli_type(seed_problem, whole_number)  # 0 to 2^32 - 1
dask_address = cli_type(dask_problem)  # tcp://host:port or host:port
module_name = cli_type(module_problem)  # a Python module's dotted name

__all__ = ["WORKERS_PER_CORE", "dask_address", "positive_count", "positive_number", "seed", "worker_count"]


def add_allow_code_argument(parser: argparse.ArgumentParser) -> None:
    """``--allow-code MODULE`` (repeated for several): the modules of one's own the command's scenes may run,
    named by import path as an extension's function or a rock law (models.definition.own_code); a scene file
    never allows any itself."""
    parser.add_argument("--allow-code", action="append", default=[], type=module_name, metavar="MODULE",
                        help="run the code of MODULE (and its submodules) that the scene names by import path "
                             "(module:function), as an extension or a rock law; repeat for several. A scene runs no "
                             "code of one's own otherwise, except what installed packages register "
                             "(entry point groups rpdrill.extensions, rpdrill.rock_laws)")


def add_budget_arguments(parser: argparse.ArgumentParser, many_runs: bool = True) -> None:
    """The budgets a command's runs are checked against before they start (studies.runtime.budgets)."""
    parser.add_argument("--max-steps", type=positive_number, default=DEFAULT_MAX_STEPS,
                        help=f"most steps of one run (default {DEFAULT_MAX_STEPS:.3g})")
    parser.add_argument("--max-memory-gb", type=positive_number, default=DEFAULT_MAX_MEMORY_GB,
                        help=f"most memory of one run, in GB (default {DEFAULT_MAX_MEMORY_GB:g})")
    if many_runs:
        parser.add_argument("--yes", action="store_true",
                            help=f"run even when the runs together are estimated above {MAX_CPU_HOURS:g} h of CPU")


def budget(args: argparse.Namespace) -> Budget:
    """The budget the command line gives."""
    return Budget(args.max_steps, args.max_memory_gb, getattr(args, "yes", False))


def run_options(args: argparse.Namespace, *takes: str) -> RunOptions:
    """The run options (rpdrill.RunOptions) the command line gives, those named in ``takes``."""
    given = {"workers": getattr(args, "workers", None), "dask": getattr(args, "dask", None), "out": args.out,
             "overwrite": getattr(args, "overwrite", False), "quiet": getattr(args, "quiet", True)}
    if "budget" in takes:
        given["budget"] = budget(args)
    return RunOptions(**{name: value for name, value in given.items() if name in takes})


def add_resumable_arguments(parser: argparse.ArgumentParser, name: str, help: str, many: bool = False) -> None:
    """A command of many runs that resumes: its input file ``name`` (one or more when ``many``), ``--out``
    (new, empty, or its own from an earlier session), where the runs go and their budgets."""
    parser.add_argument(name, help=help, nargs="+" if many else None)
    parser.add_argument("--out", required=True, help="output directory: new, empty, or this command's own (to resume)")
    add_runner_arguments(parser)
    add_budget_arguments(parser)
    add_allow_code_argument(parser)


def add_runner_arguments(parser: argparse.ArgumentParser, dask: bool = True) -> None:
    """Where a command's many runs go (studies.runtime.pools.select) and whether it shows progress."""
    if dask:
        parser.add_argument("--dask", nargs="?", const="", metavar="ADDRESS", type=dask_address,
                            help="run on a Dask cluster at ADDRESS, or on a LocalCluster when no address is given")
    parser.add_argument("--workers", type=worker_count, help="worker processes (default: all cores; 1: in this process)")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")

