"""Reading input files strictly and turning every problem into one clear message.

An :class:`InputError` message names the file, the key path, the value and what is allowed;
the command line prints it and exits with status 2.

The reader accepts a regular file of UTF-8 text (at most MAX_FILE_BYTES; a byte-order mark is
dropped) holding one YAML 1.2 document whose top level is a mapping, read by
studies.inputs.strict_yaml (ruamel.yaml, with the checks where YAML 1.1 reads otherwise or lets
mistakes pass). A file of UTF-16 or UTF-32 text (with or without a byte-order mark, told apart as
YAML 1.2's section 5.2 does) is refused as such.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ...models.definition.own_code import allowed_modules, context
from ...models.definition.scene import Scene
from ...models.definition.validation import InputError, parse, short
from ...models.solvers.simulation import SceneError, Simulation, prepare, unsupported
from .arguments import allow_code_problem, check, scene_file_problem
from .shipped import shipped_path
from .strict_yaml import MAX_DEPTH, MAX_VALUES, parse_yaml

__all__ = ["MAX_DEPTH", "MAX_FILE_BYTES", "MAX_VALUES", "InputError", "load_scene", "parse", "parse_yaml",
           "prepare_scene", "read_text", "read_yaml", "scene_and_source"]

MAX_FILE_BYTES = 2**20  # 1 MiB: the largest shipped input is 9 kB; reading 1 MiB of YAML takes seconds
# The byte-order marks and the patterns of zero bytes of the first two or four bytes (an ASCII first
# character: YAML 1.2, section 5.2) of the encodings YAML allows besides UTF-8
WIDE_ENCODINGS = ((b"\x00\x00\xfe\xff", "UTF-32 text (big-endian, with a byte-order mark)"),
                  (b"\xff\xfe\x00\x00", "UTF-32 text (little-endian, with a byte-order mark)"),
                  (b"\xfe\xff", "UTF-16 text (big-endian, with a byte-order mark)"),
                  (b"\xff\xfe", "UTF-16 text (little-endian, with a byte-order mark)"))


def _wide_encoding(data: bytes) -> str | None:
    """The UTF-16 or UTF-32 encoding of ``data`` (module doc), None when it is neither."""
    named = next((name for mark, name in WIDE_ENCODINGS if data.startswith(mark)), None)
    if named or len(data) < 2:
        return named
    if len(data) >= 4 and data[:3] == b"\0\0\0" and data[3]:
        return "UTF-32 text (big-endian, without a byte-order mark)"
    if len(data) >= 4 and data[0] and data[1:4] == b"\0\0\0":
        return "UTF-32 text (little-endian, without a byte-order mark)"
    if data[0] == 0 and data[1]:
        return "UTF-16 text (big-endian, without a byte-order mark)"
    if data[0] and data[1] == 0:
        return "UTF-16 text (little-endian, without a byte-order mark)"
    return None


def _size(count: int) -> str:
    return f"{count} bytes ({count / 2**20:.3g} MiB)" if count >= 2**20 else f"{count} bytes"


def read_text(path: str | Path) -> str:
    """The UTF-8 text of a regular file, or InputError naming the file and what is wrong with it."""
    path = Path(path)
    try:
        if not path.exists():
            shipped = "" if path.suffix else "; nor a shipped file's name (rpdrill shipped lists them)"
            raise InputError(f"{path}: no such file{shipped}")
        if path.is_dir():
            raise InputError(f"{path}: is a directory; give a YAML file")
        if not path.is_file():
            raise InputError(f"{path}: not a regular file (a device, pipe or socket); give a YAML file")
        size = path.stat().st_size
        if size > MAX_FILE_BYTES:
            raise InputError(f"{path}: {_size(size)}; an input file is at most {_size(MAX_FILE_BYTES)} of YAML "
                             "text (a scene is about 2 kB)")
        data = path.read_bytes()
    except InputError:
        raise
    except OSError as err:
        raise InputError(f"{path}: cannot read file: {err.strerror or err}") from None
    except ValueError as err:  # a name the system cannot take (a NUL byte in it)
        raise InputError(f"{path!r}: cannot read file: {err}") from None
    wide = _wide_encoding(data)
    if wide:
        raise InputError(f"{path}: {wide}; rpdrill reads UTF-8 text: save the file as UTF-8")
    nul = data.find(0)
    if nul >= 0:
        raise InputError(f"{path}: a binary file (a NUL byte at offset {nul}), not UTF-8 YAML text")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as err:
        line = data[:err.start].count(b"\n") + 1
        raise InputError(f"{path}: line {line}: byte 0x{data[err.start]:02x} is not UTF-8 text; "
                         "save the file as UTF-8") from None


def read_yaml(path: str | Path) -> dict[str, Any]:
    """The mapping in a YAML file (:func:`read_text`, :func:`parse_yaml`), or InputError naming the
    file and the problem."""
    return parse_yaml(read_text(path), str(path))


def load_scene(path: str | Path, allow_code: Sequence[str] | str = ()) -> Scene:
    """Read and validate a scene file, or a shipped scene by its name.

    Parameters
    ----------
    path : str or pathlib.Path
        A scene file (YAML; its keys: the scene reference, docs/scenes.md), or the name of a shipped scene
        (``"paper_base"``; :func:`shipped_files`, ``rpdrill shipped``). A file that exists wins over a name.
    allow_code : sequence of str or str, default ()
        The modules of one's own the scene may run (an extension's function, a rock law named by import path:
        models.definition.own_code); never read from the file.

    Returns
    -------
    Scene
        The validated scene, every key typed.

    Raises
    ------
    InputError
        Naming the file, the key path, the value and what is allowed: a missing file, YAML that YAML 1.2
        reads otherwise than YAML 1.1, an unknown key, a value out of range, code of one's own not allowed.

    Examples
    --------
    >>> import rpdrill
    >>> scene = rpdrill.load_scene("paper_base")
    >>> scene.impact.frequency_hz, scene.drill_string.bodies["collar"].mass_kg
    (65.0, 1830.0)
    >>> try:
    ...     rpdrill.load_scene("paper_bas")
    ... except rpdrill.InputError as error:
    ...     print(error)
    paper_bas: no such file; nor a shipped file's name (rpdrill shipped lists them)
    """
    check("rpdrill.load_scene", "path", path, scene_file_problem)
    check("rpdrill.load_scene", "allow_code", allow_code, allow_code_problem)
    path = shipped_path(path, "scene", "rpdrill.load_scene")
    return parse(Scene, read_yaml(path), str(path), context=context(allowed_modules(allow_code)))


def scene_and_source(scene: Scene | str | Path, function: str = "rpdrill",
                     allow_code: Sequence[str] | str = ()) -> tuple[Scene, str]:
    """A validated scene (given, or read from a file) and the name its messages use; ``function``: the
    library call whose argument it is, for the message when it is neither; ``allow_code``: the modules of
    one's own it may run besides those a given scene may (models.definition.own_code)."""
    check(function, "allow_code", allow_code, allow_code_problem)
    if isinstance(scene, Scene):
        allowed = scene if not allow_code else scene.with_({}, f"{function}: scene", allow_code)
        return allowed, f"scene {scene.name!r}"
    check(function, "scene", scene, scene_file_problem)
    path = shipped_path(scene, "scene", function)
    return load_scene(path, allow_code), str(path)


def prepare_scene(scene: Scene, source: str, where: str = "") -> Simulation:
    """Prepare a validated scene for a run; InputError naming ``source``, ``where`` (a scan point),
    the key path and the value where it cannot run as given (models.solvers.simulation.SceneError, or a
    formulation that cannot run it)."""
    try:
        simulation = prepare(scene)
    except SceneError as err:
        raise InputError(f"{source}: {where}{'.'.join(err.location)}: {short(err.value)}: {err}") from None
    formulation = simulation.settings.formulation
    why = unsupported(formulation, simulation)
    if why:
        raise InputError(f"{source}: {where}solver.formulation: {formulation!r} cannot run this scene: {why}")
    return simulation
