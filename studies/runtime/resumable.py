"""Resumable runs of many points into an output directory: a results table appended batch by batch,
and the provenance beside it.

``DIR/study.json`` records what produced the results (the study's hash, versions, the resolved
study, every session); ``DIR/<table>.csv`` gets the rows of each batch of points as it finishes
(studies.runtime.pools; the file format and its reader: studies.runtime.tables). A rerun
into the same directory keeps the complete rows (a row cut by a kill is dropped), runs only the
points without one, and refuses a study whose hash differs. Failed points count as finished
(their errors are in the table; delete their rows to retry them). Several tables run as one: their
points go to the workers together, and a point whose scene equals another's (by resolved scene,
studies.scan.study.Study.scene_keys: the formulations are deterministic; the paper's impulse scan repeats
the frequency scan's 23 points at 220 kN) runs once, its outcome written to both. Each table comes
back as a typed pandas DataFrame (studies.runtime.tables.read_table: what its file holds), one row a
point in point order.

A study is anything with ``spec.name``, ``source``, ``hash``, ``points`` (each with ``index``, the
``values`` its row starts with, and ``cpu_s``) and ``resolved()``: studies.scan.study.Study,
studies.accuracy.accuracy_study.AccuracyStudy, studies.sensitivity.sensitivity_study.SensitivityStudy.
"""

from __future__ import annotations

import importlib.metadata
import json
import sys
import time
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

from tqdm import tqdm

from ..inputs.reading import InputError, short
from .budgets import duration
from .interrupts import raise_if_stopped
from .output_files import atomic_file, write_json
from .point_runs import FINISHED
from .pools import Runner
from .tables import append_rows, cell_text, is_finite, read_table, read_text, write_rows

if TYPE_CHECKING:
    import pandas as pd

RECORD = "study.json"
WALL_TIME_FORMAT = ".4g"


class TablePoint(Protocol):
    index: int
    values: Mapping[str, Any]  # the cells its row starts with (a scan point's axis values)
    cpu_s: float  # estimated (models.solvers.cost)


class ResumableStudy(Protocol):
    source: Path
    points: Sequence[TablePoint]

    @property
    def spec(self) -> Any: ...
    @property
    def hash(self) -> str: ...
    def resolved(self) -> dict[str, Any]: ...


def checked_record(path: Path, fresh: dict[str, Any], source: Path, results: list[Path],
                   overwrite: bool = False) -> dict[str, Any]:
    """The record (JSON) at ``path`` when it has ``fresh``'s hash, else ``fresh`` for a new run;
    InputError when it holds another hash (another study into the same directory), is not a record,
    or when ``results`` exist without a record, unless ``overwrite`` (then ``fresh``: the run starts
    afresh)."""
    out = path.parent
    if not path.exists():
        found = [r.name for r in results if r.exists()]
        if found and not overwrite:
            raise InputError(f"{out}: holds {', '.join(found)} but no {path.name}; use a new --out directory")
        return fresh
    record = _read_record(path, refuse=not overwrite)
    if record.get("hash") == fresh["hash"]:
        return record
    if overwrite:
        return fresh
    raise InputError(
        f"{source}: differs from the run whose results are in {out} (hash {fresh['hash'][:12]} vs "
        f"{str(record.get('hash'))[:12]}); use a new --out directory or delete the old one")


def _read_record(path: Path, refuse: bool) -> dict[str, Any]:
    """The JSON mapping in a record file; when it is not one, InputError naming it (``refuse``) or {}."""
    try:
        record = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as error:
        record = error
    if isinstance(record, dict):
        return record
    if refuse:
        raise InputError(f"--out: {path}: not a record rpdrill wrote ({record}); use a new --out directory")
    return {}


def provenance(study: ResumableStudy, out: Path, table: str) -> dict[str, Any]:
    """study.json as found in ``out`` (refused if from another study) or a new one."""
    fresh = {"study": study.spec.name, "study_file": str(study.source), "hash": study.hash,
             "rpdrill_version": importlib.metadata.version("rpdrill"),
             "exudyn_version": importlib.metadata.version("exudyn"),
             "points": len(study.points), "resolved_study": study.resolved(), "sessions": [], "point_wall_time_s": {},
             **code_records(study.points)}
    return checked_record(out / RECORD, fresh, study.source, [out / table])


def code_records(points: Sequence[Any]) -> dict[str, Any]:
    """The code of one's own the points import (models.solvers.simulation.Simulation.code_records): every
    extension by name (import path, package and version where it has one, file) and a rock law of one's own,
    over all points (their parameters left out: the results table holds the scanned ones)."""
    records: dict[str, Any] = {}
    for point in points:
        simulation = getattr(point, "simulation", None)
        for kind, found in ({} if simulation is None else simulation.code_records().as_dict()).items():
            if kind == "extensions":
                records.setdefault(kind, {}).update({name: {key: value for key, value in record.items()
                                                            if key != "parameters"} for name, record in found.items()})
            else:
                records.setdefault(kind, found)
    return records


def damage(cells: list[str], header: list[str], columns: list[str], points: Sequence[TablePoint],
           text: Sequence[str] = (), formats: Mapping[str, str] | None = None) -> str | None:
    """Why a finished row of a table is not one rpdrill wrote for its point (None: it is): its columns,
    status and point index; its starting values those of the point (in the column's ``formats``); its
    wall time and every column after it (the metrics) but the ``text`` ones a finite number, or empty
    (rpdrill writes a value that is not a finite number as empty: an edited 'inf' is damage)."""
    if header != columns or len(cells) != len(columns):
        return "not the table's columns"
    row = dict(zip(columns, cells, strict=True))
    if not row["point"].isdigit() or int(row["point"]) >= len(points):
        return f"point {short(row['point'])}: not a point of the study"
    if row["status"] not in FINISHED:
        return f"status {short(row['status'])}: not one of {', '.join(FINISHED)}"
    point = points[int(row["point"])]
    for name in columns:
        if name in point.values and row[name] != cell_text(point.values[name], (formats or {}).get(name)):
            return f"{name} {short(row[name])}: the point's is {short(point.values[name])}"
    numeric = [name for name in columns[columns.index("wall_time_s"):] if name not in text] \
        if "wall_time_s" in columns else []
    bad = next((name for name in numeric if row[name] != "" and not is_finite(row[name])), None)
    return None if bad is None else f"{bad} {short(row[bad])}: not a finite number"


def finished_rows(path: Path, columns: list[str], points: Sequence[TablePoint], text: Sequence[str] = (),
                  formats: Mapping[str, str] | None = None) -> set[int]:
    """The points of earlier runs with a complete row; the file is rewritten with just those rows, in
    point order. A row cut by a kill is dropped; a damaged or edited row (:func:`damage`) too, said once
    in a warning (its point runs again)."""
    header, lines = read_text(path)
    rows: dict[int, list[str]] = {}
    damaged: list[str] = []
    for line, cells in lines:
        why = damage(cells, header, columns, points, text, formats)
        if why is None:
            rows.setdefault(int(cells[0]), cells)
        else:
            damaged.append(f"line {line}: {why}")
    if damaged:
        more = f" and {len(damaged) - 3} more" if len(damaged) > 3 else ""
        warnings.warn(f"{path}: {len(damaged)} row(s) damaged or edited, dropped and their points run again "
                      f"({'; '.join(damaged[:3])}{more})", stacklevel=2)
    with atomic_file(path) as handle:
        write_rows(handle, columns, [dict(zip(columns, rows[i], strict=True)) for i in sorted(rows)], {}, header=True)
    return set(rows)


def _keep_rows(path: Path, columns: list[str], kept: set[int]) -> set[int]:
    """The rows of ``kept`` points of a table's file (rewritten by :func:`finished_rows`), the rest dropped."""
    _, lines = read_text(path)
    rows = [cells for _, cells in lines if int(cells[0]) in kept]
    with atomic_file(path) as handle:
        write_rows(handle, columns, [dict(zip(columns, cells, strict=True)) for cells in rows], {}, header=True)
    return {int(cells[0]) for cells in rows}


def point_row(point: TablePoint, outcome: Mapping[str, Any]) -> dict[str, Any]:
    """A table row: the point's index, its values, then what its run returned."""
    return {"point": point.index, **point.values, **outcome}


@dataclass
class Table:
    """One study's points and where their results go: ``out/table`` with ``columns``; ``task(point)`` is
    what ``worker`` receives, its outcome (column -> value: status, error, wall time, metrics) completed
    into the point's row by ``row(point, outcome)`` (default :func:`point_row`). ``formats``: number
    formats of columns in the file (wall time: 4 digits); ``text``: columns that hold text even where
    they read as numbers or are empty (studies.runtime.tables.typed). ``scene_keys``: each point's scene,
    when points of equal keys give equal results (module doc); a task's outcome then gives the rows of every
    point of its key (a continuation's chain: studies.scan.continuation_runs). ``resumed(done)``: told the points
    with a finished row before any runs, it gives back those to keep (the others run again: their files beside
    the table do not hold them); ``taken(outcome)``: each outcome before its rows are appended (files of
    the study's own beside the table, written first so that a table's row means they hold its point)."""

    study: ResumableStudy
    out: Path
    table: str
    columns: list[str]
    task: Callable[[TablePoint], Any]
    worker: Callable[[Any], dict[str, Any]]
    row: Callable[[TablePoint, dict[str, Any]], dict[str, Any]] = point_row
    formats: dict[str, str] = field(default_factory=dict)
    text: Sequence[str] = ()
    scene_keys: Sequence[str] | None = None
    resumed: Callable[[set[int]], set[int]] | None = None
    taken: Callable[[Any], None] | None = None
    task_name: str | None = None  # a task's name when one task runs every point of its key ("chain"), not copies

    def number_formats(self) -> dict[str, str]:
        return {"wall_time_s": WALL_TIME_FORMAT, **self.formats}


def run_tagged(item: tuple[Callable[[Any], Any], int, Any]) -> tuple[int, Any]:
    """Worker: ``(worker, tag, task)`` -> ``(tag, worker(task))``, so that an outcome finds its points."""
    worker, tag, task = item
    return tag, worker(task)


def run_tables(tables: Sequence[Table], runner: tuple[str, Runner], quiet: bool,
               finished: Callable[[int, pd.DataFrame, dict[str, Any]], None] = lambda index, table, record: None
               ) -> list[pd.DataFrame]:
    """Run the points of every table without a finished row (module doc) in one call of ``runner``, so
    that the workers go from one study's points to the next without waiting; each batch's rows are
    appended to their tables as it completes; a point whose scene key equals another's runs once and
    its outcome goes to both. ``finished(i, table, record)`` is called as soon as table ``i`` is complete (in
    this process, while the workers go on), with the table in point order and its record as written to
    ``study.json``. Prints what it runs, shows
    progress, records each table's session; returns every table (typed DataFrames)."""
    label, run = runner
    records, remaining = [], []
    tasks: list[tuple[Callable[[Any], Any], int, Any]] = []
    targets: list[list[tuple[int, int]]] = []  # per task: the (table, point index) its outcome goes to
    task_of: dict[Any, int] = {}  # scene key -> task
    for i, job in enumerate(tables):
        job.out.mkdir(parents=True, exist_ok=True)
        records.append(provenance(job.study, job.out, job.table))
        write_json(job.out / RECORD, records[-1])
        done = finished_rows(job.out / job.table, job.columns, job.study.points, job.text, job.number_formats())
        if job.resumed is not None:
            kept = job.resumed(done)
            if kept != done:  # rows whose files beside the table do not hold their points: run again
                done = _keep_rows(job.out / job.table, job.columns, kept)
        todo = [p for p in job.study.points if p.index not in done]
        runs, keys = [], set()
        for point in todo:
            key = job.scene_keys[point.index] if job.scene_keys is not None else (i, point.index)
            keys.add(key)
            if key not in task_of:
                task_of[key] = len(tasks)
                tasks.append((job.worker, len(tasks), job.task(point)))
                targets.append([])
                runs.append(point)
            elif job.task_name is not None:  # run by its key's task, not copied
                runs.append(point)
            targets[task_of[key]].append((i, point.index))
        remaining.append(len(todo))
        same = f"{len(todo) - len(runs)} the same as another point (run once), " if len(runs) < len(todo) else ""
        grouped = f" in {len(keys)} {job.task_name}(s)" if job.task_name is not None else ""
        print(f"{job.study.spec.name}: {len(job.study.points)} points, {len(done)} finished earlier, {same}running "
              f"{len(runs)}{grouped} on {label} (estimated {duration(sum(p.cpu_s for p in runs))} of CPU)",
              file=sys.stderr)
    frames: list[pd.DataFrame | None] = [None] * len(tables)
    ran, copied = [0] * len(tables), [0] * len(tables)  # points written: run for the table, or copied to it
    start = time.perf_counter()

    def complete(i: int, interrupted: bool = False) -> None:
        frames[i] = _record_session(records[i], tables[i], label, ran[i], copied[i], start, interrupted)
        if not interrupted:
            finished(i, frames[i], records[i])

    try:
        for i in range(len(tables)):
            if remaining[i] == 0:
                complete(i)
        names = ", ".join(job.study.spec.name for job in tables)
        with tqdm(total=sum(remaining), desc=names, unit="point", disable=quiet) as bar:
            def record(batch: list[tuple[int, dict[str, Any]]]) -> None:
                """Append a batch's rows to their tables."""
                by_table: dict[int, list[dict[str, Any]]] = {}
                first: dict[int, int] = {}  # per table: the outcomes of points run for it (the others copied)
                outcomes: dict[int, list[Any]] = {}  # per table: the outcomes its rows come from, once each
                for tag, outcome in batch:
                    for n, (i, index) in enumerate(targets[tag]):
                        job = tables[i]
                        by_table.setdefault(i, []).append(job.row(job.study.points[index], outcome))
                        first[i] = first.get(i, 0) + (n == 0 or job.task_name is not None)
                        if not any(taken is outcome for taken in outcomes.setdefault(i, [])):
                            outcomes[i].append(outcome)
                for i, rows in by_table.items():  # a batch's rows, then one flush per table
                    job = tables[i]
                    for outcome in outcomes[i] if job.taken is not None else ():
                        job.taken(outcome)
                    append_rows(job.out / job.table, job.columns, rows, job.number_formats())
                    ran[i] += first.get(i, 0)
                    copied[i] += len(rows) - first.get(i, 0)
                    remaining[i] -= len(rows)
                    bar.update(len(rows))
                    if remaining[i] == 0:
                        complete(i)

            outcomes = run(run_tagged, tasks) if tasks else iter(())
            try:
                for batch in outcomes:
                    raise_if_stopped()  # points cut by the interrupt are not results
                    record(batch)
            except KeyboardInterrupt:  # points the workers finished before the stop are (studies.runtime.pools)
                for batch in getattr(outcomes, "finished_now", list)():
                    record(batch)
                raise
    except KeyboardInterrupt:  # Ctrl-C or SIGTERM (studies.cli.main): the finished rows stay, the sessions are recorded
        for i in range(len(tables)):
            if frames[i] is None:
                complete(i, interrupted=True)
        raise
    return [frame for frame in frames if frame is not None]


def run_points(table: Table, runner: tuple[str, Runner], quiet: bool) -> pd.DataFrame:
    """:func:`run_tables` of one table: the typed table."""
    return run_tables([table], runner, quiet)[0]


def _record_session(record: dict[str, Any], table: Table, label: str, ran: int, copied: int, start: float,
                    interrupted: bool) -> pd.DataFrame:
    """Add this session (and every point's wall time) to the record in out/study.json; the table as its
    file holds it, in point order (the file holds the rows in the order they finished)."""
    frame, out = read_table(table.out / table.table, table.text), table.out
    record["sessions"].append({"finished": datetime.now(timezone.utc).isoformat(timespec="seconds"),
                               "runner": label, "points_run": ran, "points_copied": copied,
                               "interrupted": interrupted, "wall_time_s": round(time.perf_counter() - start, 3)})
    record["point_wall_time_s"] = {str(point): float(wall) for point, wall in zip(frame["point"], frame["wall_time_s"],
                                                                                   strict=True)}
    write_json(out / RECORD, record)
    return frame
