"""The scenes, studies and analyses that ship with rpdrill, by name: ``rpdrill.load_scene("paper_base")``,
``rpdrill.load_study("paper/frequency_scan")``, ``rpdrill study paper/frequency_scan --out DIR``.

A shipped file is a YAML file of the package's ``studies`` folder, installed with it (pyproject.toml's
package data); its name is its path there without ``.yaml``, a scene's its file name alone (``paper_base``
for ``scenes/paper_base.yaml``). Its kind follows from its top-level keys (a scene has a ``drill_string``,
a study a ``scan``, a sensitivity study ``scans``, a work-precision study ``repeats``, a calibration
``parameters``, a hole ``layers``, a reproduction the rest) and its description is its own ``description``. A path that exists
is always the file there: a name is looked up only where no such file is.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from ...models.definition.validation import InputError
from .strict_yaml import parse_yaml

KINDS = ("scene", "study", "calibration", "sensitivity", "accuracy", "hole", "reproduction")
_KEYS = (("drill_string", "scene"), ("scan", "study"), ("scans", "sensitivity"), ("repeats", "accuracy"),
         ("parameters", "calibration"), ("layers", "hole"))  # in this order: a sensitivity study has parameters too


@dataclass(frozen=True)
class ShippedFile:
    """One file that ships with rpdrill (:func:`shipped_files`).

    Parameters
    ----------
    kind : {"scene", "study", "calibration", "sensitivity", "accuracy", "hole", "reproduction"}
        What it holds (:data:`KINDS`).
    name : str
        The name that opens it anywhere (``load_scene("paper_base")``, ``rpdrill study paper/frequency_scan``).
    path : pathlib.Path
        The installed file.
    description : str
        Its own ``description``.

    Examples
    --------
    >>> import rpdrill
    >>> scene = next(f for f in rpdrill.shipped_files() if f.name == "paper_base")
    >>> scene.kind, scene.path.name
    ('scene', 'paper_base.yaml')
    """

    kind: str
    name: str
    path: Path
    description: str


def _root() -> Path:
    """The installed ``studies`` folder (a folder on disk: the package is installed unzipped)."""
    return Path(str(resources.files(__package__.rpartition(".")[0])))


@functools.cache
def shipped_files() -> tuple[ShippedFile, ...]:
    """Every shipped scene, study and analysis, scenes first, each kind by name (module doc; ``rpdrill shipped``).

    Returns
    -------
    tuple of ShippedFile
        The files with their kind, name, path and description.

    Examples
    --------
    >>> import rpdrill
    >>> [f.name for f in rpdrill.shipped_files() if f.kind == "study"][:3]
    ['paper/frequency_scan', 'paper/impulse_scan', 'paper/rock_table']
    """
    root = _root()
    found = []
    for path in sorted(root.glob("*/*.yaml")):
        data = parse_yaml(path.read_text(encoding="utf-8"), str(path))
        kind = next((kind for key, kind in _KEYS if key in data), "reproduction")
        name = path.stem if kind == "scene" else path.relative_to(root).with_suffix("").as_posix()
        found.append(ShippedFile(kind, name, path, " ".join(str(data.get("description", "")).split())))
    return tuple(sorted(found, key=lambda f: (KINDS.index(f.kind), f.name)))


def shipped_path(value: str | Path, kind: str, where: str) -> str | Path:
    """``value`` itself where it is a file that exists (or names no shipped file), else the path of the
    shipped file of ``kind`` it names; InputError naming ``where`` for a shipped name of another kind."""
    text = str(value)
    try:
        exists = Path(text).exists()
    except (OSError, ValueError):  # a name the system cannot take (too long, a NUL byte): read_text says why
        return value
    if exists or text.endswith((".yaml", ".yml")) or not text:
        return value
    named = [f for f in shipped_files() if f.name == text or f.path.relative_to(_root()).with_suffix("").as_posix() == text]
    if not named:
        return value
    of_kind = [f for f in named if f.kind == kind]
    if not of_kind:
        raise InputError(f"{where}: {text}: a shipped {named[0].kind}, not a {kind}; the shipped {kind} files: "
                         f"{', '.join(f.name for f in shipped_files() if f.kind == kind)} (rpdrill shipped)")
    return of_kind[0].path
