"""The ``rpdrill`` command line: one subcommand per module, each with ``add_arguments`` and ``run``.

Exit status: 0 success, 1 a run failed, a check did not pass or a budget was exceeded
(studies.budgets), 2 bad input, 130 interrupted (Ctrl-C), 143 terminated (SIGTERM: stopped as for
Ctrl-C, finished results kept). An unexpected exception is a bug: one line naming the input and
where it was raised, exit status 1, no traceback. While a command runs, a warning prints as one
line, ``rpdrill: warning: ...`` (warnings of worker processes come back to this process and print
here, once each: studies.runners).
"""

from __future__ import annotations

import argparse
import contextlib
import gc
import importlib
import importlib.metadata
import itertools
import sys
import traceback
import warnings
from collections.abc import Iterator
from pathlib import Path

from ..rocklaw.exudyn_build import use_fast_build
from .interrupts import Terminated, raise_if_stopped, stops_handled
from .runners import start_worker_server

# name: (module, one-line help); a module is imported only when its command runs
COMMANDS = {
    "simulate": ("rpdrill.studies.commands.simulate", "run one scene: time histories, summary, plot"),
    "crosscheck": ("rpdrill.studies.commands.crosscheck", "run the Exudyn model and the ODE of Eq. 4 and compare them"),
    "study": ("rpdrill.studies.commands.study", "run a YAML study (scan) on all cores or a Dask cluster"),
    "accuracy": ("rpdrill.studies.commands.accuracy", "work-precision study: error against CPU time of solver settings"),
    "calibrate": ("rpdrill.studies.commands.calibrate", "fit scene parameters to target optimum frequencies"),
    "reproduce": ("rpdrill.studies.commands.reproduce",
                  "the paper's headline cases and figures on the shipped scene, and the generated docs"),
    "sensitivity": ("rpdrill.studies.commands.sensitivity",
                    "how the frequency optima move with each scene parameter (+-10 %%, SALib global indices)"),
    "rotation-report": ("rpdrill.studies.commands.rotation_report",
                        "the rotation-speed note (rpm x frequency map, best speed against the manual's rule)"),
    "advise": ("rpdrill.studies.commands.advise", "the operating point that maximises a metric within bounds"),
}
# the commands whose runs go to a process pool by default
POOL_COMMANDS = ("study", "accuracy", "calibrate", "reproduce", "sensitivity", "advise")


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # argparse's own usage errors are bad input too
        self.print_usage(sys.stderr)
        print(f"rpdrill: error: {message}", file=sys.stderr)
        sys.exit(2)


def _one_line_warning(message, category, filename, lineno, line=None) -> str:
    return f"rpdrill: warning: {message}\n"


@contextlib.contextmanager
def one_line_warnings() -> Iterator[None]:
    """Warnings print as one line while the block runs; the formatting before is restored after."""
    saved = warnings.formatwarning
    warnings.formatwarning = _one_line_warning
    try:
        yield
    finally:
        warnings.formatwarning = saved


def _version() -> str:
    return f"rpdrill {importlib.metadata.version('rpdrill')} (Exudyn {importlib.metadata.version('exudyn')})"


def _runs_a_process_pool(argv: list[str]) -> bool:
    """Whether the command line will run a process pool (a hint read before parsing: a wrong guess only
    starts the pool's fork server in vain): a pool command without --dask, --workers 1 or --help."""
    one_worker = "--workers=1" in argv or any(a == "--workers" and b == "1" for a, b in itertools.pairwise(argv))
    dask = any(word == "--dask" or word.startswith("--dask=") for word in argv)
    return bool(argv) and argv[0] in POOL_COMMANDS and not (one_worker or dask or {"-h", "--help"} & set(argv))


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    if _runs_a_process_pool(argv):
        start_worker_server([COMMANDS[argv[0]][0]])  # its imports overlap this process's (studies.runners)
    # imported after the fork server starts: they import the models (0.4 s), which it imports too
    from .budgets import BudgetError
    from .loading import InputError

    parser = _Parser(prog="rpdrill", description="Rotary-percussive drilling simulator on Exudyn")
    parser.add_argument("--version", action="version", version=_version())
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    module = None
    for name, (module_name, help_text) in COMMANDS.items():
        command_parser = sub.add_parser(name, help=help_text, description=help_text)
        if argv[:1] == [name]:
            module = importlib.import_module(module_name)
            module.add_arguments(command_parser)
    args = parser.parse_args(argv)
    try:
        with one_line_warnings(), stops_handled():
            status = int(module.run(args))
            raise_if_stopped()
            return status
    except InputError as err:
        print(str(err), file=sys.stderr)
        return 2
    except BudgetError as err:
        print(str(err), file=sys.stderr)
        return 1
    except KeyboardInterrupt as stop:
        terminated = isinstance(stop, Terminated)
        print(f"rpdrill: {'terminated (SIGTERM)' if terminated else 'interrupted'}; finished results are kept",
              file=sys.stderr)
        return 143 if terminated else 130
    except Exception as err:  # noqa: BLE001 - a bug, not bad input: one line naming the input, no traceback
        where = traceback.extract_tb(err.__traceback__)[-1]
        source = next((getattr(args, key) for key in ("scene", "study", "calibration") if hasattr(args, key)), "")
        print(f"{source}: rpdrill internal error: {type(err).__name__}: {err} (at {Path(where.filename).name}:"
              f"{where.lineno}); please report it with this input", file=sys.stderr)
        return 1


def console() -> None:
    """The ``rpdrill`` program: :func:`main`, then exit with its status. The program and its workers load
    Exudyn's build without range checks (rocklaw.exudyn_module: a process rpdrill owns; a user's process
    that imports rpdrill does not). What the command leaves is frozen first (``gc.freeze``): the
    interpreter's exit then skips its last collection over every object of the loaded libraries (SciPy,
    matplotlib, numba: 0.2 s). Tests call :func:`main`."""
    use_fast_build()  # before anything imports Exudyn; the workers inherit it (rocklaw.exudyn_build)
    status = main()
    gc.freeze()
    sys.exit(status)


if __name__ == "__main__":
    console()
