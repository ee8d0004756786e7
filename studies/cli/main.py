"""The ``rpdrill`` command line: one subcommand per module, each with ``add_arguments`` and ``run``.

Exit status: 0 success, 1 a run failed, a check did not pass or a budget was exceeded
(studies.runtime.budgets), 2 bad input (also: another command writes into ``--out``, whose lock it
holds: studies.runtime.out_lock), 130 interrupted (Ctrl-C), 143 terminated (SIGTERM: stopped as for
Ctrl-C, finished results kept). An unexpected exception is a bug: one line naming the input and
where it was raised, exit status 1, no traceback. While a command runs, a warning prints as one
line, ``rpdrill: warning: ...`` (warnings of worker processes come back to this process and print
here, once each: studies.runtime.pools).
"""

from __future__ import annotations

import argparse
import contextlib
import importlib.metadata
import os
import shlex
import sys
import traceback
import warnings
from collections.abc import Iterator
from pathlib import Path

from ...rocklaw.exudyn_build import use_fast_build
from ..inputs.reading import InputError
from ..runtime.budgets import BudgetError
from ..runtime.interrupts import Terminated, WorkerLost, raise_if_stopped, stops_handled
from ..runtime.out_lock import out_locked
from . import (
    accuracy_command,
    advise_command,
    calibrate_command,
    crosscheck_command,
    reproduce_command,
    rotation_report_command,
    sensitivity_command,
    simulate_command,
    study_command,
)

# name: (module with add_arguments and run, one-line help)
COMMANDS = {
    "simulate": (simulate_command, "run one scene: time histories, summary, plot"),
    "crosscheck": (crosscheck_command, "run the Exudyn model and the ODE of Eq. 4 and compare them"),
    "study": (study_command, "run a YAML study (scan) on all cores or a Dask cluster"),
    "accuracy": (accuracy_command, "work-precision study: error against CPU time of solver settings"),
    "calibrate": (calibrate_command, "fit scene parameters to target optimum frequencies"),
    "reproduce": (reproduce_command,
                  "the paper's headline cases and figures on the shipped scene, and the generated docs"),
    "sensitivity": (sensitivity_command,
                    "how the frequency optima move with each scene parameter (+-10 %%, SALib global indices)"),
    "rotation-report": (rotation_report_command,
                        "the rotation-speed note (rpm x frequency map, best speed against the manual's rule)"),
    "advise": (advise_command, "the operating point that maximises a metric within bounds"),
}


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


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    parser = _Parser(prog="rpdrill", description="Rotary-percussive drilling simulator on Exudyn")
    parser.add_argument("--version", action="version", version=_version())
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    for name, (module, help_text) in COMMANDS.items():
        module.add_arguments(sub.add_parser(name, help=help_text, description=help_text))
    args = parser.parse_args(argv)
    module = COMMANDS[args.command][0]
    try:
        command = shlex.join(["rpdrill", *argv])
        with one_line_warnings(), stops_handled(), out_locked(getattr(args, "out", None), command):
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
        why = "a worker process ended (killed or crashed)" if isinstance(stop, WorkerLost) else \
            "terminated (SIGTERM)" if terminated else "interrupted"
        print(f"rpdrill: {why}; finished results are kept", file=sys.stderr)
        return 143 if terminated else 130
    except Exception as err:  # noqa: BLE001 - a bug, not bad input: one line naming the input, no traceback
        where = traceback.extract_tb(err.__traceback__)[-1]
        source = next((getattr(args, key) for key in ("scene", "study", "calibration") if hasattr(args, key)), "")
        print(f"{source}: rpdrill internal error: {type(err).__name__}: {err} (at {Path(where.filename).name}:"
              f"{where.lineno}); please report it with this input", file=sys.stderr)
        return 1


def console() -> None:
    """The ``rpdrill`` program: :func:`main`, then exit with its status. Tests call :func:`main`. The
    program and its workers load Exudyn's build without range checks (rocklaw.exudyn_build: a process
    rpdrill owns; a user's process that imports rpdrill does not). A stopped command (130, 143) has
    written what it keeps and ended its workers: it exits at once, without the interpreter's teardown
    of its modules (a second or more on a busy machine)."""
    use_fast_build()  # before anything imports Exudyn; the workers inherit it (rocklaw.exudyn_build)
    status = main()
    if status in (130, 143):
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(status)
    sys.exit(status)


if __name__ == "__main__":
    console()
