"""One run per output folder: a lock file in ``--out`` held while a command runs.

The lock is ``--out/.rpdrill.lock``, held with ``fcntl.flock`` (released by the kernel when the
process ends, however it ends) and holding the pid and command line of its run. A second command
on the same folder is refused (InputError, exit status 2) naming the running one. A lock file
left by a run that was killed is taken over, which is said once. The lock file is removed when the
command ends, and so is ``--out`` if the command created it and left it empty (bad input leaves
``--out`` as it was).
"""

from __future__ import annotations

import contextlib
import fcntl
import os
import sys
from collections.abc import Iterator
from pathlib import Path

from ..inputs.reading import InputError

LOCK = ".rpdrill.lock"


def _holder(handle: int) -> str:
    """What a lock file says about its run: 'pid N: command', or '' when empty."""
    os.lseek(handle, 0, os.SEEK_SET)
    return os.read(handle, 4096).decode("utf-8", "replace").strip()


def _acquire(path: Path) -> tuple[int, str]:
    """An open descriptor of the lock file at ``path``, locked, and what it held before (a dead run's
    'pid: command', or ''); InputError naming the run that holds it."""
    while True:
        handle = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = _holder(handle) or "a run that is starting"
            os.close(handle)
            raise InputError(f"--out: {path.parent}: another rpdrill run writes there ({holder}); wait until it "
                             "ends, or give another folder") from None
        try:
            same = os.fstat(handle).st_ino == os.stat(path).st_ino
        except FileNotFoundError:
            same = False
        if same:  # not a file its last holder removed after we opened it
            return handle, _holder(handle)
        os.close(handle)


@contextlib.contextmanager
def out_locked(out: str | Path | None, command: str) -> Iterator[None]:
    """Hold the lock of the folder ``out`` for ``command`` (its command line) while the block runs
    (module doc); nothing when ``out`` is None or cannot be created (the command's checks say why)."""
    if out is None:
        yield
        return
    out = Path(out)
    try:
        created = [p for p in (out, *out.parents) if not p.exists() and not p.is_symlink()]
        out.mkdir(parents=True, exist_ok=True)
    except OSError:
        yield
        return
    handle, before = _acquire(out / LOCK)
    try:
        if before:
            print(f"rpdrill: --out {out}: took over the lock of a run that ended without releasing it ({before})",
                  file=sys.stderr)
        os.ftruncate(handle, 0)
        os.write(handle, f"pid {os.getpid()}: {command}\n".encode())
        yield
    finally:
        with contextlib.suppress(OSError):
            (out / LOCK).unlink()
        os.close(handle)
        for folder in created:  # the folders it made, when left empty
            with contextlib.suppress(OSError):
                folder.rmdir()
