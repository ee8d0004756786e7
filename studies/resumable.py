"""Resumable runs of many points into an output directory: a results table appended batch by batch,
and the provenance beside it.

``DIR/study.json`` records what produced the results (the study's hash, versions, the resolved
study, every session); ``DIR/<table>.csv`` gets the rows of each batch of points as it finishes
(studies.runners). A rerun
into the same directory keeps the complete rows (a row cut by a kill is dropped), runs only the
points without one, and refuses a study whose hash differs. Failed points count as finished
(their errors are in the table; delete their rows to retry them).

A study is anything with ``spec.name``, ``source``, ``hash``, ``points`` (each with ``index`` and
``parameters``) and ``resolved()``: studies.study.Study and studies.accuracy.AccuracyStudy.
"""

from __future__ import annotations

import csv
import importlib.metadata
import io
import json
import os
import sys
import time
from collections.abc import Callable, Sequence
from datetime import datetime, timezone
from pathlib import Path
from typing import Any, Protocol

from tqdm import tqdm

from rpdrill.studies.budgets import duration
from rpdrill.studies.interrupts import raise_if_stopped
from rpdrill.studies.loading import InputError
from rpdrill.studies.run_files import write_json
from rpdrill.studies.runners import Runner

STATUS_COLUMNS = ("status", "error", "wall_time_s")
RECORD = "study.json"
Row = dict[str, str]


class Point(Protocol):
    index: int
    parameters: dict[str, Any]
    cpu_s: float  # estimated (models.cost)


class ResumableStudy(Protocol):
    source: Path
    points: Sequence[Point]

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
             "points": len(study.points), "resolved_study": study.resolved(), "sessions": [], "point_wall_time_s": {}}
    return checked_record(out / RECORD, fresh, study.source, [out / table])


def finished_rows(path: Path, columns: list[str], count: int) -> dict[int, Row]:
    """Complete rows of earlier runs by point index; the file is rewritten with just those."""
    rows: dict[int, Row] = {}
    try:
        text = path.read_text(encoding="utf-8") if path.exists() else ""
        for row in csv.DictReader(io.StringIO(text[: text.rfind("\n") + 1], newline="")):  # drop a cut last line
            if list(row) == columns and None not in row.values() and row["status"] in ("ok", "failed") \
                    and row["point"].isdigit() and int(row["point"]) < count:
                rows.setdefault(int(row["point"]), row)
    except (UnicodeDecodeError, csv.Error) as error:
        raise InputError(f"--out: {path}: not a results table rpdrill wrote ({error}); use a new --out directory") \
            from None
    temporary = path.with_suffix(".csv.tmp")
    with temporary.open("w", newline="", encoding="utf-8") as handle:
        writer = csv.DictWriter(handle, columns)
        writer.writeheader()
        writer.writerows(rows[i] for i in sorted(rows))
    os.replace(temporary, path)
    return rows


def read_rows(path: Path) -> list[Row]:
    with path.open(newline="", encoding="utf-8") as handle:
        return list(csv.DictReader(handle))


def result_row(point: Point, outcome: dict[str, Any]) -> dict[str, Any]:
    """A table row: the point, its parameters, status, error, wall time and the outcome's metrics."""
    return {"point": point.index, **point.parameters, "status": outcome["status"], "error": outcome["error"],
            "wall_time_s": f"{outcome['wall_time_s']:.4g}", **outcome["metrics"]}


def run_points(study: ResumableStudy, out: Path, table: str, columns: list[str], task: Callable[[Point], Any],
               worker: Callable[[Any], dict[str, Any]], runner: tuple[str, Runner], quiet: bool,
               row: Callable[[dict[str, Any]], dict[str, Any]] | None = None) -> list[Row]:
    """Run every point of ``study`` without a finished row in ``out/table`` (module doc): ``task(point)``
    is what ``worker`` receives, ``row(outcome)`` the table row of its outcome (default
    :func:`result_row`). Prints what it runs, shows progress, records the session; returns all rows."""
    out.mkdir(parents=True, exist_ok=True)
    record = provenance(study, out, table)
    write_json(out / RECORD, record)
    path = out / table
    done = finished_rows(path, columns, len(study.points))
    todo = [p for p in study.points if p.index not in done]
    label, run = runner
    name = study.spec.name
    print(f"{name}: {len(study.points)} points, {len(done)} finished earlier, running {len(todo)} on {label} "
          f"(estimated {duration(sum(p.cpu_s for p in todo))} of CPU)", file=sys.stderr)
    to_row = row or (lambda outcome: result_row(study.points[outcome["point"]], outcome))
    start, ran = time.perf_counter(), 0
    try:
        with path.open("a", newline="", encoding="utf-8") as handle, \
                tqdm(total=len(study.points), initial=len(done), desc=name, unit="point", disable=quiet) as bar:
            writer = csv.DictWriter(handle, columns)
            for batch in run(worker, [task(p) for p in todo]) if todo else ():  # a batch's rows, then one flush
                raise_if_stopped()  # points cut by the interrupt are not results
                writer.writerows(to_row(outcome) for outcome in batch)
                handle.flush()
                ran += len(batch)
                bar.update(len(batch))
    except KeyboardInterrupt:  # Ctrl-C or SIGTERM (studies.cli): the finished rows stay, the session is recorded
        _record_session(record, out, path, label, ran, start, interrupted=True)
        raise
    return _record_session(record, out, path, label, ran, start, interrupted=False)


def _record_session(record: dict[str, Any], out: Path, path: Path, label: str, ran: int, start: float,
                    interrupted: bool) -> list[Row]:
    """Add this session (and every point's wall time) to the record in out/study.json; the rows."""
    rows = read_rows(path)
    record["sessions"].append({"finished": datetime.now(timezone.utc).isoformat(timespec="seconds"),
                               "runner": label, "points_run": ran, "interrupted": interrupted,
                               "wall_time_s": round(time.perf_counter() - start, 3)})
    record["point_wall_time_s"] = {r["point"]: float(r["wall_time_s"]) for r in sorted(rows, key=lambda r: int(r["point"]))}
    write_json(out / RECORD, record)
    return rows
