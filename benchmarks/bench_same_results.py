"""The shipped studies' results at another revision and at this checkout, cell by cell.

Usage: python benchmarks/bench_same_results.py [--base REV] [--formulation exact] [--workers N]
                                               [--studies NAME,...] [--analyses] [--keep DIR]

Runs every shipped study (studies/paper/*_scan.yaml, rock_table.yaml, studies/rotation/*.yaml,
studies/top_hammer/power_map.yaml; the same study files for both) with ``rpdrill study --formulation
FORMULATION`` twice, each in a process of its own: with rpdrill as it is at git revision REV (default
``main``; its tree exported by ``git archive`` into a scratch folder that Python imports as
``rpdrill``), and with this checkout. Then compares, per study, ``results.csv`` and ``optima.csv`` as
text, cell by cell (results.csv in point order: a study appends its rows as the points finish),
every column but the times (``wall_time_s``, and the ``cpu_time_s`` metric: what
a run cost, not what it gave). Prints per study the rows, the cells compared and those that differ
(the first few named); exit status 1 when any cell differs. A refactoring of the study machinery
must print 0 differing cells for every study.

``--analyses``: instead, the other commands on the small inputs of ``examples/inputs/`` (the docs'
examples; the same files for both): ``rpdrill calibrate``, ``sensitivity``, ``accuracy``, ``reproduce``
and ``advise``, each table they write compared the same way (CPU and wall times left out; advise's
best point and value from its advice.json).
"""

from __future__ import annotations

import argparse
import csv
import io
import json
import os
import subprocess
import sys
import tarfile
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
STUDIES = {"frequency_scan": "studies/paper/frequency_scan.yaml", "impulse_scan": "studies/paper/impulse_scan.yaml",
           "stiffness_scan": "studies/paper/stiffness_scan.yaml", "rock_table": "studies/paper/rock_table.yaml",
           "dth_example": "studies/rotation/dth_example.yaml",
           "rpm_frequency_map": "studies/rotation/rpm_frequency_map.yaml",
           "power_map": "studies/top_hammer/power_map.yaml"}
TABLES = ("results.csv", "optima.csv")
TIMES = {"wall_time_s", "cpu_time_s", "cpu_time_s_runs"}  # what a run cost, not what it gave
INPUTS = ROOT / "examples" / "inputs"
# command (its input first), the tables it writes into --out
ANALYSES = {
    "calibrate": (["calibrate", str(INPUTS / "calibration.yaml")], ("targets.csv", "pareto.csv", "best_curves.csv")),
    "sensitivity": (["sensitivity", str(INPUTS / "sensitivity.yaml")], ("results.csv", "one_at_a_time.csv", "trends.csv")),
    "accuracy": (["accuracy", str(INPUTS / "accuracy.yaml")], ("workprecision.csv",)),
    "reproduce": (["reproduce", str(INPUTS / "reproduction.yaml")], ("cases.csv",)),
    "advise": (["advise", str(ROOT / "studies" / "scenes" / "paper_base.yaml"), "--frequency-hz", "45", "75",
                "--feed-kn", "10", "30", "--popsize", "4", "--generations", "3"], ("advice.json",)),
}
SHOWN = 5  # differing cells named per table


def export(revision: str, folder: Path) -> Path:
    """The tree of ``revision`` as ``folder/rpdrill`` (importable with ``folder`` on PYTHONPATH)."""
    archive = subprocess.run(["git", "-C", str(ROOT), "archive", "--format=tar", revision],
                             check=True, capture_output=True).stdout
    package = folder / "rpdrill"
    package.mkdir(parents=True)
    with tarfile.open(fileobj=io.BytesIO(archive)) as tar:
        tar.extractall(package, filter="data")
    return folder


def at_base_and_here(base: str | None, rows: Callable[[Path], None], columns: int) -> None:
    """``rows(tree)`` of a markdown table at git revision ``base`` (when given) and then at this checkout, each
    part under a row naming it (``columns`` the table's)."""
    blanks = " |" * (columns - 1)
    if base:
        with tempfile.TemporaryDirectory() as folder:
            print(f"| at {base} |{blanks}")
            rows(export(base, Path(folder)))
        print(f"| this checkout |{blanks}")
    rows(ROOT)


def run_command(path_entry: Path, words: list[str], out: Path, workers: int) -> float:
    """An ``rpdrill`` command into ``out`` with rpdrill imported from ``path_entry``; its wall seconds."""
    env = {**os.environ, "PYTHONPATH": str(path_entry)}
    where = subprocess.run([sys.executable, "-c", "import rpdrill; print(rpdrill.__file__)"], env=env, check=True,
                           capture_output=True, text=True, cwd=path_entry).stdout.strip()
    if not where.startswith(str(path_entry)):
        raise SystemExit(f"rpdrill imported from {where}, not from {path_entry}")
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "rpdrill.studies.cli", *words, "--out", str(out), "--workers", str(workers),
                    "--quiet", *(["--yes"] if words[0] == "study" else [])],
                   env=env, check=False, cwd=path_entry, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    return time.perf_counter() - start


def run_study(path_entry: Path, study: Path, out: Path, formulation: str, workers: int) -> float:
    """``rpdrill study`` of ``study`` into ``out`` with rpdrill imported from ``path_entry``; its wall seconds."""
    return run_command(path_entry, ["study", str(study), "--formulation", formulation], out, workers)


def table(path: Path) -> tuple[list[str], list[list[str]]]:
    with path.open(newline="", encoding="utf-8") as handle:
        header, *rows = list(csv.reader(handle))
    return header, rows


def compare(old: Path, new: Path) -> tuple[int, int, list[str]]:
    """(rows, cells compared, the differences) of two tables of the same name."""
    if not old.exists() or not new.exists():
        return 0, 0, [f"{old.name}: {'missing at the base' if not old.exists() else 'missing here'}"]
    (old_header, old_rows), (new_header, new_rows) = table(old), table(new)
    if old_header != new_header:
        return len(old_rows), 0, [f"{old.name}: columns {old_header} != {new_header}"]
    if len(old_rows) != len(new_rows):
        return len(old_rows), 0, [f"{old.name}: {len(old_rows)} rows != {len(new_rows)}"]
    if "point" in old_header:  # results.csv: rows in the order the points finished
        old_rows, new_rows = (sorted(rows, key=lambda row: int(row[old_header.index("point")]))
                              for rows in (old_rows, new_rows))
    kept = [i for i, name in enumerate(old_header) if name not in TIMES]
    differences = [f"{old.name} row {r + 1} {old_header[i]}: {a[i]!r} != {b[i]!r}"
                   for r, (a, b) in enumerate(zip(old_rows, new_rows)) for i in kept if a[i] != b[i]]
    return len(old_rows), len(old_rows) * len(kept), differences


def compare_advice(old: Path, new: Path) -> tuple[int, int, list[str]]:
    """(rocks, values compared, the differences) of two advice.json files: each rock's best point and value."""
    if not old.exists() or not new.exists():
        return 0, 0, [f"{old.name}: {'missing at the base' if not old.exists() else 'missing here'}"]
    found = [[(r["rock"], r["best"], r["best_value"]) for r in json.loads(path.read_text())["results"]]
             for path in (old, new)]
    differences = [f"advice {a[0]}: {a[1:]} != {b[1:]}" for a, b in zip(*found, strict=True) if a != b]
    return len(found[0]), 2 * len(found[0]), differences


def analyses(folder: Path, base: Path, here: Path, workers: int) -> bool:
    """The other commands at both revisions (module doc); True when a cell differs."""
    print(f"{'command':<20}{'rows':<8}{'cells':<9}{'differ':<8}{'base s':<9}{'here s':<9}")
    failed = False
    for name, (words, tables) in ANALYSES.items():
        walls = [run_command(entry, words, folder / label / "out" / name, workers)
                 for entry, label in ((base, "base"), (here, "here"))]
        rows = cells = 0
        differences: list[str] = []
        for file in tables:
            old, new = folder / "base" / "out" / name / file, folder / "here" / "out" / name / file
            found = compare_advice(old, new) if file.endswith(".json") else compare(old, new)
            rows, cells, differences = rows + found[0], cells + found[1], differences + found[2]
        failed |= bool(differences) or cells == 0
        print(f"{name:<20}{rows:<8}{cells:<9}{len(differences):<8}{walls[0]:<9.1f}{walls[1]:<9.1f}", flush=True)
        for line in differences[:SHOWN]:
            print(f"    {line}")
    return failed


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--base", default="main", help="git revision to compare with (default main)")
    parser.add_argument("--formulation", default="exact")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--studies", default=",".join(STUDIES), help="comma-separated names (default: all)")
    parser.add_argument("--analyses", action="store_true", help="the other commands on examples/inputs instead")
    parser.add_argument("--keep", type=Path, help="keep both runs' folders here")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="same-results-") as scratch:
        folder = args.keep or Path(scratch)
        base = export(args.base, folder / "base")
        here = folder / "here"
        here.mkdir(parents=True, exist_ok=True)
        if not (here / "rpdrill").exists():
            (here / "rpdrill").symlink_to(ROOT)
        if args.analyses:
            print(f"rpdrill at {args.base} against this checkout; the commands on examples/inputs, --workers {args.workers}")
            return 1 if analyses(folder, base, here, args.workers) else 0
        print(f"rpdrill at {args.base} against this checkout; rpdrill study --formulation {args.formulation} "
              f"--workers {args.workers}")
        print(f"{'study':<20}{'rows':<8}{'cells':<9}{'differ':<8}{'base s':<9}{'here s':<9}")
        failed = False
        for name in args.studies.split(","):
            study = ROOT / STUDIES[name]
            walls = [run_study(entry, study, folder / label / "out" / name, args.formulation, args.workers)
                     for entry, label in ((base, "base"), (here, "here"))]
            rows = cells = 0
            differences: list[str] = []
            for file in TABLES:
                found = compare(folder / "base" / "out" / name / file, folder / "here" / "out" / name / file)
                rows, cells, differences = rows + found[0], cells + found[1], differences + found[2]
            failed |= bool(differences) or cells == 0
            print(f"{name:<20}{rows:<8}{cells:<9}{len(differences):<8}{walls[0]:<9.1f}{walls[1]:<9.1f}", flush=True)
            for line in differences[:SHOWN]:
                print(f"    {line}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
