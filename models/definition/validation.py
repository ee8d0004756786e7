"""Validated input: pydantic's problems as one message a user reads, and validated edits by key path.

An :class:`InputError` message names the source (a file, or the call that made the change), the key
path, the value and what is allowed, one line a problem; the command line prints it and exits with
status 2, the library raises it (a ``ValueError``). Generic over pydantic models: the scene and every
file format of the studies use it.
"""

from __future__ import annotations

import copy
import functools
import re
import types
import typing
from collections.abc import Mapping
from typing import Any, TypeVar, get_args, get_origin

from pydantic import BaseModel, ValidationError

ModelT = TypeVar("ModelT", bound=BaseModel)
UNIONS = (typing.Union, types.UnionType)
SHORT_VALUE_CHARS = 80  # a value longer than this is shortened in a message


LONG_QUOTED = re.compile(r"(?<!\w)(['\"])([^'\"\n]{78})[^'\"\n]{3,}\1(?!\w)")  # a quoted value beyond 80 characters


class InputError(ValueError):
    """Bad user input, refused before anything runs (a ``ValueError``; exit status 2 on the command line).

    The message is complete and meant for the user: the file (or the call), the key path, the value and what is
    allowed; a quoted value beyond 80 characters is shortened (:func:`shortened`).

    Parameters
    ----------
    *args
        The message, as for any exception.

    Attributes
    ----------
    problems : tuple of (str, str)
        When a validation found it (:func:`parse`), each problem as (key path, what is wrong), so that a caller
        can tie it to the change that caused it (a scan axis: studies.runtime.point_runs).

    Examples
    --------
    >>> import rpdrill
    >>> try:
    ...     rpdrill.load_scene("paper_base").with_({"impact.frequency_hz": -1})
    ... except rpdrill.InputError as error:
    ...     print(error)
    Scene.with_: impact.frequency_hz: -1: Input should be greater than 0
    """

    problems: tuple[tuple[str, str], ...] = ()

    def __str__(self) -> str:
        return shortened(super().__str__())


def shortened(message: str) -> str:
    """``message`` with every quoted value longer than 80 characters cut to 77 and '...'."""
    return LONG_QUOTED.sub(lambda m: f"{m[1]}{m[2][:74]}...{m[1]}", message)


FREE = "free values"  # what a mapping of plain values (an extension's parameters) holds: any key


def _inner_model(annotation: Any) -> tuple[type[BaseModel] | str | None, bool]:
    """The model inside a field's annotation (``Model``, ``Model | None``, ``dict[str, Model]``, optional
    too) and whether it sits behind a free mapping key (the dict case); a mapping of plain values
    (``dict[str, Any]``) is :data:`FREE`, any key."""
    options = [a for a in get_args(annotation) if a is not type(None)] if get_origin(annotation) in UNIONS else []
    if len(options) == 1:
        annotation = options[0]
    keyed = get_origin(annotation) is dict
    candidates = get_args(annotation)[1:] if keyed else getattr(annotation, "__args__", (annotation,))
    model = next((a for a in candidates if isinstance(a, type) and issubclass(a, BaseModel)), None)
    if keyed and model is None:
        return FREE, False
    return model, keyed


def _field(model: type[BaseModel], key: Any) -> Any:
    """The field of ``model`` named ``key`` in a file (its alias or its name), None if there is none."""
    return next((f for name, f in model.model_fields.items() if key in (name, f.alias)), None)


@functools.cache  # a pure function of a model class and a key path: each path's walk done once
def _parent_model(model: type[BaseModel], location: tuple[Any, ...]) -> type[BaseModel] | str | None:
    """The model that holds the last key of ``location`` inside ``model`` (None if not a model there;
    :data:`FREE` inside a mapping of plain values, where any key goes).

    Keys are the names a scene file uses (field aliases such as ``from``); a mapping of models
    (``drill_string.bodies``) takes any name, after which its model's keys apply again.
    """
    current: type[BaseModel] | str | None = model
    keyed = False
    for part in location[:-1]:
        if keyed:  # a free name in a mapping of models
            keyed = False
            continue
        if isinstance(part, int) or current is None or current is FREE:
            return None
        field = _field(current, part)
        if field is None:
            return None
        current, keyed = _inner_model(field.annotation)
    return None if keyed else current


def allowed_keys(model: type[BaseModel], location: tuple[Any, ...]) -> list[str] | None:
    """Keys allowed at the parent of ``location`` inside ``model`` (None if not a model there; a mapping
    of plain values allows any key: [``location``'s last])."""
    parent = _parent_model(model, location)
    if parent is FREE:
        return [location[-1]]
    return None if parent is None else [field.alias or name for name, field in parent.model_fields.items()]


def _field_keyed(model: type[BaseModel], location: tuple[Any, ...]) -> bool:
    """Whether ``location`` names a mapping of models (``drill_string.bodies``)."""
    parent = _parent_model(model, location) if location else None
    if parent is None or parent is FREE:
        return False
    field = _field(parent, location[-1])
    return field is not None and _inner_model(field.annotation)[1]


def field_at(model: type[BaseModel], location: tuple[Any, ...]) -> Any:
    """The pydantic field (FieldInfo) at the key path ``location`` inside ``model``, None if none (a key
    of a mapping of plain values has none)."""
    parent = _parent_model(model, location)
    return None if parent is None or parent is FREE else _field(parent, location[-1])


def short(value: Any) -> str:
    """A value as a message shows it: its repr, shortened to SHORT_VALUE_CHARS characters."""
    text = "null" if value is None else repr(value)
    return text if len(text) <= SHORT_VALUE_CHARS else text[:SHORT_VALUE_CHARS - 3] + "..."


# what a strict type accepts, for the messages of pydantic's type errors
STRICT_TYPES = {
    "float_type": "a number is required (not text, true/false or null; YAML reads yes/no/on/off as true/false)",
    "int_type": "a whole number is required (not a fraction, text, true/false or null)",
    "bool_type": "true or false is required",
    "string_type": "text is required",
    "dict_type": "a mapping of keys is required",
    "list_type": "a list [..] is required",
    "model_type": "a mapping of keys is required (a section, not null, a value or a list)",
    "model_attributes_type": "a mapping of keys is required (a section, not null, a value or a list)",
}


OWN_PATH = re.compile(r"[A-Za-z_][\w]*(\.[\w]+)*: ")  # a message that begins with the key path it is about


def problem(item: Any) -> str:
    """What one problem of a pydantic validation says: a validator's own text, or what the key allows."""
    if item["type"] == "value_error":
        return item["msg"].removeprefix("Value error, ")
    return STRICT_TYPES.get(item["type"], item["msg"])


def describe_validation_error(source: str, error: ValidationError, model: type[BaseModel],
                              prefix: tuple[Any, ...] = ()) -> str:
    """One message for all problems of a validation: '<file>: <key.path>: <value>: <what is allowed>'."""
    lines = []
    for item in error.errors():
        location = tuple(part for part in item["loc"] if part not in ("function-after", "[key]"))
        path = ".".join(str(p) for p in prefix + location) or "(top level)"
        if item["type"] == "extra_forbidden":
            allowed = allowed_keys(model, location)
            hint = f"unknown key; allowed keys here: {', '.join(allowed)}" if allowed else "unknown key"
            lines.append(f"{source}: {path}: {short(item['input'])}: {hint}")
        elif item["type"] == "missing":
            lines.append(f"{source}: {path}: missing: a value is required")
        elif item["type"] == "value_error" and not location and OWN_PATH.match(problem(item)):
            lines.append(f"{source}: {problem(item)}")  # a check of the whole file that names its key path itself
        elif item["type"] == "value_error":
            lines.append(f"{source}: {path}: {problem(item)}")
        else:
            lines.append(f"{source}: {path}: {short(item['input'])}: {problem(item)}")
    return "\n".join(lines)


def parse(model: type[ModelT], data: Any, source: str, prefix: tuple[Any, ...] = (),
          context: Mapping[str, Any] | None = None) -> ModelT:
    """Validate ``data`` as ``model`` (``context``: pydantic's validation context, what the reader allows:
    models.definition.own_code); InputError with the described problems otherwise."""
    try:
        return model.model_validate(data, context=None if context is None else dict(context))
    except ValidationError as error:
        failure = InputError(describe_validation_error(source, error, model, prefix))
        failure.problems = tuple((".".join(str(p) for p in item["loc"] if p != "function-after"), problem(item))
                                 for item in error.errors())
        raise failure from None


def set_path(data: dict[str, Any], path: str, value: Any) -> None:
    """Set ``data[a][b][c] = value`` for ``path`` 'a.b.c', creating missing mappings."""
    *parents, leaf = path.split(".")
    for key in parents:
        data = data.setdefault(key, {})
    data[leaf] = copy.deepcopy(value)


def check_path(model: type[BaseModel], source: str, key: str, path: str, base: dict[str, Any] | None = None,
               base_name: str = "the base scene", value_only: bool = False) -> None:
    """``path`` must name a key of ``model`` (a scene key path); a name in a mapping of models
    (``drill_string.bodies.X``) must exist in ``base`` when the path goes into it (a typo there would add a
    body, not change one); the path of a whole entry (``drill_string.bodies.clamp``) may add a new one;
    any key goes in a mapping of plain values (``extensions.NAME.parameters.KEY``).
    ``key``: where the path was given (``scan``, ``base_overrides``), prefixed to it in the message;
    ``base_name``: what the message calls ``base``; ``value_only`` (a scan axis): the key must hold a
    value, not a whole section."""
    parts = tuple(path.split("."))
    where = f"{key}.{path}" if key else path
    allowed = allowed_keys(model, parts)
    new_entry = _field_keyed(model, parts[:-1])  # a whole body, connector or extension, new or replaced
    if (allowed is None or parts[-1] not in allowed) and not new_entry:
        hint = f"allowed keys here: {', '.join(allowed)}" if allowed else "not a path to a scene key"
        raise InputError(f"{source}: {where}: unknown scene key path; {hint}")
    inner = allowed_keys(model, (*parts, "?"))
    if value_only and (inner is not None or allowed_keys(model, (*parts, "?", "?")) is not None):
        keys = f"; its keys: {', '.join(inner)}" if inner else ""
        raise InputError(f"{source}: {where}: a whole section, not a value; scan one of its keys "
                         f"({path}.KEY){keys}")
    node: Any = base
    for depth, part in enumerate(parts[:-1]):
        if not isinstance(node, dict):
            return
        free_name = allowed_keys(model, parts[:depth + 1]) is None  # a key of a mapping of models
        if free_name and part not in node:
            names = ", ".join(node)
            raise InputError(f"{source}: {where}: {part!r} is not in {base_name}'s "
                             f"{'.'.join(parts[:depth])}; there: {names} (a new one is given whole: "
                             f"{'.'.join(parts[:depth + 1])}: {{...}})")
        node = node.get(part)


def with_changes(model: ModelT, changes: dict[str, Any], source: str,
                 context: Mapping[str, Any] | None = None) -> ModelT:
    """A validated copy of ``model`` with ``changes`` (dotted key path -> value, the keys of its file
    format, ``None`` removes a key), validated with ``context`` (:func:`parse`), or InputError naming
    ``source``, the key path and the value."""
    if not isinstance(changes, Mapping):
        raise InputError(f"{source}: changes: {short(changes)}: give a mapping of key paths to values, e.g. "
                         "{'impact.frequency_hz': 70.0}")
    data = model.model_dump(by_alias=True, exclude_none=True)
    for path, value in changes.items():
        if not isinstance(path, str) or not path:
            raise InputError(f"{source}: {short(path)}: a key path is text such as 'impact.frequency_hz'")
        check_path(type(model), source, "", path, data, "the scene")
        if value is None:
            *parents, leaf = path.split(".")
            node = data
            for part in parents:
                node = node.get(part, {})
            node.pop(leaf, None)
        else:
            set_path(data, path, value)
    return parse(type(model), data, source, context=context)

