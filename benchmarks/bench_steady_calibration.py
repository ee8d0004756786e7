"""The global calibration with and without the steady-state solver: best objective and CPU seconds.

Usage:
    python benchmarks/bench_steady_calibration.py run VARIANT --out DIR [--generations N] [--workers W]
    python benchmarks/bench_steady_calibration.py report --out DIR

``run`` writes ``DIR/VARIANT.yaml`` (studies/paper/calibration.yaml, its base scene path made
absolute, ``search.max_generations`` set to N - 1 when given: N generations counting the initial
population; VARIANT ``periodic`` adds ``solver.steady_state: periodic`` to ``base_overrides``) and runs
``rpdrill calibrate`` on it into ``DIR/VARIANT``; a larger N continues an earlier run (the calibration's
budget keys do not change what it has recorded). ``report`` (``--generations N``: of the first N generations) prints, per variant, the evaluations, the
simulation CPU seconds the evaluations recorded (the workers' own process time, summed), the best objective
after each generation, and the ratios between the variants. Run each variant once, in the background
(``nohup ... &``); the machine is shared, so the CPU seconds are the workers' own, not wall time.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]
SHIPPED = ROOT / "studies" / "paper" / "calibration.yaml"
VARIANTS = ("time", "periodic")


def variant_file(out: Path, variant: str, generations: int | None) -> Path:
    """The variant's calibration file in ``out/variant`` (module doc)."""
    data = yaml.safe_load(SHIPPED.read_text(encoding="utf-8"))
    data["base_scene"] = str((SHIPPED.parent / data["base_scene"]).resolve())
    if variant == "periodic":
        data["base_overrides"]["solver.steady_state"] = "periodic"
    if generations is not None:
        data["search"]["max_generations"] = generations - 1
    out.mkdir(parents=True, exist_ok=True)
    path = out / f"{variant}.yaml"
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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("action", choices=("run", "report"))
    parser.add_argument("variant", nargs="?", choices=VARIANTS)
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--generations", type=int)
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
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
