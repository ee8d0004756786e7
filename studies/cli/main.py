"""The ``rpdrill`` command line: one subcommand per module, each with ``add_arguments`` and ``run``.

Exit status: 0 success, 1 a run failed, a check did not pass or a budget was exceeded
(studies.runtime.budgets), 2 bad input (also: another command writes into ``--out``, whose lock it
holds: studies.runtime.out_lock), 130 interrupted (Ctrl-C), 143 terminated (SIGTERM: stopped as for
Ctrl-C, finished results kept). An unexpected exception is a bug: one line naming the input and
where it was raised, exit status 1, no traceback; one that code of one's own a scene named raised is a run
that failed: one line naming that code and the user's line (models.definition.own_code.blame_resolved).
While a command runs, a warning prints as one
line, ``rpdrill: warning: ...`` (warnings of worker processes come back to this process and print
here, once each: studies.runtime.pools).

Errors of the operating system: ``--out`` that cannot be written (read-only, no permission, a full
disk when the lock is written) is refused with exit status 2 before anything runs
(studies.runtime.out_lock, studies.runtime.output_files.check_out); a write that fails later (a disk
that fills up) ends the command with one line naming the file and the error, exit status 1, every
file written whole or not at all (studies.runtime.output_files), so that the same command resumes
once the cause is gone. A closed standard output (``| head -n 0``) is not an error: what the command
prints there is dropped and it ends with its own status. A Ctrl-C or SIGTERM at any moment, from the
program's first import on, prints one line (:func:`console`).
"""

from __future__ import annotations

import argparse
import contextlib
import errno
import io
import os
import shlex
import signal
import sys
import traceback
import warnings
from collections.abc import Iterator
from pathlib import Path
from types import FrameType, ModuleType
from typing import Any

# Only the standard library at import: the program takes its signal handlers (console) before the
# libraries load (a second or two); main imports the rest.

# name: one-line help; a command's module is imported only when it runs (:func:`command_module`)
COMMANDS = {
    "simulate": "run one scene: time histories, summary, plot",
    "crosscheck": "run the Exudyn model and the ODE of Eq. 4 and compare them",
    "study": "run a YAML study (scan) on all cores or a Dask cluster",
    "accuracy": "work-precision study: error against CPU time of solver settings",
    "calibrate": "fit scene parameters to target optimum frequencies",
    "reproduce": "the paper's headline cases and figures on the shipped scene, and the generated docs",
    "sensitivity": "how the frequency optima move with each scene parameter (+-10 %%, SALib global indices)",
    "rotation-report": "the rotation-speed note (rpm x frequency map, best speed against the manual's rule)",
    "advise": "the operating point that maximises a metric within bounds",
    "hole": "drill a hole over its depth, rod by rod and layer by layer (rate, time, stresses against depth)",
    "shipped": "list the scenes, studies and analyses that ship with rpdrill, by the names that open them",
}


def command_module(name: str) -> ModuleType:
    """The module of command ``name`` (``add_arguments``, ``run``), imported now: each command loads only
    the libraries it needs (the figures' matplotlib, SALib, SciPy's optimizers)."""
    if name == "simulate":
        from . import simulate_command as module
    elif name == "crosscheck":
        from . import crosscheck_command as module
    elif name == "study":
        from . import study_command as module
    elif name == "accuracy":
        from . import accuracy_command as module
    elif name == "calibrate":
        from . import calibrate_command as module
    elif name == "reproduce":
        from . import reproduce_command as module
    elif name == "sensitivity":
        from . import sensitivity_command as module
    elif name == "rotation-report":
        from . import rotation_report_command as module
    elif name == "advise":
        from . import advise_command as module
    elif name == "hole":
        from . import hole_command as module
    elif name == "shipped":
        from . import shipped_command as module
    else:
        raise KeyError(name)
    return module


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
    import importlib.metadata

    return f"rpdrill {importlib.metadata.version('rpdrill')} (Exudyn {importlib.metadata.version('exudyn')})"


def main(argv: list[str] | None = None) -> int:
    from ...models.definition.own_code import blame_resolved
    from ..inputs.reading import InputError
    from ..runtime.budgets import BudgetError
    from ..runtime.interrupts import Terminated, WorkerLost, raise_if_stopped, stops_handled
    from ..runtime.out_lock import out_locked

    argv = sys.argv[1:] if argv is None else list(argv)
    parser = _Parser(prog="rpdrill", description="Rotary-percussive drilling simulator on Exudyn")
    parser.add_argument("--version", action="version", version=_version())
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    chosen = argv[0] if argv and argv[0] in COMMANDS else None
    for name, help_text in COMMANDS.items():
        command_parser = sub.add_parser(name, help=help_text, description=help_text)
        if name == chosen:
            command_module(name).add_arguments(command_parser)
    args = parser.parse_args(argv)
    module = command_module(args.command)
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
    except OSError as err:  # the operating system's: a disk that filled up, a folder made read-only meanwhile
        where = f" ({err.filename})" if err.filename else f" (--out {args.out})" if getattr(args, "out", None) else ""
        print(f"rpdrill {args.command}: could not finish: {err.strerror or err}{where}; the files written are whole "
              "and finished results are kept: run the same command again once the cause is gone", file=sys.stderr)
        return 1
    except Exception as err:  # noqa: BLE001 - a bug, not bad input: one line naming the input, no traceback
        where = traceback.extract_tb(err.__traceback__)[-1]
        source = next((getattr(args, key) for key in ("scene", "study", "hole", "calibration", "sensitivity", "reproduction", "runs")
                       if hasattr(args, key)), "")
        own = blame_resolved(err)  # the code of one's own a scene named raised it: a run that failed, not a bug
        if own is not None:
            print(f"{source}: {own}", file=sys.stderr)
            return 1
        print(f"{source}: rpdrill internal error: {type(err).__name__}: {err} (at {Path(where.filename).name}:"
              f"{where.lineno}); please report it with this input", file=sys.stderr)
        return 1


def _stopped_while_starting(signum: int, frame: FrameType | None) -> None:
    """Ctrl-C or SIGTERM before a command runs (its libraries loading, its arguments read): nothing
    was written; one line, and out."""
    why = "terminated (SIGTERM)" if signum == signal.SIGTERM else "interrupted"
    os.write(2, f"rpdrill: {why} while starting; nothing was written\n".encode())
    os._exit(143 if signum == signal.SIGTERM else 130)


class ClosedPipeQuiet:
    """A standard stream whose reader went away (``| head -n 0``): what is printed after is dropped (the
    stream's descriptor then points to /dev/null), not raised, so that the command ends with its own
    status once its files are written."""

    def __init__(self, stream: Any) -> None:
        self.stream = stream

    def _closed_pipe(self) -> None:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, self.stream.fileno())
        os.close(devnull)

    def write(self, text: str) -> int:
        try:
            return self.stream.write(text)
        except BrokenPipeError:
            self._closed_pipe()
            return len(text)
        except OSError as error:
            if error.errno != errno.EPIPE:
                raise
            self._closed_pipe()
            return len(text)

    def flush(self) -> None:
        try:
            self.stream.flush()
        except BrokenPipeError:
            self._closed_pipe()
            with contextlib.suppress(OSError, ValueError):
                self.stream.flush()

    def __getattr__(self, name: str) -> Any:  # encoding, fileno, isatty, ... of the stream
        return getattr(self.stream, name)

    def fileno(self) -> int:
        return self.stream.fileno()

    def isatty(self) -> bool:
        return self.stream.isatty()


EXUDYN_MODULE = "EXUDYN_MODULE"  # Exudyn's own switch of its build, read at its first import: "fast" or "regular"


def choose_exudyn_build() -> None:
    """The program's choice of Exudyn's build (rocklaw.exudyn_module), made here and nowhere in the library:
    the build without range checks where the CPU has AVX2, for this process and the workers it starts
    (they inherit ``EXUDYN_MODULE=fast``; a process pool's workers are forked with Exudyn loaded). Exudyn
    is loaded now, the line its fast build prints when loaded kept off the program's standard output
    (which holds the command's own tables). A choice made before, ``EXUDYN_MODULE`` set (``regular``),
    ``sys.exudynFast`` set or Exudyn imported, stays."""
    if EXUDYN_MODULE in os.environ or hasattr(sys, "exudynFast") or "exudyn" in sys.modules:
        return
    os.environ[EXUDYN_MODULE] = "fast"
    sys.exudynFast = True
    with contextlib.redirect_stdout(io.StringIO()):
        import exudyn  # noqa: F401 - loaded now: 0.03 CPU s


def console() -> None:
    """The ``rpdrill`` program: :func:`main`, then exit with its status. Tests call :func:`main`. A
    Ctrl-C or SIGTERM while the program starts prints one line (the command's own handling takes over
    when it runs: studies.runtime.interrupts). The program and its workers load Exudyn's build without
    range checks (:func:`choose_exudyn_build`; a user's process that imports rpdrill does not). A closed
    standard output or error is no error (:class:`ClosedPipeQuiet`). A stopped command (130, 143) exits as
    any other, the interpreter's teardown included: a study stopped by Ctrl-C exits 1.39 s after the signal
    (median of 3 on the shared 2-core machine; 1.15 s when the teardown was skipped with ``os._exit``, a
    trick not worth its keep below the 2 s the interrupt tests allow)."""
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, _stopped_while_starting)
    sys.stdout, sys.stderr = ClosedPipeQuiet(sys.stdout), ClosedPipeQuiet(sys.stderr)
    choose_exudyn_build()  # before anything else imports Exudyn; the workers inherit it
    status = main()
    for signum in (signal.SIGINT, signal.SIGTERM):  # the command has ended: its status stands
        signal.signal(signum, signal.SIG_IGN)
    _forget_interrupts_caught_in_string_code()
    sys.stdout.flush()
    sys.stderr.flush()
    sys.exit(status)


def _forget_interrupts_caught_in_string_code() -> None:
    """CPython (3.8 on, bpo-1054041) ends a program run as ``python -m rpdrill.studies.cli`` by SIGINT (status -2
    to its caller, not the command's 130 or 0) when a KeyboardInterrupt once left code run from a string
    (``exec``/``eval`` of text: a ``collections.namedtuple`` or a dataclass being made while a library
    loads), even one caught since, as the command catches every Ctrl-C. Its record is set again by every
    run of string code, so running one forgets it: tests/test_interrupts.py::
    test_a_ctrl_c_caught_inside_string_code_exits_with_the_commands_status (a Ctrl-C about 1 s into a run landed
    there twice in 125 stops on a loaded machine, once in a namedtuple numba makes as it loads)."""
    exec("pass")  # noqa: S102 - a constant: the run of string code is the point


if __name__ == "__main__":
    console()
