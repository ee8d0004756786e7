"""A study with ``steady_state: continuation``: its points' periodic orbits followed along one scan axis.

The points that share every other axis value form a chain, ordered along ``continuation_axis`` (default:
the first scan axis; the axes zipped with it change along with it). Each chain is one task for a worker,
which runs it twice, up the axis and down it (models.steady.continuation: each orbit's Newton from its
neighbours'; every point with ``solver.steady_state: periodic``, the time run where no orbit is found).
The pass up gives the results table's rows; ``continuation.csv`` holds both passes point by point
(regime, blows, |mu|max and the first metric each way), ``bifurcations.csv`` what changed between
neighbouring points of each pass (period doubling, fold, torus, grazing, regime; ``point_from``,
``point_to``: the two points), the values where the two passes end on different orbits (``hysteresis``:
coexisting attractors) and the points whose orbit the drill does not reach from the scene's start
(``coexisting``: ``start_regime`` in continuation.csv says what it reaches; models.steady.start_check).

**Resumable, a chain at a time** (:func:`continuation_table`): the chains run as the results table's tasks
(studies.runtime.resumable.run_tables, a chain one task whose outcome gives the rows of its points), so
``study.json`` is written before any runs, and as each chain returns its lines of ``continuation.csv`` and
``bifurcations.csv`` are appended, then its rows of ``results.csv``. A chain is done when every one of its
points has a row and a line in ``continuation.csv``; a rerun keeps the done chains' lines of the two files and
rows, drops the rest (a chain cut by a kill or Ctrl-C; every chain where a file is missing or has other
columns, as an earlier rpdrill's) and runs only the chains not done. So Ctrl-C keeps every chain finished and records the
session, a kill between two writes resumes, and a finished study run again runs nothing.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from ...models.solvers.simulation import Simulation
from ...models.steady.continuation import BranchPoint, Continuation, changes, coexisting, hysteresis
from ..runtime.output_files import atomic_file
from ..runtime.point_runs import run_followed
from ..runtime.resumable import Table
from ..runtime.tables import append_rows, read_text, write_rows
from .study import Study, StudyPoint

ChainTask = tuple[list[tuple[int, float, Simulation]], str]  # ([(index, value, simulation)], metric)
PASSES, CHANGES = "continuation.csv", "bifurcations.csv"


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

    def summary(outcome: dict[str, Any], orbit: BranchPoint) -> dict[str, Any]:
        return {"regime": outcome.get("regime", ""), "period_blows": outcome.get("period_blows"),
                "floquet_max_abs": outcome.get("floquet_max_abs"), metric: outcome.get(metric, math.nan),
                "start_regime": orbit.start_regime}

    found = [(direction, change) for direction, branch in (("up", branch_up), ("down", branch_down))
             for change in [*changes(branch), *coexisting(branch)]]
    return {"rows": {index: row for (index, _, _), row in zip(points, up, strict=True)},
            "passes": [(index, value, summary(a, p), summary(b, q)) for (index, value, _), a, b, p, q
                       in zip(points, up, down, branch_up, branch_down, strict=True)],
            "changes": [(direction, c.kind, c.low, c.high, c.detail) for direction, c in found],
            "hysteresis": hysteresis(branch_up, branch_down)}


def _files(study: Study) -> tuple[list[str], list[str]]:
    """The columns of continuation.csv and bifurcations.csv."""
    axis, metric = study.continuation_axis, study.spec.metrics[0]
    others = [name for name in study.points[0].values if name != axis]
    summary = ["regime", "period_blows", "floquet_max_abs", metric, "start_regime"]
    return (["point", axis, *others, *[f"{k}_up" for k in summary], *[f"{k}_down" for k in summary]],
            ["point_from", "point_to", *others, "pass", "kind", f"{axis}_from", f"{axis}_to", "detail"])


def _lines(study: Study, chained: dict[str, Any]) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """A chain's lines of continuation.csv (a point each) and bifurcations.csv (a change each)."""
    axis = study.continuation_axis
    first = chained["passes"][0][0]
    others = {k: v for k, v in study.points[first].values.items() if k != axis}
    at = {value: index for index, value, _, _ in chained["passes"]}  # (the axis's values are distinct)
    passes = [{"point": index, axis: value, **others, **{f"{k}_up": v for k, v in up.items()},
               **{f"{k}_down": v for k, v in down.items()}} for index, value, up, down in chained["passes"]]
    found = [{"point_from": at[low], "point_to": at[high], **others, "pass": direction, "kind": kind,
              f"{axis}_from": low, f"{axis}_to": high, "detail": detail}
             for direction, kind, low, high, detail in chained["changes"]]
    found += [{"point_from": at[value], "point_to": at[value], **others, "pass": "both", "kind": "hysteresis",
               f"{axis}_from": value, f"{axis}_to": value, "detail": "the passes up and down end on different orbits"}
              for value in chained["hysteresis"]]
    return passes, found


def _kept(path: Path, columns: list[str], keep: set[int]) -> list[list[str]]:
    """The whole lines of an earlier session's file whose first cell is a point of ``keep`` (the rest: chains
    not done, or a line cut by a kill)."""
    header, lines = read_text(path)
    if header != columns:
        return []
    return [cells for _, cells in lines if len(cells) == len(columns) and cells[0].isdigit() and int(cells[0]) in keep]


def _rewrite(path: Path, columns: list[str], lines: list[list[str]]) -> None:
    with atomic_file(path) as handle:
        write_rows(handle, columns, [dict(zip(columns, cells, strict=True)) for cells in lines], {}, header=True)


def continuation_table(study: Study, out: Path, columns: list[str]) -> Table:
    """The results table of a continuation study (module doc): a task a chain (:func:`follow_chain`), its outcome
    the rows of its points; continuation.csv and bifurcations.csv kept for the chains done and appended as each
    chain returns."""
    axis, metric = study.continuation_axis, study.spec.metrics[0]
    groups = chains(study)
    chain_of = {point.index: k for k, chain in enumerate(groups) for point in chain}
    passes, found = _files(study)

    def task(point: StudyPoint) -> ChainTask:
        return [(p.index, p.values[axis], p.simulation) for p in groups[chain_of[point.index]]], metric

    def resumed(done: set[int]) -> set[int]:
        """The chains done: every point with a row and a line in continuation.csv, both files of this study's
        columns (a file of another rpdrill's columns, or none, and every chain runs again); their lines kept,
        the files started with their header; the points of those chains."""
        formats = all(read_text(out / name)[0] == names for name, names in ((PASSES, passes), (CHANGES, found)))
        lines = {int(cells[0]) for cells in _kept(out / PASSES, passes, done)} if formats else set()
        whole = {p.index for chain in groups if all(q.index in done and q.index in lines for q in chain) for p in chain}
        for name, names in ((PASSES, passes), (CHANGES, found)):
            _rewrite(out / name, names, _kept(out / name, names, whole))
        return whole

    def taken(chained: dict[str, Any]) -> None:
        """A chain's lines, appended before its rows of the results table (module doc)."""
        lines = _lines(study, chained)
        for name, names, rows in ((PASSES, passes, lines[0]), (CHANGES, found, lines[1])):
            append_rows(out / name, names, rows, {})

    return Table(study, out, "results.csv", columns, task, follow_chain,
                 row=lambda point, chained: {"point": point.index, **point.values, **chained["rows"][point.index]},
                 scene_keys=[f"{study.hash} chain {chain_of[p.index]}" for p in study.points],
                 resumed=resumed, taken=taken, task_name="chain")


def sort_files(study: Study, out: Path) -> None:
    """continuation.csv in point order and bifurcations.csv by chain, as a finished study leaves them (a rerun
    appends chains in the order they return)."""
    passes, found = _files(study)
    order = {p.index: n for n, chain in enumerate(chains(study)) for p in chain}
    for name, names, key in ((PASSES, passes, lambda cells: int(cells[0])),
                             (CHANGES, found, lambda cells: order[int(cells[0])])):
        _rewrite(out / name, names, sorted(_kept(out / name, names, set(order)), key=key))
