"""The cost of a hole (issue 46): the shipped 30 m top-hammer hole (studies/holes/top_hammer_30m.yaml: 9 rods,
3 layers, fixed operation) drilled in the exact formulation, and what the same costs in the Exudyn formulation.

    python benchmarks/bench_hole.py [--repeat N] [--hole NAME] [--exudyn]

Default: the hole drilled N times (default 3) in this process (``workers=1``) into a scratch folder, the CPU
seconds of the process each time (time.process_time: every run is in this process), their median against the
target of 60 s; then per run (one per rod count and layer) its rods, the blows it ran before it settled (or its
cap), its CPU and the CPU per blow: how the cost grows with the rods (the CPU per blow) and with the depth (the
runs: one per rod count and layer, so a deeper hole adds a run per rod and per layer boundary, each run
costing blows x CPU per blow).
``--profile ROD_COUNT LAYER``: where one run's CPU goes (cProfile of the steady run of the hole's scene at that rod
count and layer, 1-based): the compiled kernels of the characteristics (models.waves.kernels, models.waves.fast_path's
calls of them) against the Python step loop around them (models.waves.stepping, levels, outgoing, recording), and
the blows the run needed.
``--periods ROD_COUNT LAYER BLOWS``: a time run of BLOWS blows of the hole's scene at that rod count and layer
(1-based; exact formulation), and for every period n of 1 to 12 blows the blow from which each blow's advance and
rock energy stay within 1e-6 (relative) of the blow n before, and the last such change: which steady state a depth
that did not settle within its cap reaches later.
``--projections``: every run of the hole (one per rod count and layer) without the early stop (to where it settles or
to its cap), and every 5 blows from the first blow it may be stopped at (wave_settling.projection_start) the blow at
which its changes would settle at their recent rate (wave_settling.earliest_settling, inf: they do not fall): how far
the early stop of a run that will not settle (beyond PROJECTION_MARGIN times the cap) is from the runs that do.
``--exudyn``: the Exudyn formulation's CPU per blow at each rod count of the hole (a run of 5 blows each, after a
warm-up) and the hole's cost estimated from it (a full Exudyn hole takes too long to run here): as the Exudyn
formulation runs (every depth to its cap: only the exact formulation stops where the blows settle), and at the exact
runs' blows.
"""

from __future__ import annotations

import argparse
import statistics
import time

import rpdrill
from rpdrill.studies.hole.hole_scenes import scene_data
from rpdrill.studies.hole.hole_spec import load_hole

TARGET_CPU_S = 60.0


def drill_once(name: str) -> tuple[float, rpdrill.HoleResult]:
    start = time.process_time()
    result = rpdrill.drill_hole(name, workers=1)
    return time.process_time() - start, result


def exudyn_per_blow(name: str, rods: list[int]) -> dict[int, float]:
    """CPU per blow of the hole's scene at each rod count (first layer) in the Exudyn formulation: 5 blows."""
    hole = load_hole(name)
    out = {}
    for count in [rods[0], *rods]:  # the first again: a warm-up
        data = scene_data(hole, count, 0)
        data["solver"].update({"formulation": "exudyn", "end_time_s": 0.1, "steady_state": "time"})
        data["metrics"] = {"transient_blows": 1, "block_blows": 1}
        scene = rpdrill.Scene.model_validate(data)
        start = time.process_time()
        rpdrill.simulate(scene)
        out[count] = (time.process_time() - start) / 5
    return out


def profile(name: str, rods: int, layer: int) -> None:
    """cProfile of one run (module doc), its own time grouped by module."""
    import cProfile
    import pstats

    from rpdrill.studies.hole.hole_runs import settled_record

    hole = load_hole(name)
    data = scene_data(hole, rods, layer - 1)
    settled_record("warm-up", 1, 0, scene_data(hole, 1, 0), name)  # numba's kernels loaded once
    profiler = cProfile.Profile()
    start = time.process_time()
    record = profiler.runcall(settled_record, "profiled", rods, layer - 1, data, name)
    total = time.process_time() - start
    by_module: dict[str, float] = {}
    for (file, _, function), (_, _, own, _, _) in pstats.Stats(profiler).stats.items():
        module = file.rsplit("/", 1)[-1] if file.startswith("/") else function
        by_module[module] = by_module.get(module, 0.0) + own
    print(f"{rods} rods in layer {layer}: {record.blows} blows ({record.regime}), {total:.1f} CPU s "
          f"({total / record.blows:.3f} s a blow; the profiler's own overhead included)")
    for module, own in sorted(by_module.items(), key=lambda item: -item[1])[:12]:
        print(f"  {own:7.2f} s  {100 * own / sum(by_module.values()):5.1f} %  {module}")


def projections(name: str) -> None:
    """Per run of the hole, its projected settling every 5 blows (module doc)."""
    from rpdrill.models.steady import wave_settling
    from rpdrill.models.steady.wave_settling import earliest_settling, per_blow, projection_start
    from rpdrill.studies.hole.hole_run import segments

    wave_settling.PROJECTION_MARGIN = float("inf")  # this script's process only: no early stop
    hole = load_hole(name)
    for rods, layer in segments(hole):
        scene = rpdrill.Scene.model_validate(scene_data(hole, rods, layer))
        advance, energy = per_blow(rpdrill.simulate(scene).raw)
        bounds = range(projection_start(scene.metrics), len(advance) + 1, 5)
        shown = " ".join(f"{b}:{earliest_settling(advance[:b], energy[:b], b):.0f}" for b in bounds)
        print(f"{rods} rods, layer {layer + 1}: {shown}")


def periods(name: str, rods: int, layer: int, blows: int) -> None:
    """The periods a long time run settles on (module doc)."""
    import numpy as np

    from rpdrill.models.steady.wave_settling import TOLERANCE, per_blow, relative_changes

    data = scene_data(load_hole(name), rods, layer - 1)
    period_s = 1.0 / data["impact"]["frequency_hz"]
    data["solver"].update({"steady_state": "time", "end_time_s": blows * period_s})
    start = time.process_time()
    result = rpdrill.simulate(rpdrill.Scene.model_validate(data))
    advance, energy = per_blow(result.raw)
    print(f"{rods} rods in layer {layer}: {len(advance)} blows, {time.process_time() - start:.1f} CPU s; mean advance "
          f"over the last 120 blows {1e6 * np.mean(advance[-120:]):.4f} um a blow")
    for n in range(1, 13):
        changes = relative_changes(advance, energy, n)
        above = np.flatnonzero(~(changes < TOLERANCE))
        first = above[-1] + 1 + n if len(above) else n
        since = "never" if len(above) and above[-1] == len(changes) - 1 else f"from blow {first}"
        print(f"  period {n:2d}: within {TOLERANCE:g} of the blow {n} before {since}; last change {changes[-1]:.2e}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--periods", type=int, nargs=3, metavar=("ROD_COUNT", "LAYER", "BLOWS"))
    parser.add_argument("--hole", default="holes/top_hammer_30m")
    parser.add_argument("--exudyn", action="store_true")
    parser.add_argument("--profile", nargs=2, type=int, metavar=("ROD_COUNT", "LAYER"))
    parser.add_argument("--projections", action="store_true")
    args = parser.parse_args()
    if args.profile:
        profile(args.hole, *args.profile)
        return
    if args.projections:
        projections(args.hole)
        return
    if args.periods:
        periods(args.hole, *args.periods)
        return
    times, result = [], None
    for i in range(args.repeat):
        cpu, result = drill_once(args.hole)
        times.append(cpu)
        print(f"run {i + 1}: {cpu:.1f} CPU s")
    median = statistics.median(times)
    print(f"{args.hole}: median {median:.1f} CPU s of {args.repeat} (target <= {TARGET_CPU_S:g} s: "
          f"{'met' if median <= TARGET_CPU_S else 'NOT met'}); {len(result.runs)} runs, "
          f"{len(result.rows)} depth rows")
    print("run                 rods  blows  regime                     CPU s   CPU s/blow")
    for key, run in sorted(result.runs.items()):
        print(f"{key:<20}{run.rods:>4}{run.blows:>7}  {run.regime:<25}{run.cpu_time_s:>7.2f}{run.cpu_time_s / run.blows:>12.4f}")
    if args.exudyn:
        rods = sorted({run.rods for run in result.runs.values()})
        per_blow = exudyn_per_blow(args.hole, rods)
        estimate = sum(run.blows * per_blow[run.rods] for run in result.runs.values())
        data = scene_data(load_hole(args.hole), rods[0], 0)
        cap = round(data["solver"]["end_time_s"] * data["impact"]["frequency_hz"])
        as_run = sum(cap * per_blow[run.rods] for run in result.runs.values())
        print("rods  Exudyn CPU s/blow")
        for count in rods:
            print(f"{count:>4}  {per_blow[count]:.3f}")
        print(f"the hole in the Exudyn formulation: about {as_run:.0f} CPU s as it runs (every depth to its cap of "
              f"{cap} blows: only the exact formulation stops where the blows settle), {as_run / median:.0f} x the "
              f"exact formulation's; about {estimate:.0f} CPU s at the exact runs' blows")


if __name__ == "__main__":
    main()
