"""The ``rpdrill`` commands, one module each: ``add_arguments(parser)`` and ``run(args) -> exit status``.
A command parses, calls the domain modules of rpdrill.studies and prints; it holds no domain logic."""

from __future__ import annotations

import argparse
import os

from ..runtime.budgets import DEFAULT_MAX_MEMORY_GB, DEFAULT_MAX_STEPS, MAX_CPU_HOURS, Budget


def positive_number(text: str) -> float:
    """An argument that must be a positive finite number."""
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not 0 < value < float("inf"):
        raise argparse.ArgumentTypeError(f"{text}: must be a positive number")
    return value


def positive_count(text: str) -> int:
    """An argument that must be a whole number of at least 1."""
    if not text.isdigit() or int(text) < 1:
        raise argparse.ArgumentTypeError(f"{text}: must be a whole number of at least 1")
    return int(text)


WORKERS_PER_CORE = 4  # more workers only share the cores, each holding its own copy of the model


def worker_count(text: str) -> int:
    """A number of worker processes: 1 to WORKERS_PER_CORE x the machine's cores."""
    most = WORKERS_PER_CORE * (os.cpu_count() or 1)
    count = positive_count(text)
    if count > most:
        raise argparse.ArgumentTypeError(f"{text}: more than {most} ({WORKERS_PER_CORE} per core of this machine)")
    return count


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


def add_resumable_arguments(parser: argparse.ArgumentParser, name: str, help: str, many: bool = False) -> None:
    """A command of many runs that resumes: its input file ``name`` (one or more when ``many``), ``--out``
    (new, empty, or its own from an earlier session), where the runs go and their budgets."""
    parser.add_argument(name, help=help, nargs="+" if many else None)
    parser.add_argument("--out", required=True, help="output directory: new, empty, or this command's own (to resume)")
    add_runner_arguments(parser)
    add_budget_arguments(parser)


def add_runner_arguments(parser: argparse.ArgumentParser, dask: bool = True) -> None:
    """Where a command's many runs go (studies.runtime.pools.select) and whether it shows progress."""
    if dask:
        parser.add_argument("--dask", nargs="?", const="", metavar="ADDRESS",
                            help="run on a Dask cluster at ADDRESS, or on a LocalCluster when no address is given")
    parser.add_argument("--workers", type=worker_count, help="worker processes (default: all cores; 1: in this process)")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")

