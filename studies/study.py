"""YAML studies: scans of a base scene over dotted scene paths, expanded into validated points.

A study names a ``base_scene`` (a file relative to the study file, or an inline mapping),
optional ``base_overrides`` (dotted path -> value, each replacing what is at that path, e.g.
``solver.end_time_s: 1.5`` or ``rock: {name: sandstone}``), the ``scan`` axes, how they
``combine`` (``grid``, ``zip``, or a list of groups zipped inside and crossed with each
other), the ``metrics`` to collect and the ``plots`` to draw. Every point's scene is validated and
prepared once, at load (models.simulation.prepare: the chain, the rock law, the solver settings,
the initial state); workers receive the prepared simulation and build the formulation's model
themselves (Exudyn systems cannot be pickled). The formulation is the scene's
``solver.formulation`` (e.g. ``base_overrides: {solver.formulation: exact}``). :func:`run_point`
is the worker function.

Example (``studies/paper/stiffness_scan.yaml`` has the full file)::

    name: stiffness_scan
    base_scene: ../scenes/paper_base.yaml
    base_overrides: {solver.end_time_s: 1.5}
    scan:
      rock.stiffness_n_per_m: [8.93e7, 2.1e8, 5.1e8, 8.4e8]
      rock.damping_n_s_per_m: [6.83e2, 1.98e3, 4.9e3, 2.3e4]
      impact.frequency_hz: {from: 10, to: 120, step: 5}        # or {from, to, num, spacing: log}
    combine: [[rock.stiffness_n_per_m, rock.damping_n_s_per_m]]  # zipped, crossed with the frequency
    metrics: [penetration_rate_m_per_s, bit_velocity_peak_m_per_s]
    plots:
      - {x: impact.frequency_hz, y: [penetration_rate_m_per_s], curves: rock.stiffness_n_per_m}
      - {kind: map, x: impact.frequency_hz, y: rock.stiffness_n_per_m, z: penetration_rate_m_per_s}
    format: png

The end time is the study's choice: the paper scans set ``solver.end_time_s: 1.5`` in
``base_overrides`` (10 transient + 5 averaged blows at 10 Hz) and leave the base scene file alone.
"""

from __future__ import annotations

import copy
import hashlib
import itertools
import json
import math
import re
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator

from rpdrill.models.formulations import unsupported
from rpdrill.models.metrics import summary_metrics
from rpdrill.models.outputs import METRICS
from rpdrill.models.scene import Scene
from rpdrill.models.simulation import SceneError, Simulation, prepare
from rpdrill.studies.loading import InputError, allowed_keys, parse, read_yaml

METRIC_NAMES = tuple(METRICS)
NUMBER = re.compile(r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?")
MetricName = Literal[METRIC_NAMES]  # type: ignore[valid-type]


class StrictSpec(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, populate_by_name=True)


class Axis(StrictSpec):
    """Values of one scan axis: a list ``[..]``, ``{from, to, step}`` or ``{from, to, num, spacing}``."""

    values: list[Any] | None = Field(None, min_length=1)
    start: float | None = Field(None, alias="from", allow_inf_nan=False)
    to: float | None = Field(None, allow_inf_nan=False)
    step: float | None = Field(None, allow_inf_nan=False)
    num: int | None = Field(None, ge=2)
    spacing: Literal["linear", "log"] = "linear"

    @model_validator(mode="before")
    @classmethod
    def _list_is_values(cls, data: Any) -> Any:
        return {"values": data} if isinstance(data, list) else data

    @field_validator("values")
    @classmethod
    def _numbers(cls, values: list[Any] | None) -> list[Any] | None:
        """YAML 1.1 reads ``1.2e5`` (no exponent sign) as a string: make such strings numbers."""
        return None if values is None else [float(v) if isinstance(v, str) and NUMBER.fullmatch(v) else v
                                            for v in values]

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


class Plot(StrictSpec):
    """``curves``: metric(s) ``y`` against axis ``x``, one curve per value of the other axes
    (labelled by axis ``curves``), maximum of each curve marked. ``map``: metric ``z`` over
    axes ``x`` and ``y`` with the ridge of maxima along ``x`` for each ``y``."""

    kind: Literal["curves", "map"] = "curves"
    x: str
    y: str | list[str]
    z: MetricName | None = None
    curves: str | None = None

    @model_validator(mode="after")
    def _fields_of_kind(self) -> Plot:
        if self.kind == "map" and (self.z is None or not isinstance(self.y, str) or self.curves):
            raise ValueError("kind: map needs x and y (scan axes) and z (a metric), and no curves")
        if self.kind == "curves" and self.z is not None:
            raise ValueError("kind: curves takes x (a scan axis) and y (metric or list of metrics), not z")
        return self

    @property
    def metrics(self) -> list[str]:
        return [self.z] if self.kind == "map" else [self.y] if isinstance(self.y, str) else list(self.y)

    @property
    def axes(self) -> list[str]:
        return [self.x, self.y] if self.kind == "map" else [self.x] + ([self.curves] if self.curves else [])


class StudySpec(StrictSpec):
    """The study file as written."""

    name: str
    description: str = ""
    base_scene: str | dict[str, Any]
    base_overrides: dict[str, Any] = {}
    scan: dict[str, Axis] = Field(min_length=1)
    combine: Literal["grid", "zip"] | list[list[str]] = "grid"
    metrics: list[MetricName] = Field(list(METRIC_NAMES), min_length=1)
    plots: list[Plot] = []
    format: Literal["png", "svg", "pdf"] = "png"


@dataclass(frozen=True)
class Point:
    """One scene of a study: its index, its scan parameters and the prepared simulation."""

    index: int
    parameters: dict[str, Any]
    simulation: Simulation


@dataclass(frozen=True)
class Study:
    """A validated study with its resolved base scene and its expanded points."""

    source: Path
    spec: StudySpec
    base: dict[str, Any]
    axes: dict[str, list[Any]]
    points: list[Point]

    def resolved(self) -> dict[str, Any]:
        """The study with the base scene (overrides applied, defaults filled) and the axis values."""
        data = self.spec.model_dump(mode="json", by_alias=True)
        data.update(base_scene=Scene.model_validate(self.base).model_dump(mode="json", by_alias=True), scan=self.axes)
        return data

    @property
    def hash(self) -> str:
        """SHA-256 of what determines the results: the point scenes and the collected metrics."""
        content = {"points": [p.simulation.resolved_scene() for p in self.points], "metrics": list(self.spec.metrics)}
        return hashlib.sha256(json.dumps(content, sort_keys=True).encode()).hexdigest()


def set_path(data: dict[str, Any], path: str, value: Any) -> None:
    """Set ``data[a][b][c] = value`` for ``path`` 'a.b.c', creating missing mappings."""
    *parents, leaf = path.split(".")
    for key in parents:
        data = data.setdefault(key, {})
    data[leaf] = copy.deepcopy(value)


def check_scene_path(source: str, key: str, path: str, base: dict[str, Any] | None = None) -> None:
    """A scan or override path must name a scene key; a name in a mapping (``drill_string.bodies.X``)
    must exist in the ``base`` scene (a typo there would add a body, not change one)."""
    parts = tuple(path.split("."))
    allowed = allowed_keys(Scene, parts)
    if allowed is None or parts[-1] not in allowed:
        hint = f"allowed keys here: {', '.join(allowed)}" if allowed else "not a path to a scene key"
        raise InputError(f"{source}: {key}.{path}: unknown scene key path; {hint}")
    node: Any = base
    for depth, part in enumerate(parts[:-1]):
        if not isinstance(node, dict):
            return
        free_name = allowed_keys(Scene, parts[:depth + 1]) is None  # a key of a mapping of models
        if free_name and part not in node:
            names = ", ".join(node)
            raise InputError(f"{source}: {key}.{path}: {part!r} is not in the base scene's "
                             f"{'.'.join(parts[:depth])}; there: {names}")
        node = node.get(part)


def _groups(spec: StudySpec, source: str) -> list[list[str]]:
    """Axis groups zipped inside and crossed with each other."""
    names = list(spec.scan)
    if spec.combine == "grid":
        return [[n] for n in names]
    if spec.combine == "zip":
        return [names]
    listed = [n for group in spec.combine for n in group]
    for n in listed:
        if n not in spec.scan or listed.count(n) > 1:
            raise InputError(f"{source}: combine: {n!r}: each group entry must be a scan axis, named once; "
                             f"scan axes: {', '.join(names)}")
    return list(spec.combine) + [[n] for n in names if n not in listed]


def _combine(groups: list[list[str]], axes: dict[str, list[Any]], source: str) -> list[dict[str, Any]]:
    zipped = []
    for group in groups:
        lengths = {n: len(axes[n]) for n in group}
        if len(set(lengths.values())) > 1:
            raise InputError(f"{source}: combine: zipped axes need equal lengths, got "
                             + ", ".join(f"scan.{n}: {k}" for n, k in lengths.items()))
        zipped.append([dict(zip(group, values)) for values in zip(*(axes[n] for n in group))])
    return [{k: v for part in combo for k, v in part.items()} for combo in itertools.product(*zipped)]


def _check_plots(spec: StudySpec, axes: dict[str, list[Any]], source: str) -> None:
    for i, plot in enumerate(spec.plots):
        for field, name in zip(("x", "y" if plot.kind == "map" else "curves"), plot.axes):
            if name not in axes:
                raise InputError(f"{source}: plots.{i}.{field}: {name!r}: not a scan axis; "
                                 f"scan axes: {', '.join(axes)}")
        for name in (plot.x, plot.y) if plot.kind == "map" else (plot.x,):
            if not all(isinstance(v, (int, float)) for v in axes[name]) or len(axes[name]) < 2:
                raise InputError(f"{source}: plots.{i}: axis {name!r} must have at least two numeric values")
        for name in plot.metrics:
            if name not in spec.metrics:
                raise InputError(f"{source}: plots.{i}: metric {name!r} is not collected; "
                                 f"metrics: {', '.join(spec.metrics)}")


def _point_error(source: str, error: ValidationError, parameters: dict[str, Any]) -> list[str]:
    """Problems of one point, each tied to the scan axis that caused it when there is one."""
    lines = []
    for item in error.errors():
        loc = ".".join(str(p) for p in item["loc"] if p != "function-after")
        related = [a for a in parameters if a == loc or a.startswith(loc + ".") or loc.startswith(a + ".")]
        message = item["msg"].removeprefix("Value error, ")
        if len(related) == 1:
            lines.append(f"{source}: scan.{related[0]}: {parameters[related[0]]!r}: {message}")
        else:
            lines.append(f"{source}: {_point(parameters)}{loc or 'scene'}: {message}")
    return lines


def base_scene_dict(spec: StudySpec, source: Path) -> dict[str, Any]:
    """The base scene as written, with the overrides set (not filled in: a scanned ``rock.name``
    must still supply the rock values)."""
    if isinstance(spec.base_scene, str):
        path = source.parent / spec.base_scene
        if not path.is_file():
            raise InputError(f"{source}: base_scene: {spec.base_scene!r}: no scene file {path}")
        data = read_yaml(path)
        parse(Scene, data, str(path))
    else:
        data = copy.deepcopy(spec.base_scene)
        parse(Scene, data, str(source), ("base_scene",))
    for path, value in spec.base_overrides.items():
        check_scene_path(str(source), "base_overrides", path, data)
        set_path(data, path, value)
    parse(Scene, data, f"{source} (base_scene with base_overrides)")
    return data


def _point(parameters: dict[str, Any]) -> str:
    return f"scan point {parameters}: " if parameters else ""


def prepare_point(source: str, scene: dict[str, Any], parameters: dict[str, Any]) -> Simulation:
    """Validate and prepare one point's scene; InputError naming the scan axis that made it invalid
    (or the point), and when its formulation cannot run it."""
    try:
        simulation = prepare(Scene.model_validate(scene))
    except ValidationError as error:
        raise InputError("\n".join(_point_error(source, error, parameters))) from None
    except SceneError as error:
        where = ".".join(error.location)
        raise InputError(f"{source}: {_point(parameters)}{where}: {error.value!r}: {error}") from None
    formulation = simulation.settings.formulation
    why = unsupported(formulation, simulation)
    if why:
        raise InputError(f"{source}: solver.formulation: {formulation!r} cannot run scan point {parameters}: {why}")
    return simulation


def load_study(path: str | Path) -> Study:
    """Read, validate and expand a study file; InputError naming the file and key path otherwise."""
    path = Path(path)
    spec = parse(StudySpec, read_yaml(path), str(path))
    base = base_scene_dict(spec, path)
    for axis in spec.scan:
        check_scene_path(str(path), "scan", axis, base)
    axes = {name: axis.expand() for name, axis in spec.scan.items()}
    _check_plots(spec, axes, str(path))
    _check_rock_name_axis(spec, base, str(path))
    points, problems = [], []
    for index, parameters in enumerate(_combine(_groups(spec, str(path)), axes, str(path))):
        scene = copy.deepcopy(base)
        for name, value in parameters.items():
            set_path(scene, name, value)
        scene["outputs"] = {"metrics": list(spec.metrics)}  # the model records only what these need
        try:
            points.append(Point(index, parameters, prepare_point(str(path), scene, parameters)))
        except InputError as error:
            problems += [line for line in str(error).splitlines() if line not in problems]
    if problems:
        more = f"\n... and {len(problems) - 5} more" if len(problems) > 5 else ""
        raise InputError("\n".join(problems[:5]) + more)
    return Study(path, spec, base, axes, points)


def _check_rock_name_axis(spec: StudySpec, base: dict[str, Any], source: str) -> None:
    """A scanned rock.name supplies the rock values only where the base rock gives none."""
    explicit = [k for k in ("stiffness_n_per_m", "damping_n_s_per_m", "threshold_n")
                if k in base.get("rock", {}) and f"rock.{k}" not in spec.scan]
    if "rock.name" in spec.scan and explicit:
        raise InputError(f"{source}: scan.rock.name: the base rock sets {', '.join(explicit)}, which would "
                         "override every named rock; name the base rock only, e.g. "
                         "base_overrides: {rock: {name: sandstone}}")


def run_point(task: tuple[Any, Simulation]) -> dict[str, Any]:
    """Worker: run one prepared point ``(key, simulation)`` and collect its outputs' metrics; a
    failure is returned, not raised."""
    key, simulation = task
    start = time.perf_counter()
    try:
        metrics = summary_metrics(simulation.run())
    except Exception as err:  # noqa: BLE001 - one bad point is recorded and the study goes on
        return {"point": key, "status": "failed", "error": f"{type(err).__name__}: {err}",
                "wall_time_s": time.perf_counter() - start, "metrics": {}}
    return {"point": key, "status": "ok", "error": "", "wall_time_s": time.perf_counter() - start, "metrics": metrics}
