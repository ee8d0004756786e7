"""What surrounds an Exudyn solve: what Exudyn prints, as one warning a line (the command line shows
each as ``rpdrill: warning: ...``), and Python's cyclic garbage collector paused while it runs."""

from __future__ import annotations

import contextlib
import gc
import io
import re
import warnings
from collections.abc import Iterator


@contextlib.contextmanager
def no_cyclic_gc() -> Iterator[None]:
    """Python's cyclic garbage collector paused: the per-step hooks allocate small objects without
    cycles (freed by reference counting), and the collections they would trigger cost ~5 % of a run."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()


class ExudynMessage(UserWarning):
    """What Exudyn printed during a run (its warnings), issued as a warning instead."""


EXUDYN_PREFIX = re.compile(r"^\s*Python WARNING \[file '[^']*', line \d+\]:\s*")


@contextlib.contextmanager
def exudyn_messages_as_warnings(name: str) -> Iterator[None]:
    """What Exudyn prints while the block runs (it prints through sys.stdout) comes out as one
    :class:`ExudynMessage` warning per distinct line, without Exudyn's file and line prefix."""
    printed = io.StringIO()
    try:
        with contextlib.redirect_stdout(printed):
            yield
    finally:
        lines = [EXUDYN_PREFIX.sub("", line).strip() for line in printed.getvalue().splitlines()]
        for line in dict.fromkeys(line for line in lines if line):
            warnings.warn(f"scene '{name}': Exudyn: {line}", ExudynMessage, stacklevel=3)
