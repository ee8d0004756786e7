"""Reading YAML input and turning every problem into one clear message.

An :class:`InputError` message names the file, the key path, the value and what is allowed;
the command line prints it and exits with status 2.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, TypeVar, get_args, get_origin

import yaml
from pydantic import BaseModel, ValidationError

from rpdrill.models.formulations import unsupported
from rpdrill.models.scene import Scene
from rpdrill.models.simulation import SceneError, Simulation, prepare

ModelT = TypeVar("ModelT", bound=BaseModel)


class InputError(Exception):
    """Bad user input; the message is complete and meant for the user."""


def read_yaml(path: str | Path) -> dict[str, Any]:
    """The mapping in a YAML file, or InputError naming the file and the problem."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as err:
        raise InputError(f"{path}: cannot read file: {err.strerror or err}") from None
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as err:
        raise InputError(f"{path}: not valid YAML: {err}") from None
    if not isinstance(data, dict):
        raise InputError(f"{path}: expected a mapping of keys at the top level, found {type(data).__name__}")
    return data


def _inner_model(annotation: Any) -> tuple[type[BaseModel] | None, bool]:
    """The model inside a field's annotation (``Model``, ``Model | None``, ``dict[str, Model]``) and
    whether it sits behind a free mapping key (the dict case)."""
    keyed = get_origin(annotation) is dict
    candidates = get_args(annotation)[1:] if keyed else getattr(annotation, "__args__", (annotation,))
    model = next((a for a in candidates if isinstance(a, type) and issubclass(a, BaseModel)), None)
    return model, keyed


def allowed_keys(model: type[BaseModel], location: tuple[Any, ...]) -> list[str] | None:
    """Keys allowed at the parent of ``location`` inside ``model`` (None if not a model there).

    Keys are the names a scene file uses (field aliases such as ``from``); a mapping of models
    (``drill_string.bodies``) takes any name, after which its model's keys apply again.
    """
    current: type[BaseModel] | None = model
    keyed = False
    for part in location[:-1]:
        if keyed:  # a free name in a mapping of models
            keyed = False
            continue
        if isinstance(part, int) or current is None:
            return None
        field = next((f for name, f in current.model_fields.items() if part in (name, f.alias)), None)
        if field is None:
            return None
        current, keyed = _inner_model(field.annotation)
    if keyed or current is None:
        return None
    return [field.alias or name for name, field in current.model_fields.items()]


def _short(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 80 else text[:77] + "..."


def describe_validation_error(source: str, error: ValidationError, model: type[BaseModel],
                              prefix: tuple[Any, ...] = ()) -> str:
    """One message for all problems of a validation: '<file>: <key.path>: <value>: <what is allowed>'."""
    lines = []
    for item in error.errors():
        location = tuple(part for part in item["loc"] if part not in ("function-after",))
        path = ".".join(str(p) for p in prefix + location) or "(top level)"
        if item["type"] == "extra_forbidden":
            allowed = allowed_keys(model, location)
            hint = f"unknown key; allowed keys here: {', '.join(allowed)}" if allowed else "unknown key"
            lines.append(f"{source}: {path}: {_short(item['input'])}: {hint}")
        elif item["type"] == "missing":
            lines.append(f"{source}: {path}: missing: a value is required")
        elif item["type"] == "value_error":
            lines.append(f"{source}: {path}: {item['msg'].removeprefix('Value error, ')}")
        else:
            lines.append(f"{source}: {path}: {_short(item['input'])}: {item['msg']}")
    return "\n".join(lines)


def parse(model: type[ModelT], data: Any, source: str, prefix: tuple[Any, ...] = ()) -> ModelT:
    """Validate ``data`` as ``model``; InputError with the described problems otherwise."""
    try:
        return model.model_validate(data)
    except ValidationError as error:
        raise InputError(describe_validation_error(source, error, model, prefix)) from None


def load_scene(path: str | Path) -> Scene:
    """Read and validate a scene file."""
    return parse(Scene, read_yaml(path), str(path))


def prepare_scene(scene: Scene, source: str) -> Simulation:
    """Prepare a validated scene for a run; InputError naming ``source``, the key path and the value
    where it cannot run as given (models.simulation.SceneError, or a formulation that cannot run it)."""
    try:
        simulation = prepare(scene)
    except SceneError as err:
        raise InputError(f"{source}: {'.'.join(err.location)}: {_short(err.value)}: {err}") from None
    formulation = simulation.settings.formulation
    why = unsupported(formulation, simulation)
    if why:
        raise InputError(f"{source}: solver.formulation: {formulation!r}: {why}")
    return simulation
