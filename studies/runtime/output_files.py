"""Writing run outputs: the output folder checked before any work, CSV with unit-carrying headers,
JSON, the resolved scene; all or nothing.

Every file is written whole or not at all: into a temporary file beside it, then renamed over it
(:func:`write_atomic`), so that a full disk or a kill leaves the file as it was (or absent), never
half written. JSON is valid JSON: a number that is not finite (NaN, infinite) is written as null.
YAML is written so that YAML 1.1 and 1.2 read it alike (text that either would read as a number or
a boolean is quoted), as the strict reader (studies.inputs.strict_yaml) reads it back."""

from __future__ import annotations

import contextlib
import csv
import dataclasses
import json
import math
import os
import re
import shutil
import tempfile
from collections.abc import Iterator, Mapping, Sequence
from enum import Enum
from pathlib import Path, PurePath
from typing import IO, Any

import numpy as np
import yaml
from pydantic import BaseModel

from ..inputs.reading import InputError

_UMASK = os.umask(0o022)  # the process's umask, read once (setting it is the only way to read it)
os.umask(_UMASK)
NEW_FILE_MODE = 0o666 & ~_UMASK
YAML_12_FLOAT = re.compile(r"^[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?$")


def check_name(option: str, path: str | Path) -> None:
    """InputError unless ``path`` is UTF-8 text (a name of other bytes, 0xff, cannot go into the files a
    command writes: its command line, its messages)."""
    try:
        os.fsencode(path).decode("utf-8")
    except UnicodeDecodeError as error:
        shown = os.fsencode(path).decode("utf-8", "backslashreplace")
        raise InputError(f"{option}: {shown}: the name holds the byte 0x{error.object[error.start]:02x}, not UTF-8 "
                         "text; give a name of UTF-8 text") from None


def check_out(out: str | Path, overwrite: bool | None = False, record: str | None = None,
              option: str = "--out") -> Path:
    """``--out`` as a folder that can take a run's files, checked before any work; InputError if it
    is a file, lies below a file, cannot be written, or is a folder that holds another run's files
    (anything but names starting with '.') unless ``overwrite`` (None: the command has no
    ``--overwrite``), or unless it holds ``record`` (a resumable command's own record, which the
    command checks itself); a name that is not UTF-8 text is refused (:func:`check_name`)."""
    check_name(option, out)
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
    folder exists and can be written, and it is not a folder itself (its name UTF-8 text: :func:`check_name`)."""
    check_name(option, path)
    path = Path(path)
    try:
        if path.is_dir():
            raise InputError(f"{option}: {path}: is a folder; give a file name")
        if path.exists() and not path.is_file():  # (a file is replaced by a renamed one: never a device)
            raise InputError(f"{option}: {path}: not a regular file (a device, pipe or socket); give a file name")
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


@contextlib.contextmanager
def atomic_file(path: str | Path, mode: str = "w") -> Iterator[IO[Any]]:
    """A file open for writing in place of ``path``: a temporary file in its folder, renamed over
    ``path`` when the block ends without an error, removed otherwise (module doc)."""
    path = Path(path)
    handle, temporary = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        os.chmod(handle, NEW_FILE_MODE)  # (mkstemp makes it 0600) as open() would make the file
        with open(handle, mode, **({} if "b" in mode else {"encoding": "utf-8", "newline": ""})) as file:
            yield file
        os.replace(temporary, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(temporary)
        raise


def write_atomic(path: str | Path, content: str | bytes) -> None:
    """Write ``content`` to ``path`` whole or not at all (:func:`atomic_file`)."""
    with atomic_file(path, "wb" if isinstance(content, bytes) else "w") as file:
        file.write(content)


def write_columns_csv(path: Path, columns: dict[str, np.ndarray]) -> None:
    """Columns of equal length as CSV; the header is the column names (units in the names)."""
    table = np.column_stack(list(columns.values()))
    with atomic_file(path) as file:
        np.savetxt(file, table, delimiter=",", header=",".join(columns), comments="", fmt="%.12g")


def json_ready(value: Any) -> Any:
    """``value`` as JSON holds it: NumPy arrays and scalars as lists and numbers, tuples as lists, a
    number that is not finite as None (null), a complex number as [re, im], an enum as its value, a path
    as text, a dataclass as the mapping of its fields (and of its properties named in ``json_properties``)."""
    if isinstance(value, (np.ndarray, np.generic)):
        value = value.tolist()
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, complex):
        return [json_ready(value.real), json_ready(value.imag)]
    if isinstance(value, Enum):
        return json_ready(value.value)
    if isinstance(value, PurePath):
        return str(value)
    if isinstance(value, BaseModel):
        return json_ready(value.model_dump())
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        fields = {f.name: getattr(value, f.name) for f in dataclasses.fields(value)}
        return json_ready({**fields, **{name: getattr(value, name) for name in getattr(value, "json_properties", ())}})
    if isinstance(value, Mapping):
        return {key: json_ready(item) for key, item in value.items()}
    if isinstance(value, (list, tuple)):
        return [json_ready(item) for item in value]
    return value


def json_text(data: Any, indent: int | None = None) -> str:
    """``data`` as valid JSON text (:func:`json_ready`; NaN is never written)."""
    return json.dumps(json_ready(data), indent=indent, sort_keys=False, allow_nan=False)


def write_json(path: Path, data: Any) -> None:
    write_atomic(path, json_text(data, indent=2) + "\n")


class _SameInBothVersions(yaml.SafeDumper):
    """PyYAML's safe dumper (YAML 1.1: it quotes text 1.1 reads otherwise) that also quotes text YAML 1.2
    reads as a number ('1e5')."""


_SameInBothVersions.add_implicit_resolver("tag:yaml.org,2002:float", YAML_12_FLOAT, list("-+.0123456789"))


def write_resolved(path: Path, data: dict[str, Any]) -> None:
    """A resolved scene (every value filled in) as YAML."""
    write_atomic(path, yaml.dump(data, Dumper=_SameInBothVersions, sort_keys=False))


def write_rows_csv(path: Path, rows: list[dict[str, Any]], columns: Sequence[str] = ()) -> None:
    """Rows as CSV under ``columns`` (default: the keys of the first row; none without rows)."""
    with atomic_file(path) as handle:
        writer = csv.DictWriter(handle, list(columns) or (list(rows[0]) if rows else []))
        writer.writeheader()
        writer.writerows(rows)
