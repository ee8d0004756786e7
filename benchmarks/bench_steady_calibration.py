"""The global calibration with and without the steady-state solver: best objective and CPU seconds.

Usage:
    python benchmarks/bench_steady_calibration.py run VARIANT --out DIR [--generations N] [--workers W]
    python benchmarks/bench_steady_calibration.py report --out DIR
    python benchmarks/bench_steady_calibration.py sample --out DIR --from VARIANT [--every K]
    python benchmarks/bench_steady_calibration.py at --out DIR --scene FILE [--set NAME=VALUE ...] [--end-times S ...]

``run`` writes ``DIR/VARIANT.yaml`` (studies/paper/calibration.yaml, its base scene path made
absolute, ``search.max_generations`` set to N - 1 when given: N generations counting the initial
population; VARIANT ``periodic`` adds ``solver.steady_state: periodic`` to ``base_overrides``) and runs
``rpdrill calibrate`` on it into ``DIR/VARIANT``; a larger N continues an earlier run (the calibration's
budget keys do not change what it has recorded). ``report`` (``--generations N``: of the first N generations) prints, per variant, the evaluations, the
simulation CPU seconds the evaluations recorded (the workers' own process time, summed), the best objective
after each generation, and the ratios between the variants. Run each variant once, in the background
(``nohup ... &``); the machine is shared, so the CPU seconds are the workers' own, not wall time.

``sample`` measures the two variants side by side on the parameter sets a whole search visited, without
running the search twice: every K-th evaluation recorded in ``DIR/VARIANT`` (a finished ``run``, all its
generations) is evaluated again in this one process with ``steady_state: time`` and ``periodic``, one
after the other for each set (every distinct target scan, as the calibration runs it: studies.scan.curves
.run_curve), and it prints the CPU seconds of both, their ratio over all sets and by quarter of the search,
the points' regimes, and the largest difference between the two variants' objectives.

``at`` evaluates one drill (a scene file's values of the calibration's parameters, ``--set`` its free ones,
e.g. ``$impulse_3_2_n=257e3``) with time runs of each ``--end-times`` length and with periodic orbits, and
prints each objective, each target's miss, and the largest Floquet multipliers of the orbits found: whether
a search's best value is the drill's or its time runs' transient's.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import yaml

ROOT = Path(__file__).resolve().parents[1]
SHIPPED = ROOT / "studies" / "paper" / "calibration.yaml"
VARIANTS = ("time", "periodic")


def variant_file(out: Path, variant: str, generations: int | None, end_time_s: float | None = None) -> Path:
    """The variant's calibration file in ``out/variant`` (module doc); ``end_time_s``: its time runs that
    long (``out/time_<end>s.yaml``)."""
    data = yaml.safe_load(SHIPPED.read_text(encoding="utf-8"))
    data["base_scene"] = str((SHIPPED.parent / data["base_scene"]).resolve())
    if variant == "periodic":
        data["base_overrides"]["solver.steady_state"] = "periodic"
    if generations is not None:
        data["search"]["max_generations"] = generations - 1
    if end_time_s is not None:
        data["base_overrides"]["solver.end_time_s"] = end_time_s
    out.mkdir(parents=True, exist_ok=True)
    path = out / (f"{variant}.yaml" if end_time_s is None else f"{variant}_{end_time_s:g}s.yaml")
    path.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    return path


def records(folder: Path) -> list[dict]:
    """The evaluations recorded in a calibration's folder, in order."""
    path = folder / "evaluations.jsonl"
    if not path.exists():
        return []
    rows = [json.loads(line) for line in path.read_text(encoding="utf-8").splitlines() if line.strip()]
    return [row for row in rows if "objective" in row]


def report(out: Path, generations: int | None) -> None:
    population = None
    summary = {}
    for variant in VARIANTS:
        rows = records(out / variant)
        if rows and generations is not None:  # the same number of evaluations of each variant
            rows = rows[:generations * 8 * len(rows[0]["unit"])]
        if not rows:
            print(f"{variant}: no evaluations in {out / variant}")
            continue
        population = population or 8 * len(rows[0]["unit"])
        cpu = sum(row["cpu_time_s"] for row in rows)
        best, running = [], float("inf")
        for i, row in enumerate(rows):
            running = min(running, row["objective"])
            if (i + 1) % population == 0:
                best.append(running)
        summary[variant] = (len(rows), cpu, running, best)
        print(f"{variant}: {len(rows)} evaluations, {cpu:.1f} CPU s of simulations ({cpu / len(rows):.3f} s each), "
              f"best objective {running:.6g}; best after each generation: {', '.join(f'{b:.4g}' for b in best)}")
    if len(summary) == 2:
        (n_t, cpu_t, best_t, _), (n_p, cpu_p, best_p, _) = summary["time"], summary["periodic"]
        per_t, per_p = cpu_t / n_t, cpu_p / n_p
        print(f"CPU per evaluation time / periodic: {per_t / per_p:.2f}; best objective periodic / time: "
              f"{best_p / best_t:.4f} ({(best_p - best_t) / best_t:+.2%})")


def evaluate(calibration: Any, parameters: dict[str, float]) -> tuple[float, float, list[Any], list[dict]]:
    """One parameter set as the calibration evaluates it (every distinct target scan: studies.scan.curves
    .run_curve): the objective, the scans' CPU seconds, the scans' runs (one per target) and the targets'
    results."""
    from rpdrill.studies.calibration.calibration_search import objective, target_curves, target_result
    from rpdrill.studies.scan.curves import run_curve

    frequencies = list(calibration.frequencies_hz)
    curves = target_curves(calibration, 0, parameters, lambda _: frequencies)
    runs, spent = {}, 0.0
    for curve in curves:
        if curve.signature not in runs:
            runs[curve.signature] = run_curve(curve)
            spent += runs[curve.signature].cpu_time_s
    results = [target_result(calibration, t, runs[curve.signature]) for t, curve in enumerate(curves)]
    return objective(calibration, results)[0], spent, [runs[curve.signature] for curve in curves], results


def load(path: Path) -> Any:
    from rpdrill.studies.calibration.calibration_spec import load_calibration
    from rpdrill.studies.runtime.budgets import Budget

    return load_calibration(path, Budget(accept_long=True))


def sample(out: Path, source: str, every: int) -> None:
    rows = records(out / source)[::every]
    if not rows:
        sys.exit(f"no evaluations in {out / source}")
    calibrations = {variant: load(variant_file(out / "sample", variant, None)) for variant in VARIANTS}
    cpu = {variant: [] for variant in VARIANTS}
    objectives = {variant: [] for variant in VARIANTS}
    regimes: dict[str, int] = {}
    for row in rows:
        for variant, calibration in calibrations.items():
            value, spent, runs, _ = evaluate(calibration, row["parameters"])
            if variant == "periodic":
                for run in {id(run): run for run in runs}.values():
                    for regime in run.table["regime"].astype(object).fillna("failed (no run)"):
                        regimes[regime] = regimes.get(regime, 0) + 1
            cpu[variant].append(spent)
            objectives[variant].append(value)
    time_s, periodic_s = np.array(cpu["time"]), np.array(cpu["periodic"])
    print(f"{len(rows)} parameter sets (every {every}th of {out / source}), CPU s per evaluation: time "
          f"{time_s.mean():.3f}, periodic {periodic_s.mean():.3f}; time / periodic {time_s.sum() / periodic_s.sum():.2f}")
    for q, (t, p) in enumerate(zip(np.array_split(time_s, 4), np.array_split(periodic_s, 4), strict=True), start=1):
        if len(t):
            print(f"  quarter {q} of the search: time / periodic {t.sum() / p.sum():.2f} ({len(t)} sets)")
    print(f"  periodic points by regime: {dict(sorted(regimes.items(), key=lambda item: -item[1]))}")
    difference = np.abs(np.array(objectives["periodic"]) - np.array(objectives["time"]))
    print(f"  objective periodic - time: largest {difference.max():.4g}, median {np.median(difference):.3g}; best "
          f"set of the sample: time {min(objectives['time']):.6g}, periodic {min(objectives['periodic']):.6g}")


def at(out: Path, scene_file: Path, free: list[str], end_times_s: list[float]) -> None:
    """The objective of one drill (``scene_file``'s values of the calibration's parameters, ``free``: NAME=VALUE
    of its free ones) with time runs of each length and with periodic orbits; each target's miss, and the
    largest Floquet multiplier of the orbits found."""
    import rpdrill
    from rpdrill.studies.calibration.calibration_spec import is_free
    from rpdrill.studies.inputs.specs import scene_value

    scene = rpdrill.load_scene(scene_file)
    given = {name: float(value) for name, value in (item.split("=", 1) for item in free)}
    periodic = load(variant_file(out, "periodic", None))
    parameters = {name: given[name] if is_free(name) else scene_value(scene, name) for name in periodic.spec.parameters}
    variants = {f"time {end:g} s": load(variant_file(out, "time", None, end)) for end in end_times_s}
    variants["periodic"] = periodic
    print(f"{scene_file} with {given}: the calibration's objective")
    for name, calibration in variants.items():
        value, spent, runs, results = evaluate(calibration, parameters)
        misses = " ".join(f"{result['miss']:+.3f}" if result.get("miss") is not None else "-" for result in results)
        line = f"  {name}: objective {value:.6g} ({spent:.1f} CPU s); misses by target: {misses}"
        if name == "periodic":
            tables = [run.table for run in {id(run): run for run in runs}.values()]
            orbits = np.concatenate([t["floquet_max_abs"].to_numpy(dtype=float)[t["regime"].astype(str).str.startswith("period")]
                                     for t in tables])
            points = sum(len(t) for t in tables)
            line += (f"; {len(orbits)} of {points} points on a stable orbit, |mu|max median {np.median(orbits):.7f}, "
                     f"largest {orbits.max():.7f}")
        print(line, flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("action", choices=("run", "report", "sample", "at"))
    parser.add_argument("variant", nargs="?", choices=VARIANTS)
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--generations", type=int)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--from", dest="source", choices=VARIANTS, help="sample: the search whose sets are taken")
    parser.add_argument("--every", type=int, default=20, help="sample: every K-th evaluation")
    parser.add_argument("--scene", type=Path, help="at: the drill (a scene file)")
    parser.add_argument("--set", dest="free", action="append", default=[], help="at: NAME=VALUE of a free parameter")
    parser.add_argument("--end-times", type=float, nargs="+", default=[1.5], help="at: the time runs' lengths, s")
    args = parser.parse_args()
    if args.action == "at":
        if args.scene is None:
            parser.error("at needs --scene")
        at(args.out, args.scene, args.free, args.end_times)
        return
    if args.action == "sample":
        sample(args.out, args.source or "periodic", args.every)
        return
    if args.action == "report":
        report(args.out, args.generations)
        return
    if args.variant is None:
        parser.error("run needs a VARIANT")
    path = variant_file(args.out, args.variant, args.generations)
    command = [sys.executable, "-m", "rpdrill.studies.cli", "calibrate", str(path), "--out", str(args.out / args.variant),
               "--workers", str(args.workers), "--yes", "--quiet"]
    sys.exit(subprocess.run(command, check=False).returncode)


if __name__ == "__main__":
    main()
