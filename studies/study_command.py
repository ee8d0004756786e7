"""Run a YAML study (a scan of scenes) on all cores or a Dask cluster.

Writes DIR/results.csv (one row per point, appended as points finish), DIR/study.json
(provenance) and the study's plots. Running again into the same DIR skips finished points;
a changed study is refused. Failed points count as finished (their errors are in results.csv;
delete their rows to retry them); the exit status is 1 when some failed.
"""

from __future__ import annotations

import argparse
import csv
import importlib.metadata
import io
import json
import os
import sys
import time
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

from tqdm import tqdm

from rpdrill.studies.loading import InputError
from rpdrill.studies.outputs import write_json
from rpdrill.studies.runners import select
from rpdrill.studies.study import Point, Study, load_study, run_point
from rpdrill.studies.study_plots import draw_plots

STATUS_COLUMNS = ("status", "error", "wall_time_s")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("study", help="study YAML file")
    parser.add_argument("--out", required=True, help="output directory (reused to resume)")
    parser.add_argument("--dask", nargs="?", const="", metavar="ADDRESS",
                        help="run on a Dask cluster at ADDRESS, or on a LocalCluster when no address is given")
    parser.add_argument("--workers", type=int, help="worker processes (default: all cores; 1: in this process)")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")


def _columns(study: Study) -> list[str]:
    return ["point", *study.axes, *STATUS_COLUMNS, *study.spec.metrics]


def study_provenance(study: Study, out: Path) -> dict[str, Any]:
    """study.json as found in ``out`` (refused if from another study) or a new one."""
    path = out / "study.json"
    if not path.exists():
        if (out / "results.csv").exists():
            raise InputError(f"{out}: holds results.csv but no study.json; use a new --out directory")
        return {"study": study.spec.name, "study_file": str(study.source), "hash": study.hash,
                "rpdrill_version": importlib.metadata.version("rpdrill"), "exudyn_version": importlib.metadata.version("exudyn"),
                "points": len(study.points), "resolved_study": study.resolved(),
                "sessions": [], "point_wall_time_s": {}}
    provenance = json.loads(path.read_text(encoding="utf-8"))
    if provenance.get("hash") != study.hash:
        raise InputError(
            f"{study.source}: the study differs from the one whose results are in {out} "
            f"(hash {study.hash[:12]} vs {str(provenance.get('hash'))[:12]}); "
            "use a new --out directory or delete the old one")
    return provenance


def finished_rows(path: Path, columns: list[str], count: int) -> dict[int, dict[str, str]]:
    """Complete rows of earlier runs by point index; the file is rewritten with just those."""
    text = path.read_text(encoding="utf-8") if path.exists() else ""
    rows: dict[int, dict[str, str]] = {}
    for row in csv.DictReader(io.StringIO(text[: text.rfind("\n") + 1], newline="")):  # drop a cut last line
        if list(row) == columns and None not in row.values() and row["status"] in ("ok", "failed") \
                and row["point"].isdigit() and int(row["point"]) < count:
            rows.setdefault(int(row["point"]), row)
    temporary = path.with_suffix(".csv.tmp")
    with temporary.open("w", newline="", encoding="utf-8") as handle:
        writer = csv.DictWriter(handle, columns)
        writer.writeheader()
        writer.writerows(rows[i] for i in sorted(rows))
    os.replace(temporary, path)
    return rows


def result_row(point: Point, outcome: dict[str, Any]) -> dict[str, Any]:
    return {"point": point.index, **point.parameters, "status": outcome["status"], "error": outcome["error"],
            "wall_time_s": f"{outcome['wall_time_s']:.4g}", **outcome["metrics"]}


def read_results(path: Path) -> list[dict[str, str]]:
    with path.open(newline="", encoding="utf-8") as handle:
        return list(csv.DictReader(handle))


def run(args: argparse.Namespace) -> int:
    study = load_study(args.study)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    provenance = study_provenance(study, out)
    write_json(out / "study.json", provenance)
    results = out / "results.csv"
    columns = _columns(study)
    done = finished_rows(results, columns, len(study.points))
    todo = [p for p in study.points if p.index not in done]
    label, runner = select(args.dask, args.workers)
    print(f"{study.spec.name}: {len(study.points)} points, {len(done)} finished earlier, "
          f"running {len(todo)} on {label}", file=sys.stderr)
    start = time.perf_counter()
    tasks = [(p.index, p.simulation) for p in todo]
    with results.open("a", newline="", encoding="utf-8") as handle, \
            tqdm(total=len(study.points), initial=len(done), desc=study.spec.name, unit="point",
                 disable=args.quiet) as bar:
        writer = csv.DictWriter(handle, columns)
        for outcome in runner(run_point, tasks) if tasks else ():
            writer.writerow(result_row(study.points[outcome["point"]], outcome))
            handle.flush()
            bar.update(1)
    rows = read_results(results)
    provenance["sessions"].append({"finished": datetime.now(timezone.utc).isoformat(timespec="seconds"),
                                   "runner": label, "points_run": len(todo),
                                   "wall_time_s": round(time.perf_counter() - start, 3)})
    provenance["point_wall_time_s"] = {
        row["point"]: float(row["wall_time_s"]) for row in sorted(rows, key=lambda r: int(r["point"]))}
    write_json(out / "study.json", provenance)
    written = draw_plots(study, rows, out)
    failed = [row for row in rows if row["status"] != "ok"]
    print(f"{study.spec.name}: {len(rows) - len(failed)} points ok, {len(failed)} failed; "
          f"wrote {results}, {out / 'study.json'}" + "".join(f", {p}" for p in written), file=sys.stderr)
    for row in failed[:5]:
        print(f"  point {row['point']}: {row['error']}", file=sys.stderr)
    return 1 if failed else 0
