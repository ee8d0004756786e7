"""What the study, accuracy and calibration files share: a strict spec base naming a base scene
with overrides, scan axes, and the check of a scene key path they name.

``base_scene`` is a scene file (relative to the spec file) or an inline mapping; ``base_overrides``
maps dotted scene paths to values, each replacing what is at that path (``solver.end_time_s: 1.5``,
``rock: {name: sandstone}``): the base scene is the typed scene with them (``Scene.with_``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

from ...models.definition.outputs import METRICS
from ...models.definition.own_code import allowed_modules, context
from ...models.definition.scene import Scene
from ...models.definition.validation import InputError, check_path, parse
from .reading import read_yaml

METRIC_NAMES = tuple(METRICS)
MetricName = Literal[METRIC_NAMES]  # type: ignore[valid-type]
# a range's num is bounded so that its count stays a float; a study of so many points is refused by
# its budget long before (studies.runtime.budgets)
MAX_NUM = 10**15


class StrictSpec(BaseModel):
    """Unknown keys are errors; numbers are numbers and finite (as in the scene, models.definition.scene.Strict)."""

    model_config = ConfigDict(extra="forbid", frozen=True, populate_by_name=True, strict=True, allow_inf_nan=False)


class SceneSpec(StrictSpec):
    """A spec file's common part: its name, and the base scene with overrides (module doc)."""

    name: str
    description: str = ""
    base_scene: str | dict[str, Any]
    base_overrides: dict[str, Any] = Field(default_factory=dict)

    def base(self, source: Path, allow_code: Sequence[str] | str = ()) -> Scene:
        """The base scene, validated, with the overrides (``Scene.with_``: the scene keeps what its file
        gives, so that a scanned ``rock.name`` still supplies the rock's values); InputError naming
        ``source`` (and the scene file, or ``base_overrides``) otherwise. ``allow_code``: the modules of
        one's own the scene may run (models.definition.own_code), the reader's, never the file's."""
        allowed = context(allowed_modules(allow_code))
        if isinstance(self.base_scene, str):
            path = source.parent / self.base_scene
            try:
                data = read_yaml(path)
            except InputError as error:
                raise InputError(f"{source}: base_scene: {self.base_scene!r}: {error}") from None
            scene = parse(Scene, data, str(path), context=allowed)
        else:
            scene = parse(Scene, self.base_scene, str(source), ("base_scene",), context=allowed)
        return scene.with_(dict(self.base_overrides), f"{source}: base_overrides") if self.base_overrides else scene


class Axis(StrictSpec):
    """Values of one scan axis: a list ``[..]``, ``{from, to, step}`` or ``{from, to, num, spacing}``."""

    values: list[Any] | None = Field(None, min_length=1)
    start: float | None = Field(None, alias="from")
    to: float | None = None
    step: float | None = None
    num: int | None = Field(None, ge=2, le=MAX_NUM)
    spacing: Literal["linear", "log"] = "linear"

    @model_validator(mode="before")
    @classmethod
    def _list_is_values(cls, data: Any) -> Any:
        return {"values": data} if isinstance(data, list) else data

    @model_validator(mode="after")
    def _one_form(self) -> Axis:
        if self.values is not None:
            if any(v is not None for v in (self.start, self.to, self.step, self.num)):
                raise ValueError("give either a list of values or from/to with step or num, not both")
            return self
        if self.start is None or self.to is None or (self.step is None) == (self.num is None):
            raise ValueError("give a list [..], {from, to, step} or {from, to, num, spacing: linear|log}")
        if self.step is not None and (self.step == 0 or (self.to - self.start) * self.step < 0):
            raise ValueError(f"step {self.step} does not lead from {self.start} to {self.to}")
        if self.spacing == "log" and (self.num is None or self.start <= 0 or self.to <= 0):
            raise ValueError("spacing: log needs num and positive from and to")
        return self

    @property
    def count(self) -> float:
        """How many values :meth:`expand` gives, known before expanding (inf beyond any float)."""
        if self.values is not None:
            return float(len(self.values))
        if self.step is not None:
            span = (self.to - self.start) / self.step
            return float(math.floor(span + 1e-9) + 1) if math.isfinite(span) else math.inf
        return float(self.num)

    def expand(self) -> list[Any]:
        """The axis values; ranges include ``to`` and are rounded to 12 significant digits."""
        if self.values is not None:
            return list(self.values)
        if self.step is not None:
            count = math.floor((self.to - self.start) / self.step + 1e-9) + 1
            raw = [self.start + i * self.step for i in range(count)]
        elif self.spacing == "log":
            ratio = math.log(self.to / self.start) / (self.num - 1)
            raw = [self.start * math.exp(i * ratio) for i in range(self.num)]
        else:
            raw = [self.start + i * (self.to - self.start) / (self.num - 1) for i in range(self.num)]
        return [float(f"{v:.12g}") for v in raw]


def check_scene_path(source: str, key: str, path: str, base: Scene | None = None, value_only: bool = False) -> None:
    """A scan or override path must name a scene key; a name in a mapping (``drill_string.bodies.X``)
    must exist in the ``base`` scene; ``value_only`` (a scan axis): a value, not a whole section
    (models.definition.validation.check_path)."""
    data = None if base is None else base.model_dump(by_alias=True, exclude_none=True)
    check_path(Scene, source, key, path, data, value_only=value_only)


def scene_value(scene: Scene, path: str) -> Any:
    """The value at a scene key path (None where the scene has none: an optional key left out)."""
    node: Any = scene.model_dump(by_alias=True, exclude_none=True)
    for key in path.split("."):
        node = node.get(key) if isinstance(node, dict) else None
    return node
