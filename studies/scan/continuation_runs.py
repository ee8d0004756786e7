"""A study with ``steady_state: continuation``: its points' periodic orbits followed along one scan axis.

The points that share every other axis value form a chain, ordered along ``continuation_axis`` (default:
the first scan axis; the axes zipped with it change along with it). Each chain is one task for a worker,
which runs it twice, up the axis and down it (models.steady.continuation: each orbit's Newton from its
neighbours'; every point with ``solver.steady_state: periodic``, the time run where no orbit is found).
The pass up gives the results table's rows; ``continuation.csv`` holds both passes point by point
(regime, blows, |mu|max and the first metric each way), ``bifurcations.csv`` what changed between
neighbouring points of each pass (period doubling, fold, torus, grazing, regime) and the values where the
two passes end on different orbits (``hysteresis``: coexisting attractors).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from ...models.solvers.simulation import Simulation
from ...models.steady.continuation import BranchPoint, Continuation, branch_point, changes, hysteresis
from ..runtime.output_files import write_rows_csv
from ..runtime.point_runs import run_prepared
from ..runtime.pools import Runner
from .study import Study, StudyPoint

ChainTask = tuple[str, list[tuple[int, float, Simulation]], str]  # (axis, [(index, value, simulation)], metric)


def chains(study: Study) -> list[list[StudyPoint]]:
    """The study's points grouped by every axis but the continuation axis (and those zipped with it),
    each group ordered along it."""
    axis = study.continuation_axis
    moving = set(study.zipped_with(axis))
    groups: dict[str, list[StudyPoint]] = {}
    for point in study.points:
        key = repr(sorted((name, value) for name, value in point.parameters.items() if name not in moving))
        groups.setdefault(key, []).append(point)
    return [sorted(group, key=lambda p: p.parameters[axis]) for group in groups.values()]


def _pass(axis: str, points: list[tuple[int, float, Simulation]], metric: str
          ) -> tuple[list[dict[str, Any]], list[BranchPoint]]:
    """One pass along the chain: each point's outcome (studies.runtime.point_runs.run_prepared) and orbit."""
    branch, outcomes = Continuation(), []
    for index, value, simulation in points:
        outcome, result = run_prepared(index, simulation, branch.guess(value), branch.cold_newton)
        outcomes.append(outcome)
        advance = math.nan
        if result is not None:
            advance = outcome["metrics"].get("advance_per_blow_m", math.nan)
        branch.add(branch_point(value, {} if result is None else result.info, advance))
    return outcomes, branch.points


def follow_chain(task: ChainTask) -> dict[str, Any]:
    """Worker: a chain up and down its axis (module doc): the outcomes of the pass up, both passes'
    summaries, their changes and the hysteresis values."""
    axis, points, metric = task
    up, branch_up = _pass(axis, points, metric)
    down, branch_down = _pass(axis, points[::-1], metric)
    down, branch_down = down[::-1], branch_down[::-1]

    def summary(outcome: dict[str, Any]) -> dict[str, Any]:
        return {"regime": outcome.get("regime", ""), "period_blows": outcome.get("period_blows"),
                "floquet_max_abs": outcome.get("floquet_max_abs"), metric: outcome["metrics"].get(metric, math.nan)}

    found = [(direction, change) for direction, branch in (("up", branch_up), ("down", branch_down))
             for change in changes(branch)]
    return {"outcomes": up, "passes": [(index, value, summary(a), summary(b))
                                       for (index, value, _), a, b in zip(points, up, down, strict=True)],
            "changes": [(direction, c.kind, c.low, c.high, c.detail) for direction, c in found],
            "hysteresis": hysteresis(branch_up, branch_down)}


def follow_study(study: Study, out: Path, runner: tuple[str, Runner]) -> dict[int, dict[str, Any]]:
    """Every chain of the study followed on the runner (module doc); writes ``continuation.csv`` and
    ``bifurcations.csv`` into ``out``; each point's outcome of the pass up, by point index."""
    axis, metric = study.continuation_axis, study.spec.metrics[0]
    tasks = [(axis, [(p.index, p.parameters[axis], p.simulation) for p in chain], metric) for chain in chains(study)]
    outcomes, passes, found = {}, [], []
    for batch in runner[1](follow_chain, tasks) if tasks else ():
        for chained in batch:
            outcomes.update({outcome["point"]: outcome for outcome in chained["outcomes"]})
            for index, value, up, down in chained["passes"]:
                others = {k: v for k, v in study.points[index].parameters.items() if k != axis}
                passes.append({"point": index, axis: value, **others, **{f"{k}_up": v for k, v in up.items()},
                               **{f"{k}_down": v for k, v in down.items()}})
            others = {k: v for k, v in study.points[chained["passes"][0][0]].parameters.items() if k != axis}
            found += [{**others, "pass": direction, "kind": kind, f"{axis}_from": low, f"{axis}_to": high,
                       "detail": detail} for direction, kind, low, high, detail in chained["changes"]]
            found += [{**others, "pass": "both", "kind": "hysteresis", f"{axis}_from": value, f"{axis}_to": value,
                       "detail": "the passes up and down end on different orbits"} for value in chained["hysteresis"]]
    out.mkdir(parents=True, exist_ok=True)
    write_rows_csv(out / "continuation.csv", sorted(passes, key=lambda row: row["point"]))
    columns = [*[k for k in study.points[0].parameters if k != axis], "pass", "kind", f"{axis}_from", f"{axis}_to",
               "detail"]
    write_rows_csv(out / "bifurcations.csv", found, columns)
    return outcomes


def given_outcome(outcome: dict[str, Any]) -> dict[str, Any]:
    """Worker of the results table of a continuation study: the outcome its chain gave (module doc)."""
    return outcome
