"""The best operating point as a library call: :func:`advise_scene` is ``rpdrill advise`` without its
files and printing (studies.advice.advice_search: the search, the curves around the optimum, the feed x
frequency map), with the bounds in SI units by key path."""

from __future__ import annotations

from pathlib import Path

from ...models.definition.scene import Scene
from ...rocklaw.catalog import TABLE_1
from ..inputs.arguments import (
    bounds_problem,
    check,
    choice_problem,
    dask_problem,
    instance_problem,
    names_problem,
    optional,
    positive_problem,
    workers_problem,
)
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
    60e3)}``, optionally ``"impact.amplitude_n"`` and an extension's ``"extensions.NAME.parameters.KEY"``; SI
    units) for the scene's rock, or for each Table 1
    rock of ``rocks``; ``power_kw``: a fixed hammer power (a piston scene, the blow energy P / f). One
    :class:`Advice` per rock (SI units). InputError before anything runs when an input cannot be used."""
    where = "rpdrill.advise"
    check(where, "bounds", bounds, bounds_problem)
    check(where, "metric", metric, choice_problem(METRICS, "metric"))
    check(where, "rocks", rocks, optional(names_problem(TABLE_1, "Table 1 rock")))
    check(where, "power_kw", power_kw, optional(positive_problem))
    check(where, "max_thrust_ratio", max_thrust_ratio, positive_problem)
    check(where, "search", search, instance_problem(AdviceSearch, "a rpdrill.AdviceSearch or None", optional=True))
    check(where, "workers", workers, optional(workers_problem))
    check(where, "dask", dask, dask_problem)
    check(where, "max_rod_stress_pa", max_rod_stress_pa, optional(positive_problem))
    validated, source = scene_and_source(scene, where)
    data = validated.model_dump(by_alias=True, exclude_none=True)
    allowed = [entry.path for entry in PARAMETERS]
    own = [f"extensions.{name}.parameters.KEY" for name in validated.extensions or {}]  # an extension's parameter
    for path in bounds:
        if path not in allowed and not _extension_parameter(path, validated):
            raise InputError(f"{source}: bounds: {path!r}: not a parameter advise searches; allowed: "
                             f"{', '.join(allowed + own)}")
    missing = [path for path in (FREQUENCY, FEED) if path not in bounds]
    if missing:
        raise InputError(f"{source}: bounds: give {' and '.join(missing)} (low, high)")
    ordered = {path: tuple(map(float, bounds[path])) for path in [*allowed, *sorted(set(bounds) - set(allowed))]
               if path in bounds}
    request = Request(metric, ordered, max_thrust_ratio, search or AdviceSearch(),
                      power_w=power_kw * 1e3 if power_kw else None, max_rod_stress_pa=max_rod_stress_pa)
    scenes = [(rock, runnable_scene(data, rock, request, source)) for rock in rocks or [None]]
    with pool(dask, workers, f"{where}: dask") as (_, runner):
        return [advise(prepared, rock, request, runner) for rock, prepared in scenes]


def _extension_parameter(path: str, scene: Scene) -> bool:
    """Whether ``path`` is ``extensions.NAME.parameters.KEY`` of an extension of ``scene``."""
    parts = path.split(".")
    return len(parts) == 4 and parts[0] == "extensions" and parts[2] == "parameters" and \
        parts[1] in (scene.extensions or {})


__all__ = ["Advice", "AdviceSearch", "advise_scene"]
