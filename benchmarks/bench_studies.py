"""What the study machinery costs beside the simulations: the three paper scans, measured in one run.

Usage: python benchmarks/bench_studies.py [--workers N] [--formulations exact,fast] [--repeats N] [--base REV]
For each formulation (``exact``: the exact formulation; ``fast``/``standard``: Exudyn at that preset),
the three paper scans (studies/paper/{frequency,impulse,stiffness}_scan.yaml, 207 points of 1.5 s)
run through the study command's own loop (studies.study_runs.run_studies: resumable results, the
scans' points as one run, a point two scans share run once, optima, each scan's plots drawn by the
workers once its points are done) on one process pool,
into a scratch directory, each formulation in a process of its own (its own pool), --repeats times. Prints, of the run of median wall time, the wall time from opening the pool to the last plot, the CPU seconds of that process,
and its workers (read from /proc before the pool closes: Linux; on a shared machine
the wall time depends on the other load, the CPU time is what the run needs: on N idle cores the wall
time is about CPU / N), the points and how many were run, the CPU seconds the simulations reported
(``cpu_time_s`` of every point run),
their share of all CPU, the plot files written, the CPU seconds of drawing each plot (PNG and SVG)
again in that process after the pool closed, and the wall time of the whole process (interpreter
start, imports, the three scans and their plots, the plots again, exit); then every run's wall time.
Then, as a user runs them (a new process each: imports, pool, plots): one ``rpdrill study`` command
of the three scans, and one of the frequency scan alone; their wall times (median of --repeats runs;
each run starts afresh: the finished points are in a new folder), after the start and exit of a
Python process with the libraries of a study loaded, with and without gc.freeze() before its exit.

With ``--base REV`` the same measurements of rpdrill as it is at git revision REV (its tree exported by
``git archive``, benchmarks/bench_same_results.py; its own bench_studies.py measures it) alternate with
this checkout's, run by run, and the medians of both are printed with their ratio (this checkout / REV):
the cost of a change measured side by side on the same machine at the same time.
"""

from __future__ import annotations

import argparse
import compileall
import contextlib
import json
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import yaml

from rpdrill.studies.figures.plot_tasks import draw_plot, plot_tasks
from rpdrill.studies.inputs.reading import read_yaml
from rpdrill.studies.runtime.pools import pool
from rpdrill.studies.scan.study import load_study
from rpdrill.studies.study_runs import run_studies

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
    the pool's workers, which are not this process's waited-for children."""
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
    """The three scans on one pool in this process (a child of main: its own pool), through the
    study command's own loop (studies.study_runs.run_studies), into new folders; its figures as
    one line of JSON."""
    studies = [load_study(study_file(scan, solver, folder)) for scan in SCANS]
    folders = [Path(tempfile.mkdtemp(prefix=f"{scan}_{solver}_", dir=folder)) for scan in SCANS]
    start = time.perf_counter()
    with pool(None, workers) as runner:
        runs = run_studies(studies, folders, runner, plots_here=False, quiet=True)
        plots_written = sum(len(run.plots) for run in runs)
        cpu = process_tree_cpu_s(os.getpid())
    wall = time.perf_counter() - start
    run_once = {run.study.scene_keys[point]: seconds if status == "ok" else 0.0
                for run in runs for point, status, seconds in zip(run.table["point"], run.table["status"],
                                                                   run.table["cpu_time_s"], strict=True)}
    simulated_cpu = sum(run_once.values())  # a point two scans share ran once
    points = f"{sum(len(run.table) for run in runs)} ({len(run_once)})"
    plots_cpu = []
    import rpdrill.studies.figures.scan_figures  # noqa: F401 - matplotlib loaded first, as in the pool's workers
    for run in runs:  # each plot again, in this process, for its CPU time
        (folder / "replotted" / run.out.name).mkdir(parents=True)
        for task in plot_tasks(run.study, run.table, run.optima, folder / "replotted" / run.out.name)[0]:
            start = time.process_time()
            draw_plot(task)
            plots_cpu.append(time.process_time() - start)
    print(json.dumps({"points": points, "wall": wall, "cpu": cpu, "simulated_cpu": simulated_cpu,
                      "plots_written": plots_written, "plots_cpu": plots_cpu}))


def one_command(solver: str, workers: int, folder: Path, scans: tuple[str, ...]) -> float:
    """Wall seconds of one ``rpdrill study`` command of the ``scans`` as a user runs it (a new process)."""
    files = [str(study_file(scan, solver, folder)) for scan in scans]
    out = tempfile.mkdtemp(prefix=f"command_{solver}_{len(scans)}_", dir=folder)  # new: nothing to resume
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "rpdrill.studies.cli", "study", *files, "--out", out,
                    "--workers", str(workers), "--quiet"],
                   check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - start


def versions_side_by_side(base: str, solvers: list[str], workers: int, repeats: int) -> None:
    """The measurements of :func:`main` for rpdrill at ``base`` and for this checkout, alternated run by
    run, each version's rpdrill on its own PYTHONPATH; medians and their ratio (module doc)."""
    sys.path.insert(0, str(Path(__file__).parent))
    from bench_same_results import export

    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)
        entries = {"base": export(base, folder / "base"), "here": folder / "here"}
        (entries["here"] / "rpdrill").parent.mkdir(parents=True)
        (entries["here"] / "rpdrill").symlink_to(ROOT)
        for entry in entries.values():
            compileall.compile_dir(entry / "rpdrill", quiet=1, rx=re.compile(r"[/\\](tests|docs|\.\w+)[/\\]"))
        scripts = {label: entry / "rpdrill" / "benchmarks" / "bench_studies.py" for label, entry in entries.items()}

        def environment(label: str) -> dict[str, str]:
            return {**os.environ, "PYTHONPATH": str(entries[label])}

        print(f"rpdrill at {base} (base) against this checkout (here), alternated, {repeats} runs each, "
              f"{workers} workers; medians, and here / base")
        for solver in solvers:
            runs: dict[str, list[dict]] = {"base": [], "here": []}
            for label in runs:  # a warm-up run of each, not counted (compiled kernels cached, files in the OS cache)
                subprocess.run([sys.executable, str(scripts[label]), "--one", solver, "--folder", str(folder),
                                "--workers", str(workers)], env=environment(label), check=True, capture_output=True,
                               cwd=folder)
            for _ in range(repeats):
                for label, found in runs.items():
                    start = time.perf_counter()
                    child = subprocess.run([sys.executable, str(scripts[label]), "--one", solver, "--folder",
                                            str(folder), "--workers", str(workers)], env=environment(label),
                                           check=True, capture_output=True, text=True, cwd=folder)
                    found.append({**json.loads(child.stdout.splitlines()[-1]), "process": time.perf_counter() - start})
            for key, what in (("wall", "pool to last plot, wall s"), ("cpu", "all CPU s"),
                              ("process", "whole process, wall s")):
                medians = {label: statistics.median(r[key] for r in found) for label, found in runs.items()}
                print(f"{solver:<8}{what:<28} base {medians['base']:<8.2f} here {medians['here']:<8.2f} "
                      f"here / base {medians['here'] / medians['base']:.3f}   (base: "
                      + " ".join(f"{r[key]:.2f}" for r in runs["base"]) + "; here: "
                      + " ".join(f"{r[key]:.2f}" for r in runs["here"]) + ")", flush=True)
        for solver in solvers:
            commands: dict[str, list[tuple[float, float]]] = {"base": [], "here": []}  # (wall, CPU) of each run
            for _ in range(repeats):
                for label, measured in commands.items():
                    files = [str(study_file(scan, solver, folder)) for scan in SCANS]
                    out = tempfile.mkdtemp(prefix=f"command_{label}_", dir=folder)
                    start, before = time.perf_counter(), resource.getrusage(resource.RUSAGE_CHILDREN)
                    subprocess.run([sys.executable, "-m", "rpdrill.studies.cli", "study", *files, "--out", out,
                                    "--workers", str(workers), "--quiet"], env=environment(label), cwd=folder,
                                   check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
                    used = resource.getrusage(resource.RUSAGE_CHILDREN)  # the command and its waited-for workers
                    measured.append((time.perf_counter() - start, used.ru_utime + used.ru_stime - before.ru_utime
                                     - before.ru_stime))
            for index, what in ((0, "one rpdrill study command, wall s"), (1, "one rpdrill study command, CPU s")):
                medians = {label: statistics.median(m[index] for m in found) for label, found in commands.items()}
                print(f"{solver:<8}{what:<28} base {medians['base']:<8.2f} here {medians['here']:<8.2f} here / base "
                      f"{medians['here'] / medians['base']:.3f}   (base: "
                      + " ".join(f"{m[index]:.2f}" for m in commands["base"]) + "; here: "
                      + " ".join(f"{m[index]:.2f}" for m in commands["here"]) + ")", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--formulations", default="exact,fast")
    parser.add_argument("--repeats", type=int, default=3, help="runs of each measurement (the median shown)")
    parser.add_argument("--base", help="also measure rpdrill at this git revision, alternating with this checkout")
    parser.add_argument("--one", help=argparse.SUPPRESS)  # a child: the three scans of one formulation
    parser.add_argument("--folder", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.one:
        three_scans(args.one, args.workers, Path(args.folder))
        return
    if args.base:
        versions_side_by_side(args.base, args.formulations.split(","), args.workers, args.repeats)
        return
    solvers = args.formulations.split(",")
    # the project's modules byte-compiled, as a user's install has them after its first run (an
    # environment with PYTHONDONTWRITEBYTECODE set would compile them again in every process)
    compileall.compile_dir(ROOT, quiet=1, rx=re.compile(r"[/\\](benchmarks|tests|docs|\.\w+)[/\\]"))
    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)
        print(f"three paper scans on one pool of {args.workers} workers, a process each")
        print(f"{'solver':<10}{'points (run)':<14}{'wall s':<10}{'all CPU s':<13}{'simulation CPU s':<20}"
              f"{'simulation / all':<20}{'plots':<7}{'plots CPU s':<12}{'per plot':<32}{'process s':<11}wall s of each run")
        for solver in solvers:
            runs = []
            for _ in range(args.repeats):
                start = time.perf_counter()
                child = subprocess.run([sys.executable, __file__, "--one", solver, "--folder", str(folder),
                                        "--workers", str(args.workers)], check=True, capture_output=True, text=True)
                runs.append({**json.loads(child.stdout.splitlines()[-1]), "process": time.perf_counter() - start})
            run = min(runs, key=lambda r: abs(r["wall"] - statistics.median(r["wall"] for r in runs)))  # the median run
            print(f"{solver:<10}{run['points']:<14}{run['wall']:<10.2f}{run['cpu']:<13.2f}{run['simulated_cpu']:<20.2f}"
                  f"{run['simulated_cpu'] / run['cpu']:<20.2f}{run['plots_written']:<7}{sum(run['plots_cpu']):<12.2f}"
                  f"{' '.join(f'{c:.2f}' for c in run['plots_cpu']):<32}{run['process']:<11.2f}"
                  + " ".join(f"{r['wall']:.2f}" for r in runs), flush=True)
        for solver in solvers:
            for scans in (SCANS, SCANS[:1]):
                walls = [one_command(solver, args.workers, folder, scans) for _ in range(args.repeats)]
                print(f"one command (rpdrill study {' '.join(scans)}, {solver}): {statistics.median(walls):.2f} s "
                      f"wall, median of {args.repeats} ({' '.join(f'{w:.2f}' for w in walls)})", flush=True)


if __name__ == "__main__":
    main()
