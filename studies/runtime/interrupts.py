"""Stopping on Ctrl-C or SIGTERM, the same way.

In the main process both signals raise KeyboardInterrupt (:class:`Terminated` for SIGTERM) and are
remembered: a Python callback inside Exudyn (the rock's return map) swallows the exception and the
run ends as a failed one, so a command asks :func:`raise_if_stopped` before it records a result,
and an interrupted run is never recorded as a failed point or evaluation. Pool workers leave the
stopping to the command's process: they ignore Ctrl-C and end at SIGTERM or when that process ends
(:func:`worker_ends_with_its_command`); the command ends them on a stop instead of waiting for the
points they run (studies.runtime.pools), so that it exits within a second or two with every point
finished before the signal kept.
"""

from __future__ import annotations

import contextlib
import ctypes
import ctypes.util
import multiprocessing
import os
import signal
import sys
from collections.abc import Iterator
from types import FrameType

PR_SET_PDEATHSIG = 1  # prctl(2): the signal a process gets when its parent ends
_received: list[int] = []  # the signals received in this process while handled


class Terminated(KeyboardInterrupt):
    """SIGTERM: stop as for Ctrl-C."""


class WorkerLost(Terminated):
    """A pool worker ended in the middle of the run (killed alone, or crashed): stop as for SIGTERM."""


def _stop(signum: int, frame: FrameType | None) -> None:
    _received.append(signum)
    raise Terminated() if signum == signal.SIGTERM else KeyboardInterrupt()


@contextlib.contextmanager
def stops_handled() -> Iterator[None]:
    """Within the block, SIGINT and SIGTERM raise (and are remembered); the handlers before are restored."""
    previous = {signum: signal.signal(signum, _stop) for signum in (signal.SIGINT, signal.SIGTERM)}
    _received.clear()
    try:
        yield
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)


def raise_if_stopped() -> None:
    """Raise the interrupt again if one was received (it may have been swallowed since)."""
    if _received:
        raise Terminated() if signal.SIGTERM in _received else KeyboardInterrupt()


def worker_ends_with_its_command() -> None:
    """In a pool worker: Ctrl-C is ignored (the command's process stops the run and ends its workers),
    SIGTERM ends it at once, and so does the end of the command's process however it ends (Linux:
    PR_SET_PDEATHSIG, asked of the kernel through libc: no Python call sets it), so that no worker
    outlives its run: tests/test_interrupts.py::test_a_killed_command_leaves_no_worker_in_the_middle_of_a_point
    (without it the workers ran on after the kill)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    if sys.platform.startswith("linux"):
        with contextlib.suppress(OSError, AttributeError):
            libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
            libc.prctl(PR_SET_PDEATHSIG, signal.SIGTERM)
        parent = multiprocessing.parent_process()
        if parent is not None and os.getppid() != parent.pid:  # the command ended before the line above
            os._exit(1)
