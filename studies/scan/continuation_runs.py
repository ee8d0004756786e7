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
from ...models.steady.continuation import BranchPoint, Continuation, changes, hysteresis
from ..runtime.output_files import write_rows_csv
from ..runtime.point_runs import run_followed
from ..runtime.pools import Runner
from .study import Study, StudyPoint

ChainTask = tuple[list[tuple[int, float, Simulation]], str]  # ([(index, value, simulation)], metric)


def chains(study: Study) -> list[list[StudyPoint]]:
    """The study's points grouped by every axis but the continuation axis (and those zipped with it),
    each group ordered along it."""
    axis = study.continuation_axis
    moving = set(study.zipped_with(axis))
    groups: dict[str, list[StudyPoint]] = {}
    for point in study.points:
        key = repr(sorted((name, value) for name, value in point.values.items() if name not in moving))
        groups.setdefault(key, []).append(point)
    return [sorted(group, key=lambda p: p.values[axis]) for group in groups.values()]


def _pass(points: list[tuple[int, float, Simulation]]) -> tuple[list[dict[str, Any]], list[BranchPoint]]:
    """One pass along the chain: each point's row (studies.runtime.point_runs.run_followed) and orbit."""
    branch = Continuation()
    return [run_followed(branch, value, simulation) for _, value, simulation in points], branch.points


def follow_chain(task: ChainTask) -> dict[str, Any]:
    """Worker: a chain up and down its axis (module doc): the rows of the pass up by point index, both
    passes' summaries, their changes and the hysteresis values."""
    points, metric = task
    up, branch_up = _pass(points)
    down, branch_down = _pass(points[::-1])
    down, branch_down = down[::-1], branch_down[::-1]

    def summary(outcome: dict[str, Any]) -> dict[str, Any]:
        return {"regime": outcome.get("regime", ""), "period_blows": outcome.get("period_blows"),
                "floquet_max_abs": outcome.get("floquet_max_abs"), metric: outcome.get(metric, math.nan)}

    found = [(direction, change) for direction, branch in (("up", branch_up), ("down", branch_down))
             for change in changes(branch)]
    return {"rows": {index: row for (index, _, _), row in zip(points, up, strict=True)}, "passes": [(index, value, summary(a), summary(b))
                                       for (index, value, _), a, b in zip(points, up, down, strict=True)],
            "changes": [(direction, c.kind, c.low, c.high, c.detail) for direction, c in found],
            "hysteresis": hysteresis(branch_up, branch_down)}


def follow_study(study: Study, out: Path, runner: tuple[str, Runner]) -> dict[int, dict[str, Any]]:
    """Every chain of the study followed on the runner (module doc); writes ``continuation.csv`` and
    ``bifurcations.csv`` into ``out``; each point's row of the pass up, by point index."""
    axis, metric = study.continuation_axis, study.spec.metrics[0]
    tasks = [([(p.index, p.values[axis], p.simulation) for p in chain], metric) for chain in chains(study)]
    rows, passes, found = {}, [], []
    for batch in runner[1](follow_chain, tasks) if tasks else ():
        for chained in batch:
            rows.update(chained["rows"])
            for index, value, up, down in chained["passes"]:
                others = {k: v for k, v in study.points[index].values.items() if k != axis}
                passes.append({"point": index, axis: value, **others, **{f"{k}_up": v for k, v in up.items()},
                               **{f"{k}_down": v for k, v in down.items()}})
            others = {k: v for k, v in study.points[chained["passes"][0][0]].values.items() if k != axis}
            found += [{**others, "pass": direction, "kind": kind, f"{axis}_from": low, f"{axis}_to": high,
                       "detail": detail} for direction, kind, low, high, detail in chained["changes"]]
            found += [{**others, "pass": "both", "kind": "hysteresis", f"{axis}_from": value, f"{axis}_to": value,
                       "detail": "the passes up and down end on different orbits"} for value in chained["hysteresis"]]
    out.mkdir(parents=True, exist_ok=True)
    write_rows_csv(out / "continuation.csv", sorted(passes, key=lambda row: row["point"]))
    columns = [*[k for k in study.points[0].values if k != axis], "pass", "kind", f"{axis}_from", f"{axis}_to",
               "detail"]
    write_rows_csv(out / "bifurcations.csv", found, columns)
    return rows


def given_row(row: dict[str, Any]) -> dict[str, Any]:
    """Worker of the results table of a continuation study: the row its chain gave (module doc)."""
    return row
