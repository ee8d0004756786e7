"""What the study machinery costs beside the simulations: the three paper scans, measured in one run.

Usage: python benchmarks/bench_studies.py [--workers N] [--formulations exact,fast]
For each formulation (``exact``: the exact formulation; ``fast``/``standard``: Exudyn at that preset),
the three paper scans (studies/paper/{frequency,impulse,stiffness}_scan.yaml, 207 points of 1.5 s)
run through the study command's own code (studies.commands.study.run_study: load, resumable results,
optima; then studies.plots.scans.draw_plots) on one process pool opened for the three, into a scratch
directory.
Each formulation's three scans run in a process of their own (its own pool and fork server, as one
command has: the process starts the pool's fork server before its own imports, as the command line
does). Prints the wall time from opening the pool to the last plot, of it the time spent drawing the
plots (by the pool's workers), the CPU seconds of that process, its fork server and its
workers (read from /proc before the pool closes: Linux; on a shared machine the wall time depends
on the other load, the CPU time is what the run needs: on N idle cores the wall time is about
CPU / N), the CPU seconds the simulations reported (``cpu_time_s`` of every point), their share of
all CPU, the plots written and the wall time of the whole process (interpreter start, imports, the
three scans and their plots, exit).
Then one ``rpdrill study`` command of the frequency scan as a user runs it (a new process: imports,
pool start, plots), its wall time.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from rpdrill.studies.runners import start_worker_server

if __name__ == "__main__" and "--one" in sys.argv:
    start_worker_server()  # as the command line does, before the heavy imports below

import yaml

from rpdrill.studies.commands.study import run_study
from rpdrill.studies.loading import read_yaml
from rpdrill.studies.plots.scans import draw_plots
from rpdrill.studies.runners import pool
from rpdrill.studies.study import load_study

ROOT = Path(__file__).resolve().parents[1]
SCANS = ("frequency_scan", "impulse_scan", "stiffness_scan")
SOLVERS = {"exact": {"solver.formulation": "exact"}, "fast": {"solver.preset": "fast"},
           "standard": {"solver.preset": "standard"}}


def study_file(scan: str, solver: str, folder: Path) -> Path:
    """The paper scan with the solver's overrides, as a study file in ``folder``."""
    data = read_yaml(ROOT / "studies" / "paper" / f"{scan}.yaml")
    data["base_scene"] = str(ROOT / "studies" / "scenes" / "paper_base.yaml")
    data["base_overrides"] = {**data.get("base_overrides", {}), **SOLVERS[solver]}
    path = folder / f"{scan}_{solver}.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    return path


def process_tree_cpu_s(pid: int) -> float:
    """CPU seconds (user + system) of process ``pid`` and of its living descendants, from /proc (Linux):
    the pool's fork server and its workers, which are not this process's waited-for children."""
    tick = os.sysconf("SC_CLK_TCK")
    parents, cpu = {}, {}
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            with contextlib.suppress(OSError):
                fields = (entry / "stat").read_text().rsplit(")", 1)[1].split()
                parents[int(entry.name)] = int(fields[1])
                cpu[int(entry.name)] = (int(fields[11]) + int(fields[12])) / tick

    def descends(p: int) -> bool:
        while p > 1:
            if p == pid:
                return True
            p = parents.get(p, 0)
        return False

    return sum(seconds for p, seconds in cpu.items() if descends(p))


def three_scans(solver: str, workers: int, folder: Path) -> None:
    """The three scans on one pool in this process (a child of main: its own fork server); one line."""
    start, simulated_cpu, points, plots_written, plots_s = time.perf_counter(), 0.0, 0, 0, 0.0
    with pool(None, workers) as runner:
        for scan in SCANS:
            study = load_study(study_file(scan, solver, folder))
            rows, optima = run_study(study, folder / f"{scan}_{solver}", runner, quiet=True)
            plots_start = time.perf_counter()
            plots_written += len(draw_plots(study, rows, optima, folder / f"{scan}_{solver}", runner[1])[0])
            plots_s += time.perf_counter() - plots_start
            simulated_cpu += sum(float(row["cpu_time_s"]) for row in rows if row["status"] == "ok")
            points += len(rows)
        cpu = process_tree_cpu_s(os.getpid())
    wall = time.perf_counter() - start
    print(f"{solver:<10}{points:<8}{wall:<10.2f}{plots_s:<10.2f}{cpu:<13.2f}{simulated_cpu:<20.2f}"
          f"{simulated_cpu / cpu:<20.2f}{plots_written:<7}", end="", flush=True)


def one_command(solver: str, workers: int, folder: Path) -> float:
    study = study_file("frequency_scan", solver, folder)
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "rpdrill.studies.cli", "study", str(study), "--out",
                    str(folder / f"command_{solver}"), "--workers", str(workers), "--quiet"], check=True)
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--formulations", default="exact,fast")
    parser.add_argument("--one", help=argparse.SUPPRESS)  # a child: the three scans of one formulation
    parser.add_argument("--folder", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.one:
        three_scans(args.one, args.workers, Path(args.folder))
        return
    solvers = args.formulations.split(",")
    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)
        print(f"three paper scans on one pool of {args.workers} workers, a process each")
        print(f"{'solver':<10}{'points':<8}{'wall s':<10}{'plots s':<10}{'all CPU s':<13}{'simulation CPU s':<20}"
              f"{'simulation / all':<20}{'plots':<7}process s")
        for solver in solvers:
            start = time.perf_counter()
            subprocess.run([sys.executable, __file__, "--one", solver, "--folder", str(folder), "--workers",
                            str(args.workers)], check=True)
            print(f"{time.perf_counter() - start:.2f}")
        for solver in solvers:
            print(f"one command (rpdrill study frequency_scan, 23 points, {solver}): "
                  f"{one_command(solver, args.workers, folder):.2f} s wall")


if __name__ == "__main__":
    main()
