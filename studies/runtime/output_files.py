"""Writing run outputs: the output folder checked before any work, CSV with unit-carrying headers,
JSON, the resolved scene; all or nothing."""

from __future__ import annotations

import contextlib
import csv
import json
import os
import shutil
import tempfile
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from ..inputs.reading import InputError


def check_out(out: str | Path, overwrite: bool | None = False, record: str | None = None,
              option: str = "--out") -> Path:
    """``--out`` as a folder that can take a run's files, checked before any work; InputError if it
    is a file, lies below a file, cannot be written, or is a folder that holds another run's files
    (anything but names starting with '.') unless ``overwrite`` (None: the command has no
    ``--overwrite``), or unless it holds ``record`` (a resumable command's own record, which the
    command checks itself)."""
    out = Path(out)
    try:
        dangling = next((p for p in (out, *out.parents) if p.is_symlink() and not p.exists()), None)
        if dangling is not None:
            raise InputError(f"{option}: {out}: {'' if dangling == out else f'{dangling}, on its path, is '}a symbolic "
                             f"link to {os.readlink(dangling)}, which does not exist; give a folder")
        existing = next(p for p in (out, *out.parents) if p.exists())
        if not existing.is_dir():
            where = "is a file" if existing == out else f"lies below the file {existing}"
            raise InputError(f"{option}: {out}: {where}; give a folder")
        if not os.access(existing, os.W_OK | os.X_OK):
            raise InputError(f"{option}: {out}: cannot write in {existing}; give a folder you can write")
        held = sorted(p.name for p in out.iterdir() if not p.name.startswith(".")) if existing == out else []
    except OSError as error:
        raise InputError(f"{option}: {out}: cannot be used: {error.strerror or error}; give a folder you can write") \
            from None
    if held and not overwrite and (record is None or record not in held):
        shown = ", ".join(held[:6]) + (f" and {len(held) - 6} more" if len(held) > 6 else "")
        hint = "give a new folder" + ("" if overwrite is None else ", or --overwrite to write over them")
        why = f"but no {record} (another run's files, or an earlier run's whose {record} was deleted)" if record \
            else "(another run's files)"
        raise InputError(f"{option}: {out}: holds {shown} {why}; {hint}")
    return out


def check_file_target(option: str, path: str | Path) -> Path:
    """A file a command will write (``option`` names it), checked before any work: InputError unless its
    folder exists and can be written, and it is not a folder itself."""
    path = Path(path)
    try:
        if path.is_dir():
            raise InputError(f"{option}: {path}: is a folder; give a file name")
        folder = path.parent
        if not folder.is_dir():
            raise InputError(f"{option}: {path}: no folder {folder}; create it or give a file in an existing folder")
        if not os.access(folder, os.W_OK | os.X_OK) or (path.exists() and not os.access(path, os.W_OK)):
            raise InputError(f"{option}: {path}: cannot be written; give a file you can write")
    except OSError as error:
        raise InputError(f"{option}: {path}: cannot be used: {error.strerror or error}") from None
    return path


@contextlib.contextmanager
def staged_directory(out_dir: str | Path) -> Iterator[Path]:
    """Yield a scratch directory; its files and folders move into ``out_dir`` only if the block succeeds
    (replacing those of the same name there)."""
    out_dir = Path(out_dir)
    out_dir.parent.mkdir(parents=True, exist_ok=True)
    stage = Path(tempfile.mkdtemp(prefix=f".{out_dir.name}-", dir=out_dir.parent))
    try:
        yield stage
        out_dir.mkdir(exist_ok=True)
        for item in stage.iterdir():
            if (out_dir / item.name).is_dir():
                shutil.rmtree(out_dir / item.name)
            os.replace(item, out_dir / item.name)
    finally:
        shutil.rmtree(stage, ignore_errors=True)


def write_columns_csv(path: Path, columns: dict[str, np.ndarray]) -> None:
    """Columns of equal length as CSV; the header is the column names (units in the names)."""
    table = np.column_stack(list(columns.values()))
    np.savetxt(path, table, delimiter=",", header=",".join(columns), comments="", fmt="%.12g")


def _plain(value: Any) -> Any:
    """NumPy arrays and scalars (a formulation's run info) as JSON lists and numbers."""
    if isinstance(value, (np.ndarray, np.generic)):
        return value.tolist()
    raise TypeError(f"{type(value).__name__} is not JSON serializable")


def write_json(path: Path, data: Any) -> None:
    path.write_text(json.dumps(data, indent=2, sort_keys=False, default=_plain) + "\n", encoding="utf-8")


def write_resolved(path: Path, data: dict[str, Any]) -> None:
    """A resolved scene (every value filled in) as YAML."""
    path.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")


def write_rows_csv(path: Path, rows: list[dict[str, Any]], columns: Sequence[str] = ()) -> None:
    """Rows as CSV under ``columns`` (default: the keys of the first row; none without rows)."""
    with path.open("w", newline="", encoding="utf-8") as handle:
        writer = csv.DictWriter(handle, list(columns) or (list(rows[0]) if rows else []))
        writer.writeheader()
        writer.writerows(rows)
