"""Reading YAML input strictly and turning every problem into one clear message.

An :class:`InputError` message names the file, the key path, the value and what is allowed;
the command line prints it and exits with status 2.

The reader accepts a regular file of UTF-8 text (at most MAX_FILE_BYTES) holding one YAML
document whose top level is a mapping, and is stricter than YAML 1.1 where 1.1 lets mistakes
pass: a key given twice in one mapping is an error (not the last one winning), keys are text,
aliases may not expand beyond MAX_VALUES values nor nest beyond MAX_DEPTH levels, and no text
holds control characters or invisible direction marks. Numbers follow YAML 1.2: ``1e5`` and
``1.5e-3`` are floats (YAML 1.1 reads a float without a dot as text).
"""

from __future__ import annotations

import re
import unicodedata
from pathlib import Path
from typing import Any

import yaml

from ...models.definition.scene import Scene
from ...models.definition.validation import InputError, parse, short
from ...models.solvers.simulation import SceneError, Simulation, prepare, unsupported

__all__ = ["InputError", "load_scene", "parse", "parse_yaml", "prepare_scene", "read_text", "read_yaml",
           "scene_and_source"]

MAX_FILE_BYTES = 16 * 2**20
MAX_VALUES = 100_000  # values of a document, aliases expanded (a scene has about a hundred)
MAX_DEPTH = 32  # nesting of mappings and lists (a scene has five levels)
YAML_12_FLOAT = re.compile(r"^[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?$")
MERGE = "tag:yaml.org,2002:merge"


def read_text(path: str | Path) -> str:
    """The UTF-8 text of a regular file, or InputError naming the file and what is wrong with it."""
    path = Path(path)
    try:
        if not path.exists():
            raise InputError(f"{path}: no such file")
        if path.is_dir():
            raise InputError(f"{path}: is a directory; give a YAML file")
        if not path.is_file():
            raise InputError(f"{path}: not a regular file (a device, pipe or socket); give a YAML file")
        size = path.stat().st_size
        if size > MAX_FILE_BYTES:
            raise InputError(f"{path}: {size} bytes; an input file is at most {MAX_FILE_BYTES} bytes of YAML text")
        data = path.read_bytes()
    except OSError as err:
        raise InputError(f"{path}: cannot read file: {err.strerror or err}") from None
    nul = data.find(0)
    if nul >= 0:
        raise InputError(f"{path}: a binary file (a NUL byte at offset {nul}), not UTF-8 YAML text")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as err:
        line = data[:err.start].count(b"\n") + 1
        raise InputError(f"{path}: line {line}: byte 0x{data[err.start]:02x} is not UTF-8 text; "
                         "save the file as UTF-8") from None


class _Refused(yaml.YAMLError):
    """Valid YAML that the strict reader refuses: the key path, where, and why."""

    def __init__(self, path: str, mark: yaml.Mark, message: str) -> None:
        super().__init__(message)
        self.path, self.mark, self.message = path or "(top level)", mark, message


class _StrictLoader(yaml.SafeLoader):
    """SafeLoader with YAML 1.2 floats; keys once per mapping and text only (module doc)."""

    key_paths: dict[int, str]  # id(mapping node) -> its key path, for messages

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict[Any, Any]:
        first: dict[Any, yaml.Node] = {}
        for key_node, _ in node.value:
            if key_node.tag == MERGE:
                continue
            key = self.construct_object(key_node, deep=True)
            where = _join(self.key_paths.get(id(node), ""), key)
            if not isinstance(key, str):
                raise _Refused(where, key_node.start_mark, f"key {key!r} is not text; quote it (YAML reads numbers, "
                               "yes/no/on/off and null as such)")
            if key in first:
                raise _Refused(where, key_node.start_mark, f"duplicate key, first at line "
                               f"{first[key].start_mark.line + 1}; a key may appear once in a mapping")
            first[key] = key_node
        return super().construct_mapping(node, deep)


_StrictLoader.yaml_implicit_resolvers = {first: list(resolvers)
                                         for first, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()}
_StrictLoader.add_implicit_resolver("tag:yaml.org,2002:float", YAML_12_FLOAT, list("-+.0123456789"))


def _join(parent: str, key: Any) -> str:
    return f"{parent}.{key}" if parent else str(key)


def _key_paths(root: yaml.Node) -> dict[int, str]:
    """The key path of every mapping node; _Refused when aliases expand beyond MAX_VALUES values,
    nest beyond MAX_DEPTH levels, or contain themselves."""
    paths: dict[int, str] = {}
    sizes: dict[int, int] = {}  # id -> values below the node, aliases expanded
    stack: list[tuple[yaml.Node, str, int, bool]] = [(root, "", 1, False)]
    open_nodes: set[int] = set()
    while stack:
        node, path, depth, done = stack.pop()
        children = [child for pair in node.value for child in pair] if isinstance(node, yaml.MappingNode) \
            else node.value if isinstance(node, yaml.SequenceNode) else []
        if done:
            open_nodes.discard(id(node))
            sizes[id(node)] = 1 + sum(sizes[id(child)] for child in children)
            if sizes[id(node)] > MAX_VALUES:
                raise _Refused(path, node.start_mark, f"aliases expand to more than {MAX_VALUES} values; "
                               "write the values out")
            continue
        if id(node) in open_nodes:
            raise _Refused(path, node.start_mark, "a recursive alias (an anchor that contains itself)")
        if id(node) in sizes:
            continue
        if depth > MAX_DEPTH:
            raise _Refused(path, node.start_mark, f"nested more than {MAX_DEPTH} levels deep")
        open_nodes.add(id(node))
        if isinstance(node, yaml.MappingNode):
            paths.setdefault(id(node), path)
        stack.append((node, path, depth, True))
        if isinstance(node, yaml.MappingNode):
            for key, value in node.value:
                name = key.value if isinstance(key, yaml.ScalarNode) else "?"
                stack += [(key, path, depth + 1, False), (value, _join(path, name), depth + 1, False)]
        else:
            stack += [(child, _join(path, i), depth + 1, False) for i, child in enumerate(children)]
    return paths


def _hidden_character(text: str) -> str | None:
    """The first control character (but tab and newline) or invisible format character (direction
    marks, zero-width characters) in ``text``."""
    return next((c for c in text if c not in "\t\n" and unicodedata.category(c) in ("Cc", "Cf")), None)


def _hidden_text(data: Any) -> str | None:
    """'<key.path>: <value>: ...' for the first key or text value below ``data`` that holds a hidden
    character (:func:`_hidden_character`), None if there is none."""
    stack: list[tuple[Any, str]] = [(data, "")]
    while stack:
        value, where = stack.pop()
        if isinstance(value, dict):
            stack += [(key, where) for key in value] + [(item, _join(where, key)) for key, item in value.items()]
        elif isinstance(value, list):
            stack += [(item, _join(where, i)) for i, item in enumerate(value)]
        elif isinstance(value, str) and (hidden := _hidden_character(value)) is not None:
            name = unicodedata.name(hidden, "")
            return (f"{where or '(top level)'}: {short(value)}: holds the control or invisible character "
                    f"U+{ord(hidden):04X}{f' ({name})' if name else ''}; text here is printable characters only")
    return None


def parse_yaml(text: str, source: str) -> dict[str, Any]:
    """The top-level mapping of YAML ``text`` read strictly (module doc); InputError naming
    ``source`` (and the line) otherwise."""
    loader = None
    try:
        loader = _StrictLoader(text)
        node = loader.get_single_node()
        if node is None:
            raise InputError(f"{source}: the file is empty; expected a mapping of keys")
        loader.key_paths = _key_paths(node)
        data = loader.construct_document(node)
    except _Refused as err:
        raise InputError(f"{source}: {err.path} (line {err.mark.line + 1}): {err.message}") from None
    except yaml.reader.ReaderError as err:
        line = text[:err.position].count("\n") + 1
        raise InputError(f"{source}: line {line}: character U+{err.character:04X} is not allowed in YAML text "
                         "(a control character)") from None
    except yaml.MarkedYAMLError as err:
        mark = err.problem_mark
        where = f"line {mark.line + 1}, column {mark.column + 1}: " if mark else ""
        context = f" ({err.context})" if err.context else ""
        raise InputError(f"{source}: {where}not valid YAML: {err.problem}{context}") from None
    except RecursionError:
        raise InputError(f"{source}: nested too deeply to read; at most {MAX_DEPTH} levels") from None
    finally:
        if loader is not None:
            loader.dispose()
    if not isinstance(data, dict):
        raise InputError(f"{source}: expected a mapping of keys at the top level, found "
                         f"{'a list' if isinstance(data, list) else short(data)}")
    hidden = _hidden_text(data)
    if hidden:
        raise InputError(f"{source}: {hidden}")
    return data


def read_yaml(path: str | Path) -> dict[str, Any]:
    """The mapping in a YAML file (:func:`read_text`, :func:`parse_yaml`), or InputError naming the
    file and the problem."""
    return parse_yaml(read_text(path), str(path))


def load_scene(path: str | Path) -> Scene:
    """Read and validate a scene file."""
    return parse(Scene, read_yaml(path), str(path))


def scene_and_source(scene: Scene | str | Path) -> tuple[Scene, str]:
    """A validated scene (given, or read from a file) and the name its messages use."""
    if isinstance(scene, Scene):
        return scene, f"scene {scene.name!r}"
    return load_scene(scene), str(scene)


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
