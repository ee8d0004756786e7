"""The best operating point as a library call: :func:`advise_scene` is ``rpdrill advise`` without its
files and printing (studies.advice.advice_search: the search, the curves around the optimum, the feed x
frequency map), with the bounds in SI units by key path."""

from __future__ import annotations

from pathlib import Path

from ...models.definition.scene import Scene
from ...rocklaw.catalog import TABLE_1
from ..inputs.reading import InputError, scene_and_source
from ..runtime.pools import pool
from .advice_search import (
    FEED,
    FREQUENCY,
    METRICS,
    PARAMETERS,
    Advice,
    AdviceSearch,
    Request,
    advise,
    runnable_scene,
)


def advise_scene(scene: Scene | str | Path, bounds: dict[str, tuple[float, float]], metric: str = METRICS[0],
                 rocks: list[str] | None = None, power_kw: float | None = None, max_thrust_ratio: float = 1.0,
                 search: AdviceSearch | None = None, workers: int | None = None,
                 dask: str | None = None, max_rod_stress_pa: float | None = None) -> list[Advice]:
    """Maximise ``metric`` over ``bounds`` (``{"impact.frequency_hz": (45, 70), "feed.force_n": (35e3,
    60e3)}``, optionally ``"impact.amplitude_n"``; SI units) for the scene's rock, or for each Table 1
    rock of ``rocks``; ``power_kw``: a fixed hammer power (a piston scene, the blow energy P / f). One
    :class:`Advice` per rock (SI units). InputError before anything runs when an input cannot be used."""
    validated, source = scene_and_source(scene)
    data = validated.model_dump(by_alias=True, exclude_none=True)
    allowed = [entry.path for entry in PARAMETERS]
    for path, (low, high) in bounds.items():
        if path not in allowed:
            raise InputError(f"{source}: bounds: {path!r}: not a parameter advise searches; allowed: "
                             f"{', '.join(allowed)}")
        if not low < high:
            raise InputError(f"{source}: bounds: {path}: ({low:g}, {high:g}): the lower bound must be below the upper")
    missing = [path for path in (FREQUENCY, FEED) if path not in bounds]
    if missing:
        raise InputError(f"{source}: bounds: give {' and '.join(missing)} (low, high)")
    if metric not in METRICS:
        raise InputError(f"{source}: metric {metric!r}: allowed: {', '.join(METRICS)}")
    unknown = [rock for rock in rocks or [] if rock not in TABLE_1]
    if unknown:
        raise InputError(f"{source}: rocks: {', '.join(unknown)}: not a Table 1 rock; allowed: {', '.join(TABLE_1)}")
    ordered = {entry.path: tuple(map(float, bounds[entry.path])) for entry in PARAMETERS if entry.path in bounds}
    request = Request(metric, ordered, max_thrust_ratio, search or AdviceSearch(),
                      power_w=power_kw * 1e3 if power_kw else None, max_rod_stress_pa=max_rod_stress_pa)
    scenes = [(rock, runnable_scene(data, rock, request, source)) for rock in rocks or [None]]
    with pool(dask, workers) as (_, runner):
        return [advise(prepared, rock, request, runner) for rock, prepared in scenes]


__all__ = ["Advice", "AdviceSearch", "advise_scene"]
