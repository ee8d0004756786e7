"""The best operating point as a library call: :func:`advise_scene` is ``rpdrill advise`` without its
printing (studies.advice.advice_search: the search, the curves around the optimum, the feed x frequency
map), with the bounds in SI units by key path. With ``out`` every point run is recorded there as it
returns (evaluations.jsonl, studies.runtime.evaluation_log: a rerun into the same folder replays them and
runs the rest) and the report is written at the end (advice.json, advice.md, the figures of each rock:
studies.advice.advice_report, studies.advice.advice_figures)."""

from __future__ import annotations

import contextlib
import sys
import time
from collections.abc import Sequence
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

from tqdm import tqdm

from ...models.definition.scene import Scene
from ...rocklaw.catalog import TABLE_1
from ..display.catalogue import metric as metric_entry
from ..display.catalogue import parameter
from ..inputs.arguments import (
    bounds_problem,
    check,
    choice_problem,
    file_problem,
    instance_problem,
    names_problem,
    optional,
    positive_problem,
)
from ..inputs.reading import InputError, scene_and_source
from ..runtime.evaluation_log import CHECKPOINT, EvaluationLog
from ..runtime.output_files import check_file_target, check_out, staged_directory, write_atomic, write_json
from ..runtime.pools import pool
from ..runtime.run_options import RunOptions
from .advice_figures import plot_curves, plot_feed_map
from .advice_report import advice_markdown, advice_record
from .advice_search import (
    FEED,
    FREQUENCY,
    METRICS,
    PARAMETERS,
    Advice,
    AdviceEvaluation,
    AdviceSearch,
    NoAllowedPoint,
    Request,
    advice_hash,
    planned_evaluations,
    runnable_scene,
    search_advice,
)

ADVISE_OPTIONS = ("workers", "dask", "out", "overwrite", "quiet")  # its run options (rpdrill.RunOptions)


def advise_scene(scene: Scene | str | Path, bounds: dict[str, tuple[float, float]], metric: str = METRICS[0],
                 rocks: list[str] | None = None, power_kw: float | None = None, max_thrust_ratio: float = 1.0,
                 search: AdviceSearch | None = None, markdown: str | Path | None = None, command: str | None = None,
                 max_rod_stress_pa: float | None = None, options: RunOptions | None = None,
                 allow_code: Sequence[str] | str = (), **run: Any) -> list[Advice]:
    """The operating point that maximises a metric within bounds: ``rpdrill advise`` as a library call.

    Differential evolution (on the exact formulation where the scene allows it), then the metric along each
    parameter through the optimum and a feed x frequency map (module doc). Points whose mean thrust (feed +
    frequency x impulse per blow) reaches ``max_thrust_ratio`` of the rock's threshold are not run.

    Parameters
    ----------
    scene : Scene, str or pathlib.Path
        The scene, a scene file or a shipped scene's name.
    bounds : dict of str to (float, float)
        Key path to (low, high), SI units: ``impact.frequency_hz``, ``feed.force_n``, optionally
        ``impact.amplitude_n`` and an extension's ``extensions.NAME.parameters.KEY``.
    metric : {"penetration_rate_m_per_s", "penetration_per_impact_energy_m_per_j"}, optional
        What is maximised (default the penetration rate).
    rocks : list of str, optional
        Table 1 rocks (``conglomerate``, ``sandstone``, ``soft_limestone``) to advise for, each in turn;
        default the scene's rock.
    power_kw : float, optional
        A fixed hammer power (a piston scene): the blow energy P / f at every frequency.
    max_thrust_ratio : float, default 1.0
        The largest mean thrust run, as a share of the rock's threshold F_th.
    search : AdviceSearch, optional
        Differential evolution's budget (default ``AdviceSearch()``).
    markdown : str or pathlib.Path, optional
        Where a copy of ``advice.md`` goes.
    command : str, optional
        The command the report names (default: this call).
    max_rod_stress_pa : float, optional
        The best point whose rods stay below this stress, tension or compression (a scene with rods).
    options : RunOptions, optional
        ``workers``, ``dask``, ``out`` (the checkpoint ``evaluations.jsonl`` and the report: resumable),
        ``overwrite``, ``quiet``; or these names as keywords.
    allow_code : sequence of str or str, default ()
        The modules of one's own the scene may run (models.definition.own_code).
    **run
        :class:`RunOptions` names.

    Returns
    -------
    list of Advice
        One per rock: the best point, its value, the curves around it, the feed x frequency map.

    Raises
    ------
    InputError
        When an input cannot be used, before anything runs.
    NoAllowedPoint
        A ``RuntimeError``: no point run keeps its rods below ``max_rod_stress_pa`` (the points run are kept in
        ``out``).

    Examples
    --------
    >>> import rpdrill
    >>> scene = rpdrill.load_scene("paper_base").with_({"solver.formulation": "exact"})
    >>> advice = rpdrill.advise(scene, {"impact.frequency_hz": (45, 75), "feed.force_n": (10e3, 30e3)},
    ...                         search=rpdrill.AdviceSearch(popsize=3, max_generations=2))  # doctest: +SKIP
    >>> advice[0].best  # doctest: +SKIP
    {'impact.frequency_hz': 75.0, 'feed.force_n': 30000.0}
    """
    where = "rpdrill.advise"
    check(where, "bounds", bounds, bounds_problem)
    check(where, "metric", metric, choice_problem(METRICS, "metric"))
    check(where, "rocks", rocks, optional(names_problem(TABLE_1, "Table 1 rock")))
    check(where, "power_kw", power_kw, optional(positive_problem))
    check(where, "max_thrust_ratio", max_thrust_ratio, positive_problem)
    check(where, "search", search, instance_problem(AdviceSearch, "a rpdrill.AdviceSearch or None", optional=True))
    options = RunOptions.of(where, options, run, ADVISE_OPTIONS)
    workers, dask, out, overwrite, quiet = options.workers, options.dask, options.out, options.overwrite, options.quiet
    check(where, "markdown", markdown, optional(file_problem))
    check(where, "max_rod_stress_pa", max_rod_stress_pa, optional(positive_problem))
    folder = None if out is None else check_out(out, overwrite, CHECKPOINT)
    if markdown is not None:
        check_file_target("--markdown", markdown)
    data, source = scene_and_source(scene, where, allow_code)
    allowed = [entry.path for entry in PARAMETERS]
    own = [f"extensions.{name}.parameters.KEY" for name in data.extensions or {}]  # an extension's parameter
    for path in bounds:
        if path not in allowed and not _extension_parameter(path, data):
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
    identity = {"advice": data.name, "scene_file": source, "hash": advice_hash([s for _, s in scenes], request)}
    advices: list[Advice] = []
    with contextlib.ExitStack() as stack:
        log = None if folder is None else stack.enter_context(
            contextlib.closing(EvaluationLog(folder, identity, Path(source), AdviceEvaluation, overwrite)))
        label, runner = stack.enter_context(pool(dask, workers, f"{where}: dask"))
        bar = stack.enter_context(tqdm(total=planned_evaluations(request) * len(scenes), desc="advise", unit="point",
                                       disable=quiet))
        earlier = len(log.records) if log else 0
        print(f"advise: maximising {metric_entry(metric).name} over {', '.join(parameter(p).name for p in ordered)} "
              f"for {len(scenes)} rock(s) on {label}" + (f"; {earlier} points recorded earlier in {folder}"
                                                         if earlier else ""), file=sys.stderr)
        start = time.perf_counter()
        try:
            for rock, prepared in scenes:
                advices.append(search_advice(prepared, rock, request, runner, bar.update, log))
        except (KeyboardInterrupt, NoAllowedPoint) as stop:  # the points run are kept (evaluations.jsonl); the
            if log:                                             # session says where it stopped
                log.add_session(_session(label, len(log.records) - earlier, advices, start,
                                         interrupted=isinstance(stop, KeyboardInterrupt)))
            raise
        if log:
            log.add_session(_session(label, len(log.records) - earlier, advices, start, interrupted=False))
    command = command or _call(source, ordered, metric, rocks, power_kw, max_thrust_ratio, request.search, out,
                               max_rod_stress_pa)
    if folder is not None:
        with staged_directory(folder) as stage:
            write_json(stage / "advice.json", advice_record(advices, command))
            (stage / "advice.md").write_text(advice_markdown(advices, command), encoding="utf-8")
            for advice in advices:
                name = advice.rock or advice.scene
                plot_curves(advice, stage / f"{name}_curves.png")
                plot_feed_map(advice, stage / f"{name}_feed_frequency_map.png")
    if markdown is not None:
        write_atomic(Path(markdown), advice_markdown(advices, command))
    return advices


def _session(runner: str, points_run: int, advices: list[Advice], start: float, interrupted: bool) -> dict[str, Any]:
    """One session of an advice, for its checkpoint (as a calibration records its sessions)."""
    return {"finished": datetime.now(timezone.utc).isoformat(timespec="seconds"), "runner": runner,
            "interrupted": interrupted, "points_run": points_run,
            "points_replayed": sum(advice.replayed for advice in advices), "rocks_done": len(advices),
            "wall_time_s": round(time.perf_counter() - start, 3)}


def _call(source: str, bounds: dict[str, tuple[float, ...]], metric: str, rocks: list[str] | None,
          power_kw: float | None, max_thrust_ratio: float, search: AdviceSearch, out: str | Path | None,
          max_rod_stress_pa: float | None = None) -> str:
    """The library call as the report names it."""
    stress = "" if max_rod_stress_pa is None else f", max_rod_stress_pa={max_rod_stress_pa!r}"
    return (f"rpdrill.advise({source!r}, {bounds!r}, metric={metric!r}, rocks={rocks!r}, power_kw={power_kw!r}, "
            f"max_thrust_ratio={max_thrust_ratio!r}, search={search!r}, out={None if out is None else str(out)!r}"
            f"{stress})")


def _extension_parameter(path: str, scene: Scene) -> bool:
    """Whether ``path`` is ``extensions.NAME.parameters.KEY`` of an extension of ``scene``."""
    parts = path.split(".")
    return len(parts) == 4 and parts[0] == "extensions" and parts[2] == "parameters" and \
        parts[1] in (scene.extensions or {})


__all__ = ["Advice", "AdviceSearch", "advise_scene"]
