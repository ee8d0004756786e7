"""Stopping on Ctrl-C or SIGTERM, the same way.

In the main process both signals raise KeyboardInterrupt (:class:`Terminated` for SIGTERM) and are
remembered: a Python callback inside Exudyn (the rock's return map) swallows the exception and the
run ends as a failed one, so a command asks :func:`raise_if_stopped` before it records a result,
and an interrupted run is never recorded as a failed point or evaluation. Pool workers take
SIGTERM as SIGINT (:func:`worker_stops_like_ctrl_c`), so that a SIGTERM to the whole process group
stops them as Ctrl-C does.
"""

from __future__ import annotations

import contextlib
import signal
from collections.abc import Iterator
from types import FrameType

_received: list[int] = []  # the signals received in this process while handled


class Terminated(KeyboardInterrupt):
    """SIGTERM: stop as for Ctrl-C."""


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


def worker_stops_like_ctrl_c() -> None:
    """In a pool worker: SIGTERM raises KeyboardInterrupt, as SIGINT does."""
    signal.signal(signal.SIGTERM, signal.default_int_handler)
