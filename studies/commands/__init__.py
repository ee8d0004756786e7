"""The ``rpdrill`` commands, one module each: ``add_arguments(parser)`` and ``run(args) -> exit status``.
A command parses, calls the domain modules of rpdrill.studies and prints; it holds no domain logic."""

from __future__ import annotations

import argparse


def add_runner_arguments(parser: argparse.ArgumentParser, dask: bool = True) -> None:
    """Where a command's many runs go (studies.runners.select) and whether it shows progress."""
    if dask:
        parser.add_argument("--dask", nargs="?", const="", metavar="ADDRESS",
                            help="run on a Dask cluster at ADDRESS, or on a LocalCluster when no address is given")
    parser.add_argument("--workers", type=int, help="worker processes (default: all cores; 1: in this process)")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")


def positive_number(text: str) -> float:
    """An argparse type: a number > 0."""
    value = float(text)
    if not value > 0:
        raise argparse.ArgumentTypeError(f"{text}: must be a positive number")
    return value
