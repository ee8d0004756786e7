"""YAML studies: scans of a base scene over dotted scene paths, expanded into validated points.

A study names a ``base_scene`` (a file relative to the study file, or an inline mapping),
optional ``base_overrides`` (dotted path -> value, each replacing what is at that path, e.g.
``solver.end_time_s: 1.5`` or ``rock: {name: sandstone}``), the ``scan`` axes, how they
``combine`` (``grid``, ``zip``, or a list of groups zipped inside and crossed with each
other), the ``metrics`` to collect and the ``plots`` to draw. Every point is a typed scene, the base
scene with its axis values (``Scene.with_``: any scene key path is an axis), prepared once, at load
(studies.runtime.point_runs); the formulation is the scene's ``solver.formulation`` (e.g.
``base_overrides: {solver.formulation: exact}``).

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

import hashlib
import itertools
import json
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import Field, model_validator

from ...models.definition.formulations import FORMULATIONS
from ...models.definition.scene import Scene
from ...models.definition.validation import short
from ...models.solvers.simulation import Simulation
from ..inputs.arguments import (
    allow_code_problem,
    check,
    choice_problem,
    file_problem,
    instance_problem,
    optional,
)
from ..inputs.reading import InputError, parse, read_yaml
from ..inputs.shipped import shipped_path
from ..inputs.specs import METRIC_NAMES, Axis, MetricName, SceneSpec, StrictSpec, check_scene_path
from ..runtime.budgets import DEFAULT_BUDGET, Budget, BudgetError, base_estimate_s, check_size
from ..runtime.point_runs import prepare_point, where


class Plot(StrictSpec):
    """``curves``: metric(s) ``y`` against axis ``x``, one curve per value of the other axes
    (``curves``: the axis the plot is about; every varied value is in the legend), the optimum of
    each curve marked. ``map``: metric ``z`` over axes ``x`` and ``y`` as cells, the optimum along
    ``x`` of each ``y`` marked, a panel for each combination of the other axes (studies.figures.scan_figures)."""

    kind: Literal["curves", "map"] = "curves"
    x: str
    y: str | Annotated[list[str], Field(min_length=1)]
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


class StudySpec(SceneSpec):
    """The study file as written."""

    scan: dict[str, Axis] = Field(min_length=1)
    combine: Literal["grid", "zip"] | list[Annotated[list[str], Field(min_length=1)]] = "grid"
    metrics: list[MetricName] = Field(list(METRIC_NAMES), min_length=1)
    plots: list[Plot] = Field(default_factory=list)
    format: Literal["png", "svg", "pdf"] = "png"  # an SVG is written beside a PNG or PDF
    # continuation: every point's periodic orbit (solver.steady_state periodic) followed along one scan axis
    # from both ends (studies.scan.continuation_runs); continuation_axis default: the first scan axis
    steady_state: Literal["continuation"] | None = None
    continuation_axis: str | None = None


@dataclass(frozen=True)
class StudyPoint:
    """One scene of a study: its index, its axis values (scene key path -> value), the prepared
    simulation of ``base.with_(values)`` and its estimated CPU seconds (models.solvers.cost)."""

    index: int
    values: dict[str, Any]
    simulation: Simulation
    cpu_s: float

    @property
    def scene(self) -> Scene:
        return self.simulation.scene


@dataclass(frozen=True)
class Study:
    """A validated study: its base scene and its points, expanded from the scan axes (:func:`load_study`).

    Parameters
    ----------
    source : pathlib.Path
        The study file.
    spec : StudySpec
        The file's content, typed (the keys: docs/studies.md).
    base : Scene
        The base scene, ``base_overrides`` applied.
    axes : dict of str to list
        Each scan axis (a scene key path) and its values.
    points : list of StudyPoint
        Every point: its index, its axis values, its prepared simulation and its estimated CPU seconds.

    Examples
    --------
    >>> import rpdrill
    >>> study = rpdrill.load_study("paper/frequency_scan")
    >>> len(study.points), study.axes["impact.frequency_hz"][:3]
    (23, [10.0, 15.0, 20.0])
    >>> study.points[0].scene.impact.frequency_hz
    10.0
    """

    source: Path
    spec: StudySpec
    base: Scene
    axes: dict[str, list[Any]]
    points: list[StudyPoint]

    def resolved(self) -> dict[str, Any]:
        """The study with the base scene (overrides applied, defaults filled) and the axis values."""
        data = self.spec.model_dump(mode="json", by_alias=True)
        data.update(base_scene=self.base.model_dump(mode="json", by_alias=True), scan=self.axes)
        return data

    @property
    def continuation_axis(self) -> str:
        """The axis a continuation study follows (``continuation_axis``, else the first scan axis)."""
        return self.spec.continuation_axis or next(iter(self.spec.scan))

    def zipped_with(self, axis: str) -> list[str]:
        """The scan axes that change together with ``axis`` (its ``combine`` group, itself included)."""
        return next(group for group in _groups(self.spec, str(self.source)) if axis in group)

    @cached_property
    def scene_keys(self) -> list[str]:
        """Each point's resolved scene (models.solvers.simulation.Simulation.resolved_scene: with its outputs and
        solver settings) as canonical JSON: equal keys, equal results."""
        return [json.dumps(p.simulation.resolved_scene(), sort_keys=True) for p in self.points]

    @property
    def hash(self) -> str:
        """SHA-256 of what determines the results: the point scenes and the collected metrics (the JSON
        of {"metrics": [...], "points": [scene, ...]} with sorted keys, assembled from :attr:`scene_keys`)."""
        content = f'{{"metrics": {json.dumps(list(self.spec.metrics))}, "points": [{", ".join(self.scene_keys)}]}}'
        return hashlib.sha256(content.encode()).hexdigest()


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


def _point_count(groups: list[list[str]], spec: StudySpec, source: str) -> float:
    """The number of points, from the axes' counts (before any is expanded); InputError when a
    zipped group's axes differ in length."""
    count = 1.0
    for group in groups:
        lengths = {n: spec.scan[n].count for n in group}
        if len(set(lengths.values())) > 1:
            raise InputError(f"{source}: combine: zipped axes need equal lengths, got "
                             + ", ".join(f"scan.{n}: {k:.6g}" for n, k in lengths.items()))
        count *= next(iter(lengths.values()))
    return count


def _combine(groups: list[list[str]], axes: dict[str, list[Any]]) -> list[dict[str, Any]]:
    zipped = [[dict(zip(group, values)) for values in zip(*(axes[n] for n in group))] for group in groups]
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


def load_study(path: str | Path, formulation: str | None = None, budget: Budget = DEFAULT_BUDGET,
               allow_code: Sequence[str] | str = ()) -> Study:
    """Read, validate and expand a study file, or a shipped study by its name.

    Every point is validated and prepared here, so a point that cannot run is refused now, naming the scan
    axis that made it so; the study's runs are checked against ``budget`` before anything runs.

    Parameters
    ----------
    path : str or pathlib.Path
        A study file (its keys: docs/studies.md), or a shipped study's name (``"paper/frequency_scan"``).
    formulation : {"exudyn", "exact", "ode"}, optional
        Every point with this formulation (the base scene's solver options of another formulation dropped).
    budget : Budget, default Budget()
        The steps and memory per run, and the CPU time of all runs, the study may take.
    allow_code : sequence of str or str, default ()
        The modules of one's own its scenes may run (models.definition.own_code); never read from the file.

    Returns
    -------
    Study
        The study with its base scene and points, ready for :func:`run_study`.

    Raises
    ------
    InputError
        Naming the file, the key path, the value and what is allowed.
    BudgetError
        Naming the cost and the option that allows it.

    Examples
    --------
    >>> import rpdrill
    >>> study = rpdrill.load_study("paper/frequency_scan", formulation="exact")
    >>> study.spec.name, len(study.points), study.base.solver.formulation
    ('frequency_scan', 23, 'exact')
    """
    check("rpdrill.load_study", "path", path, file_problem)
    check("rpdrill.load_study", "formulation", formulation, optional(choice_problem(FORMULATIONS, "formulation")))
    check("rpdrill.load_study", "budget", budget, instance_problem(Budget, "a rpdrill Budget"))
    check("rpdrill.load_study", "allow_code", allow_code, allow_code_problem)
    path = Path(shipped_path(path, "study", "rpdrill.load_study"))
    source = str(path)
    spec = parse(StudySpec, read_yaml(path), source)
    base = spec.base(path, allow_code)
    if formulation is not None:
        base = base.with_solver(formulation)
    for axis in spec.scan:
        check_scene_path(source, "scan", axis, base, value_only=True)
    if spec.continuation_axis is not None and spec.steady_state != "continuation":
        raise InputError(f"{source}: continuation_axis: {spec.continuation_axis!r}: only with steady_state: continuation")
    if spec.steady_state == "continuation":
        _check_continuation(spec, source)
        base = base.with_({"solver.steady_state": "periodic"}, source)
    _check_rock_name_axis(spec, base, source)
    groups = _groups(spec, source)
    count = _point_count(groups, spec, source)
    outputs = {"outputs": {"metrics": list(spec.metrics)}}  # the model records only what these need
    what = f"scan: {count:.6g} points (" + ", ".join(f"scan.{n}: {a.count:.6g} values" for n, a in spec.scan.items()) + ")"
    check_size(budget, source, what, count, base_estimate_s(source, base, outputs))
    axes = {name: axis.expand() for name, axis in spec.scan.items()}
    _check_distinct(axes, source)
    if spec.steady_state == "continuation":
        axes = _continuation_order(spec, axes, groups, source)
    points, problems, bad_input = [], [], False
    for index, values in enumerate(_combine(groups, axes)):
        try:
            simulation = prepare_point(base, values, source, outputs)
            cost = budget.check_run(simulation, source, where(values))
            points.append(StudyPoint(index, values, simulation, cost.cpu_s))
        except (InputError, BudgetError) as error:
            bad_input |= isinstance(error, InputError)
            problems += [line for line in str(error).splitlines() if line not in problems]
    if problems:
        more = f"\n... and {len(problems) - 5} more" if len(problems) > 5 else ""
        raise (InputError if bad_input else BudgetError)("\n".join(problems[:5]) + more)
    _check_plots(spec, axes, source)
    budget.check_total(source, what, count, sum(p.cpu_s for p in points))
    return Study(path, spec, base, axes, points)


def _check_continuation(spec: StudySpec, source: str) -> None:
    """A continuation follows a numeric scan axis."""
    axis = spec.continuation_axis or next(iter(spec.scan))
    if axis not in spec.scan:
        raise InputError(f"{source}: continuation_axis: {axis!r}: not a scan axis; scan axes: {', '.join(spec.scan)}")
    values = spec.scan[axis].expand()
    if len(values) < 2 or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values):
        raise InputError(f"{source}: scan.{axis}: a continuation follows an axis of at least two numbers")


def _continuation_order(spec: StudySpec, axes: dict[str, list[Any]], groups: list[list[str]], source: str
                        ) -> dict[str, list[Any]]:
    """The axes with the continuation axis in increasing order (its zipped axes along with it) where it was
    given in neither increasing nor decreasing order, said in a warning: a continuation follows its axis from
    one end to the other, and the tables and plots show the points in that order."""
    axis = spec.continuation_axis or next(iter(spec.scan))
    values = axes[axis]
    steps = [b - a for a, b in itertools.pairwise(values)]
    if all(step > 0 for step in steps) or all(step < 0 for step in steps):
        return axes
    order = sorted(range(len(values)), key=values.__getitem__)
    group = next(g for g in groups if axis in g)
    warnings.warn(f"{source}: scan.{axis}: {short(values)} is not in order; a continuation follows it from one end "
                  f"to the other: the points run in increasing order, {short(sorted(values))}"
                  + (f" (the zipped axes {', '.join(n for n in group if n != axis)} along with it)" if len(group) > 1
                     else ""), UserWarning, stacklevel=3)
    return {name: [values_[i] for i in order] if name in group else values_ for name, values_ in axes.items()}


def _check_rock_name_axis(spec: StudySpec, base: Scene, source: str) -> None:
    """A scanned rock.name supplies the rock values only where the base rock gives none."""
    explicit = [k for k in ("stiffness_n_per_m", "damping_n_s_per_m", "threshold_n")
                if getattr(base.rock, k) is not None and f"rock.{k}" not in spec.scan]
    if "rock.name" in spec.scan and explicit:
        raise InputError(f"{source}: scan.rock.name: the base rock sets {', '.join(explicit)}, which would "
                         "override every named rock; name the base rock only, e.g. "
                         "base_overrides: {rock: {name: sandstone}}")


def _check_distinct(axes: dict[str, list[Any]], source: str) -> None:
    """Each axis gives each value once (a value twice would give two points of one scene)."""
    for name, values in axes.items():
        seen: list[Any] = []
        for value in values:
            if value in seen:
                raise InputError(f"{source}: scan.{name}: {short(value)}: given twice; each value of an axis once")
            seen.append(value)
