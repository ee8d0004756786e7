"""Resumable runs of many points into an output directory: a results table appended batch by batch,
and the provenance beside it.

``DIR/study.json`` records what produced the results (the study's hash, versions, the resolved
study, every session); ``DIR/<table>.csv`` gets the rows of each batch of points as it finishes
(studies.runtime.pools). A rerun
into the same directory keeps the complete rows (a row cut by a kill is dropped), runs only the
points without one, and refuses a study whose hash differs. Failed points count as finished
(their errors are in the table; delete their rows to retry them). Several tables run as one: their
points go to the workers together, and a point whose scene equals another's (by resolved scene,
studies.scan.study.Study.scene_keys: the formulations are deterministic; the paper's impulse scan repeats
the frequency scan's 23 points at 220 kN) runs once, its outcome written to both.

A study is anything with ``spec.name``, ``source``, ``hash``, ``points`` (each with ``index`` and
``parameters``) and ``resolved()``: studies.scan.study.Study and studies.accuracy.accuracy_study.AccuracyStudy.
"""

from __future__ import annotations

import csv
import importlib.metadata
import io
import json
import math
import sys
import time
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from datetime import datetime, timezone
from pathlib import Path
from typing import Any, Protocol

from tqdm import tqdm

from ...models.evaluation.run_status import STATUSES
from ..inputs.reading import InputError, short
from .budgets import duration
from .interrupts import raise_if_stopped
from .output_files import atomic_file, write_json
from .pools import Runner

STATUS_COLUMNS = ("status", "error", "steady_state", "regime", "wall_time_s", "period_blows", "floquet_max_abs")
# a finished point's status: ok; failed (its error says why); unstable, unsettled, not_finite or
# unbalanced (metrics written, but the run's figures do not stand as they are: models.evaluation.run_status)
FINISHED = ("failed", *STATUSES)
RECORD = "study.json"
Row = dict[str, str]


class TablePoint(Protocol):
    index: int
    parameters: dict[str, Any]
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
        for kind, found in ({} if simulation is None else simulation.code_records()).items():
            if kind == "extensions":
                records.setdefault(kind, {}).update({name: {key: value for key, value in record.items()
                                                            if key != "parameters"} for name, record in found.items()})
            else:
                records.setdefault(kind, found)
    return records


def _is_finite(text: str) -> bool:
    try:
        return math.isfinite(float(text))
    except ValueError:
        return False


def damage(row: Row, columns: list[str], points: Sequence[TablePoint]) -> str | None:
    """Why a finished row of a table is not one rpdrill wrote for its point (None: it is): its columns,
    status and point index; its parameters those of the point; its wall time and every column after it
    (the metrics) a finite number, or empty (rpdrill writes a metric that is not a finite number as empty:
    an edited 'inf' is damage)."""
    if list(row) != columns or None in row.values():
        return "not the table's columns"
    if not row["point"].isdigit() or int(row["point"]) >= len(points):
        return f"point {short(row['point'])}: not a point of the study"
    if row["status"] not in FINISHED:
        return f"status {short(row['status'])}: not one of {', '.join(FINISHED)}"
    point = points[int(row["point"])]
    for name in columns:
        if name in point.parameters and row[name] != str(point.parameters[name]):
            return f"{name} {short(row[name])}: the point's is {short(point.parameters[name])}"
    numeric = columns[columns.index("wall_time_s"):] if "wall_time_s" in columns else []
    bad = next((name for name in numeric if row[name] != "" and not _is_finite(row[name])), None)
    return None if bad is None else f"{bad} {short(row[bad])}: not a finite number"


def finished_rows(path: Path, columns: list[str], points: Sequence[TablePoint]) -> dict[int, Row]:
    """Complete rows of earlier runs by point index; the file is rewritten with just those. A row cut
    by a kill is dropped; a damaged or edited row (:func:`damage`) too, said once in a warning (its
    point runs again)."""
    rows: dict[int, Row] = {}
    damaged: list[str] = []
    try:
        text = path.read_text(encoding="utf-8") if path.exists() else ""
        for line, row in enumerate(csv.DictReader(io.StringIO(text[: text.rfind("\n") + 1], newline="")), 2):
            why = damage(row, columns, points)
            if why is None:
                rows.setdefault(int(row["point"]), row)
            else:
                damaged.append(f"line {line}: {why}")
    except (UnicodeDecodeError, csv.Error, OSError) as error:
        why = error.strerror if isinstance(error, OSError) and error.strerror else error
        raise InputError(f"--out: {path}: not a results table rpdrill wrote ({why}); use a new --out directory") \
            from None
    if damaged:
        more = f" and {len(damaged) - 3} more" if len(damaged) > 3 else ""
        warnings.warn(f"{path}: {len(damaged)} row(s) damaged or edited, dropped and their points run again "
                      f"({'; '.join(damaged[:3])}{more})", stacklevel=2)
    with atomic_file(path) as handle:
        writer = csv.DictWriter(handle, columns)
        writer.writeheader()
        writer.writerows(rows[i] for i in sorted(rows))
    return rows


def read_rows(path: Path) -> list[Row]:
    with path.open(newline="", encoding="utf-8") as handle:
        return list(csv.DictReader(handle))


def result_row(point: TablePoint, outcome: dict[str, Any]) -> dict[str, Any]:
    """A table row: the point, its parameters, status, error, wall time and the outcome's metrics (empty
    where not a finite number: its status says so, models.evaluation.run_status)."""
    return {"point": point.index, **point.parameters, "status": outcome["status"], "error": outcome["error"],
            "steady_state": outcome.get("steady_state", ""), "regime": outcome.get("regime", ""),
            "wall_time_s": f"{outcome['wall_time_s']:.4g}", "period_blows": cell(outcome.get("period_blows")),
            "floquet_max_abs": cell(outcome.get("floquet_max_abs")), **{k: cell(v) for k, v in outcome["metrics"].items()}}


def cell(value: Any) -> Any:
    """A table's cell of a value: empty where it is not a finite number (NaN, infinite; also as text)."""
    try:
        return value if math.isfinite(float(value)) else ""
    except (TypeError, ValueError):
        return value


@dataclass
class Table:
    """One study's points and where their results go: ``out/table`` with ``columns``; ``task(point)`` is
    what ``worker`` receives, ``row(outcome)`` the table row of its outcome (default :func:`result_row`,
    the outcome's ``point`` its index). ``scene_keys``: each point's scene, when points of equal keys
    give equal results (module doc; the worker's outcome then names its point by index)."""

    study: ResumableStudy
    out: Path
    table: str
    columns: list[str]
    task: Callable[[TablePoint], Any]
    worker: Callable[[Any], dict[str, Any]]
    row: Callable[[dict[str, Any]], dict[str, Any]] | None = None
    scene_keys: Sequence[str] | None = None

    def to_row(self, outcome: dict[str, Any]) -> dict[str, Any]:
        return self.row(outcome) if self.row else result_row(self.study.points[outcome["point"]], outcome)


def run_tagged(item: tuple[Callable[[Any], Any], int, Any]) -> tuple[int, Any]:
    """Worker: ``(worker, tag, task)`` -> ``(tag, worker(task))``, so that an outcome finds its points."""
    worker, tag, task = item
    return tag, worker(task)


def run_tables(tables: Sequence[Table], runner: tuple[str, Runner], quiet: bool,
               finished: Callable[[int, list[Row]], None] = lambda index, rows: None) -> list[list[Row]]:
    """Run the points of every table without a finished row (module doc) in one call of ``runner``, so
    that the workers go from one study's points to the next without waiting; each batch's rows are
    appended to their tables as it completes; a point whose scene key equals another's runs once and
    its outcome goes to both. ``finished(i, rows)`` is called as soon as table ``i`` is complete (in
    this process, while the workers go on), with its rows in point order. Prints what it runs, shows
    progress, records each table's session; returns every table's rows."""
    label, run = runner
    records, remaining = [], []
    tasks: list[tuple[Callable[[Any], Any], int, Any]] = []
    targets: list[list[tuple[int, int]]] = []  # per task: the (table, point index) its outcome goes to
    task_of: dict[Any, int] = {}  # scene key -> task
    for i, job in enumerate(tables):
        job.out.mkdir(parents=True, exist_ok=True)
        records.append(provenance(job.study, job.out, job.table))
        write_json(job.out / RECORD, records[-1])
        done = finished_rows(job.out / job.table, job.columns, job.study.points)
        todo = [p for p in job.study.points if p.index not in done]
        runs = []
        for point in todo:
            key = job.scene_keys[point.index] if job.scene_keys is not None else (i, point.index)
            if key not in task_of:
                task_of[key] = len(tasks)
                tasks.append((job.worker, len(tasks), job.task(point)))
                targets.append([])
                runs.append(point)
            targets[task_of[key]].append((i, point.index))
        remaining.append(len(todo))
        same = f"{len(todo) - len(runs)} the same as another point (run once), " if len(runs) < len(todo) else ""
        print(f"{job.study.spec.name}: {len(job.study.points)} points, {len(done)} finished earlier, {same}running "
              f"{len(runs)} on {label} (estimated {duration(sum(p.cpu_s for p in runs))} of CPU)", file=sys.stderr)
    rows: list[list[Row] | None] = [None] * len(tables)
    ran, copied = [0] * len(tables), [0] * len(tables)  # points written: run for the table, or copied to it
    start = time.perf_counter()

    def complete(i: int, interrupted: bool = False) -> None:
        rows[i] = _record_session(records[i], tables[i].out, tables[i].out / tables[i].table, label, ran[i],
                                  copied[i], start, interrupted)
        if not interrupted:
            finished(i, rows[i])

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
                for tag, outcome in batch:
                    for n, (i, index) in enumerate(targets[tag]):
                        by_table.setdefault(i, []).append({**outcome, "point": index} if tables[i].scene_keys
                                                          is not None else outcome)
                        first[i] = first.get(i, 0) + (n == 0)
                for i, outcomes in by_table.items():  # a batch's rows, then one flush per table
                    with (tables[i].out / tables[i].table).open("a", newline="", encoding="utf-8") as handle:
                        csv.DictWriter(handle, tables[i].columns).writerows(map(tables[i].to_row, outcomes))
                    ran[i] += first.get(i, 0)
                    copied[i] += len(outcomes) - first.get(i, 0)
                    remaining[i] -= len(outcomes)
                    bar.update(len(outcomes))
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
            if rows[i] is None:
                complete(i, interrupted=True)
        raise
    return [r for r in rows if r is not None]


def run_points(study: ResumableStudy, out: Path, table: str, columns: list[str], task: Callable[[TablePoint], Any],
               worker: Callable[[Any], dict[str, Any]], runner: tuple[str, Runner], quiet: bool,
               row: Callable[[dict[str, Any]], dict[str, Any]] | None = None) -> list[Row]:
    """:func:`run_tables` of one study: its rows."""
    return run_tables([Table(study, out, table, columns, task, worker, row)], runner, quiet)[0]


def _record_session(record: dict[str, Any], out: Path, path: Path, label: str, ran: int, copied: int,
                    start: float, interrupted: bool) -> list[Row]:
    """Add this session (and every point's wall time) to the record in out/study.json; the rows in point
    order (the table holds them in the order they finished)."""
    rows = sorted(read_rows(path), key=lambda r: int(r["point"]))
    record["sessions"].append({"finished": datetime.now(timezone.utc).isoformat(timespec="seconds"),
                               "runner": label, "points_run": ran, "points_copied": copied,
                               "interrupted": interrupted, "wall_time_s": round(time.perf_counter() - start, 3)})
    record["point_wall_time_s"] = {r["point"]: float(r["wall_time_s"]) for r in rows}
    write_json(out / RECORD, record)
    return rows
