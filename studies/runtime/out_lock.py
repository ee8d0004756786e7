"""One run per output folder: a lock file in ``--out`` held while a command runs.

The lock is ``--out/.rpdrill.lock``, a ``filelock.FileLock`` (``flock`` on Unix: released by the
kernel when the process ends, however it ends; the file is removed when it is released) that holds
the pid and command line of its run. A second command on the same folder is refused (InputError,
exit status 2) naming the running one. A lock file left by a run that was killed is taken over,
which is said once. When the folder cannot take the lock (read-only, not writable, a full disk) the
command is refused naming ``--out`` and why, before anything runs (a folder that takes no files, such as one
in /proc, too: filelock reports it as a lock held by another run). So is an ``--out`` that cannot be made. ``--out`` is removed when the
command ends if the command created it and left it empty (bad input leaves ``--out`` as it was).
"""

from __future__ import annotations

import contextlib
import os
import sys
from collections.abc import Iterator
from pathlib import Path

from filelock import FileLock, Timeout

from ..inputs.reading import InputError
from .output_files import check_name, check_out

LOCK = ".rpdrill.lock"


def _holder_text(handle: int) -> str:
    """What a lock file says about its run: 'pid N: command', or '' when empty."""
    os.lseek(handle, 0, os.SEEK_SET)
    return os.read(handle, 4096).decode("utf-8", "replace").strip()


def _holder(path: Path) -> str:
    """What the lock file at ``path`` says about the run that holds it ('' when it cannot be read)."""
    try:
        return path.read_text(encoding="utf-8", errors="replace").strip()
    except OSError:
        return ""


def _unwritable(path: Path) -> OSError | None:
    """Why the lock file ``path`` cannot be opened for writing (its folder takes no files: /proc), or None."""
    try:
        handle = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
    except OSError as error:
        return error
    os.close(handle)
    return None


def _refusal(out: Path, error: OSError) -> InputError:
    return InputError(f"--out: {out}: cannot write there ({error.strerror or error}); give a folder you can write")


@contextlib.contextmanager
def out_locked(out: str | Path | None, command: str) -> Iterator[None]:
    """Hold the lock of the folder ``out`` for ``command`` (its command line) while the block runs
    (module doc); nothing when ``out`` is None or cannot be created (the command's checks say why)."""
    if out is None:
        yield
        return
    check_name("--out", out)
    out = Path(out)
    try:
        created = [p for p in (out, *out.parents) if not p.exists() and not p.is_symlink()]
        out.mkdir(parents=True, exist_ok=True)
    except ValueError:  # (a NUL in the name) the command's check of --out says why
        yield
        return
    except OSError as error:  # the command's check of --out says why where it can (a file on the path), else this
        check_out(out, overwrite=True)
        raise InputError(f"--out: {out}: cannot be made ({error.strerror or error}); give a folder you can "
                         "write") from None
    before: list[str] = []

    def take(handle: int) -> None:
        """The lock is ours: keep what it said of an earlier run, then say ours; _Removed when its last
        holder removed the file after this process opened it (another run may hold the new one)."""
        try:
            same = os.path.samestat(os.fstat(handle), os.stat(out / LOCK))
        except FileNotFoundError:
            same = False
        if not same:
            raise _Removed()
        before.append(_holder_text(handle))
        os.ftruncate(handle, 0)
        os.lseek(handle, 0, os.SEEK_SET)
        os.write(handle, f"pid {os.getpid()}: {command}\n".encode("utf-8", "surrogateescape"))

    lock = FileLock(out / LOCK, timeout=0, fallback_to_soft=False, on_acquired=take)
    try:
        for _ in range(100):  # a file removed under us is opened again (a lock is held for seconds at least)
            with contextlib.suppress(_Removed):
                lock.acquire()
                break
    except Timeout:
        refused = _unwritable(out / LOCK)  # filelock reports a folder that takes no files (/proc) as a lock held
        if refused is not None:
            _remove(created)
            raise _refusal(out, refused) from None
        holder = _holder(out / LOCK) or "a run that is starting"
        raise InputError(f"--out: {out}: another rpdrill run writes there ({holder}); wait until it ends, or give "
                         "another folder") from None
    except OSError as error:
        _remove(created)
        raise _refusal(out, error) from None
    try:
        if before and before[0]:
            print(f"rpdrill: --out {out}: took over the lock of a run that ended without releasing it ({before[0]})",
                  file=sys.stderr)
        yield
    finally:  # removed while held, so that no run takes a file that is about to go
        with contextlib.suppress(OSError):
            (out / LOCK).unlink()
        with contextlib.suppress(OSError):
            lock.release()
        _remove(created)


class _Removed(Exception):
    """The lock file was removed by its last holder between this process's open and its lock."""


def _remove(created: list[Path]) -> None:
    """The folders a command made, when left empty."""
    for folder in created:
        with contextlib.suppress(OSError):
            folder.rmdir()
