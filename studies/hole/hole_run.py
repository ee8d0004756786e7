"""A hole drilled over its depth (``rpdrill hole``, :func:`drill_hole`): the depth rows, one steady run per distinct
(rod count, layer, operating point), the rows and the summary, the files.

Depth rows: every ``depth_step_m`` from the collar and the hole's depth, or (``at_changes``) the collar, every rod
change, every layer boundary and the depth. A row's rods and layer are those of the interval just above it (the
collar's: the first rods in the first layer). Rows within one segment (the same rods and layer) read the same run:
a 30 m hole of 9 rods and 3 layers is 11 runs however fine its rows.

Time to a depth: the integral of dz / rate over the segments above it (the rate constant within one) plus
``rod_change_s`` for each rod added on the way. Energy per metre: the hammer's energy per blow over the advance
per blow, integrated over the depth (and the energy reaching the rock alike).

With ``operating: advise`` each segment's run is at the point the advisor finds for it (studies.hole.hole_advice;
its scene written beside the rig's as ``*_advised.yaml``), its rate at the rig's own point kept, and the summary
gives the time gained against that fixed setting.

Resumable: each run's record is written to ``DIR/runs/<key>.json`` as it finishes (and each depth's scene to
``DIR/scenes/`` before any runs, for ``rpdrill simulate``); a rerun into DIR reads the records whose scene is
unchanged and runs the rest; a Ctrl-C keeps every finished record (studies.runtime.interrupts). The hole's files
(hole.csv, hole.json, hole.png) are written once every run is done.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd
from tqdm import tqdm

from ...models.definition.scene import Scene
from ...models.definition.validation import InputError, parse
from ..inputs.reading import prepare_scene
from ..runtime.interrupts import raise_if_stopped
from ..runtime.output_files import write_atomic, write_json, write_resolved, write_rows_csv
from ..runtime.run_options import RunOptions
from .hole_runs import SegmentRun, run_segment, scene_hash
from .hole_scenes import apply_changes, scene_data
from .hole_spec import Hole

RECORD = "hole.resolved.yaml"  # written first: a rerun into the folder resumes the same hole only


@dataclass(frozen=True)
class Segment:
    """One distinct run of a hole: ``rods`` in layer ``layer``, its scene's data and file."""

    rods: int
    layer: int
    data: dict[str, Any]
    file: str

    @property
    def key(self) -> str:
        return f"rods{self.rods:03d}_layer{self.layer + 1:02d}"


@dataclass(frozen=True)
class HoleResult:
    """A hole drilled (:func:`drill_hole`).

    Parameters
    ----------
    name : str
        The hole file's ``name``.
    rows : pandas.DataFrame
        One row a depth (``hole.csv``): rods, layer, rate, time to the depth, energies per blow, the energy
        lost in each coupling, the largest stresses and where, efficiencies, regime, the depth's scene file.
    summary : dict
        What ``hole.json`` holds: total time, mean rate, energy per metre, the depth where the rate falls below
        half its start, the largest stresses and where.
    out : pathlib.Path or None
        The folder written (None: a scratch folder, removed).
    runs : dict of str to SegmentRun
        Each run's record (studies.hole.hole_runs.SegmentRun) by its key, ``rods003_layer02``.

    Examples
    --------
    >>> import rpdrill
    >>> drilled = rpdrill.drill_hole("holes/top_hammer_30m", out="runs/hole")  # doctest: +SKIP
    >>> drilled.rows[["depth_m", "rods", "rate_mm_per_s"]].tail(1)  # doctest: +SKIP
    """

    name: str
    rows: pd.DataFrame
    summary: dict[str, Any]
    out: Path | None
    runs: dict[str, SegmentRun] = field(default_factory=dict)


def depth_rows(hole: Hole) -> list[float]:
    """The depths of the rows (module doc)."""
    spec = hole.spec
    depth, length = spec.depth_m, spec.string.rod.length_m
    if spec.depth_step_m == "at_changes":
        changes = {k * length for k in range(spec.string.first_rods, math.ceil(depth / length) + 1)}
        changes |= {layer.to_m for layer in spec.layers}
        return sorted({0.0, depth, *(round(z, 9) for z in changes if 0 < z < depth)})
    step = float(spec.depth_step_m)
    count = math.floor(depth / step + 1e-9)
    return sorted({round(i * step, 9) for i in range(count + 1)} | {depth})


def segments(hole: Hole) -> dict[tuple[int, int], Segment]:
    """The distinct (rods, layer) of the hole's intervals, each with its scene (studies.hole.hole_scenes)."""
    out = {}
    for depth in _breaks(hole):
        key = (hole.rods_at(depth), hole.layer_at(depth))
        if key not in out:
            data = scene_data(hole, *key)
            out[key] = Segment(*key, data, f"scenes/{data['name']}.yaml")
    return out


def _breaks(hole: Hole) -> list[float]:
    """Every depth where the rods or the layer change, the rows and the hole's depth (the ends of the pieces the
    time integral sums over)."""
    spec = hole.spec
    length = spec.string.rod.length_m
    ends = {*depth_rows(hole), *(layer.to_m for layer in spec.layers if layer.to_m < spec.depth_m),
            *(k * length for k in range(spec.string.first_rods, math.ceil(spec.depth_m / length) + 1)
              if k * length < spec.depth_m)}
    return sorted(round(z, 9) for z in ends)


def check_segments(hole: Hole, found: dict[tuple[int, int], Segment], options: RunOptions) -> float:
    """Every segment's scene validated and prepared, its run checked against the budget, before anything runs;
    the estimated CPU seconds of them all."""
    total = 0.0
    for segment in found.values():
        source = f"{hole.source}: the scene at {segment.rods} rods in layers.{segment.layer}"
        simulation = prepare_scene(parse(Scene, segment.data, source), source)
        total += options.budget.check_run(simulation, source).cpu_s
    options.budget.check_total(str(hole.source), "hole", len(found), total)
    return total


def run_segments(hole: Hole, found: dict[tuple[int, int], Segment], out: Path, runner: Any,
                 quiet: bool = True) -> dict[tuple[int, int], SegmentRun]:
    """Each segment's record: read back from ``out/runs`` where its scene is unchanged, else run (by ``runner``,
    studies.runtime.pools) and written there as it finishes; a progress bar in depth."""
    (out / "runs").mkdir(parents=True, exist_ok=True)
    done: dict[tuple[int, int], SegmentRun] = {}
    todo = []
    advise = None if hole.spec.operating == "fixed" else hole.spec.operating.options
    for key, segment in found.items():
        path = out / "runs" / f"{segment.key}.json"
        if path.exists():
            record = SegmentRun.from_json(path.read_text(encoding="utf-8"))
            if record.scene_hash == scene_hash(segment.data, advise):
                done[key] = record
                continue
        todo.append((segment.key, segment.rods, segment.layer, segment.data,
                     f"{hole.source}: {segment.file}", advise))
    lengths = _segment_lengths(hole)
    keys = {segment.key: key for key, segment in found.items()}
    with tqdm(total=hole.spec.depth_m, desc=hole.spec.name, unit="m", disable=quiet,
              bar_format="{l_bar}{bar}| {n:.3g}/{total:.3g} m [{elapsed}<{remaining}]") as bar:
        bar.update(sum(lengths.get(key, 0.0) for key in done))
        for batch in runner(run_segment, todo) if todo else ():
            for record in batch:
                raise_if_stopped()  # an interrupted run is not recorded
                write_atomic(out / "runs" / f"{record.key}.json", record.as_json())
                done[keys[record.key]] = record
                bar.update(lengths.get(keys[record.key], 0.0))
    return done


def _segment_lengths(hole: Hole) -> dict[tuple[int, int], float]:
    """The depth each segment drills."""
    lengths: dict[tuple[int, int], float] = {}
    breaks = _breaks(hole)
    for top, bottom in itertools.pairwise(breaks):
        key = (hole.rods_at(bottom), hole.layer_at(bottom))
        lengths[key] = lengths.get(key, 0.0) + bottom - top
    return lengths


def elapsed_times(hole: Hole, rates: dict[tuple[int, int], float]) -> dict[float, float]:
    """The time to reach each break depth (:func:`_breaks`) at these rates by (rods, layer): the integral of
    dz / rate plus ``rod_change_s`` for each rod added on the way."""
    breaks = _breaks(hole)
    elapsed, clock = {breaks[0]: 0.0}, 0.0
    for top, bottom in itertools.pairwise(breaks):
        rods = hole.rods_at(bottom)
        clock += (rods - hole.rods_at(top)) * hole.spec.rod_change_s  # the rods added to drill below ``top``
        clock += (bottom - top) / rates[(rods, hole.layer_at(bottom))]
        elapsed[bottom] = clock
    return elapsed


def hole_rows(hole: Hole, found: dict[tuple[int, int], Segment], runs: dict[tuple[int, int], SegmentRun]
              ) -> pd.DataFrame:
    """One row a depth (module doc)."""
    spec = hole.spec
    elapsed = elapsed_times(hole, {key: run.rate_m_per_s for key, run in runs.items()})
    advised = spec.operating != "fixed"
    couplings = sorted({name for run in runs.values() for name in run.coupling_lost_j}, key=_coupling_order)
    rows = []
    for depth in depth_rows(hole):
        key = (hole.rods_at(depth), hole.layer_at(depth))
        run, layer = runs[key], spec.layers[key[1]]
        row = {"depth_m": depth, "rods": key[0], "layer": key[1] + 1,
               "rock": layer.rock.get("name", "values given"), "rate_mm_per_s": 1e3 * run.rate_m_per_s,
               "rate_m_per_s": run.rate_m_per_s, "time_s": elapsed[depth],
               "advance_per_blow_m": run.advance_per_blow_m, "rock_energy_per_blow_j": run.rock_energy_per_blow_j,
               "hammer_energy_per_blow_j": run.hammer_energy_per_blow_j,
               "coupling_lost_per_blow_j": sum(run.coupling_lost_j.values()),
               "rock_transfer_efficiency": run.rock_transfer_efficiency,
               "energy_transfer_efficiency": run.energy_transfer_efficiency,
               "compression_max_mpa": run.compression_pa / 1e6, "compression_rod": run.compression_rod,
               "compression_position_m": run.compression_position_m, "tension_max_mpa": run.tension_pa / 1e6,
               "tension_rod": run.tension_rod, "tension_position_m": run.tension_position_m,
               "regime": run.regime, "settle_blows": run.blows, "last_change": run.last_change,
               "scene": advised_file(found[key]) if advised else found[key].file}
        if advised:
            row.update({"fixed_rate_mm_per_s": 1e3 * run.fixed_rate_m_per_s,
                        **{f"advised_{path}": value for path, value in run.operating.items() if value is not None}})
        row.update({f"lost_j_{name}": run.coupling_lost_j.get(name, math.nan) for name in couplings})
        rows.append(row)
    return pd.DataFrame(rows)


def advised_file(segment: Segment) -> str:
    """The file of a segment's scene at its advised operating point."""
    return segment.file.removesuffix(".yaml") + "_advised.yaml"


def _coupling_order(name: str) -> tuple[int, int, str]:
    digits = "".join(ch for ch in name if ch.isdigit())
    return (0 if name.startswith("shank") else 2 if name.startswith("bit") else 1, int(digits or 0), name)


def hole_summary(hole: Hole, rows: pd.DataFrame, runs: dict[tuple[int, int], SegmentRun]) -> dict[str, Any]:
    """The hole's summary (hole.json): total time, mean rate, energy per metre, where the rate falls below half its
    start, the largest stresses and where."""
    spec, breaks = hole.spec, _breaks(hole)
    hammer = rock = drilling = 0.0
    for top, bottom in itertools.pairwise(breaks):
        run = runs[(hole.rods_at(bottom), hole.layer_at(bottom))]
        hammer += (bottom - top) * run.hammer_energy_per_blow_j / run.advance_per_blow_m
        rock += (bottom - top) * run.rock_energy_per_blow_j / run.advance_per_blow_m
        drilling += (bottom - top) / run.rate_m_per_s
    total = float(rows["time_s"].iloc[-1])
    start = float(rows["rate_m_per_s"].iloc[0])
    below = rows[rows["rate_m_per_s"] < 0.5 * start]
    worst = {kind: rows.loc[rows[f"{kind}_max_mpa"].idxmax()] for kind in ("compression", "tension")}
    return {
        "name": spec.name, "hammer": spec.hammer, "depth_m": spec.depth_m, "rows": len(rows), "runs": len(runs),
        "total_time_s": total, "drilling_time_s": drilling,
        "rod_change_time_s": int(rows["rods"].iloc[-1] - spec.string.first_rods) * spec.rod_change_s,
        "rods_added": int(rows["rods"].iloc[-1] - spec.string.first_rods),
        "mean_rate_m_per_s": spec.depth_m / drilling, "start_rate_m_per_s": start,
        "end_rate_m_per_s": float(rows["rate_m_per_s"].iloc[-1]),
        "hammer_energy_per_m_j": hammer / spec.depth_m, "rock_energy_per_m_j": rock / spec.depth_m,
        "half_rate_depth_m": float(below["depth_m"].iloc[0]) if len(below) else None,
        **{f"largest_{kind}": {"stress_mpa": float(row[f"{kind}_max_mpa"]), "depth_m": float(row["depth_m"]),
                               "rod": row[f"{kind}_rod"], "position_m": float(row[f"{kind}_position_m"])}
           for kind, row in worst.items()},
        **({} if spec.operating == "fixed" else _gained(hole, runs, total)),
        "regimes": sorted({run.regime for run in runs.values()}),
        "run_cpu_time_s": sum(run.cpu_time_s for run in runs.values()),
    }


def _gained(hole: Hole, runs: dict[tuple[int, int], SegmentRun], total_s: float) -> dict[str, float]:
    """With ``operating: advise``: the total time at the rig's own operating point and the time gained."""
    fixed = elapsed_times(hole, {key: run.fixed_rate_m_per_s for key, run in runs.items()})
    fixed_total = fixed[max(fixed)]
    return {"fixed_total_time_s": fixed_total, "time_gained_s": fixed_total - total_s}


def write_hole(hole: Hole, result: HoleResult, out: Path) -> list[Path]:
    """hole.csv, hole.json and the figure (studies.hole.hole_figures) into ``out``."""
    from .hole_figures import plot_hole

    write_rows_csv(out / "hole.csv", result.rows.to_dict("records"), list(result.rows.columns))
    write_json(out / "hole.json", {"summary": result.summary, "source": str(hole.source), "rig": hole.rig_source})
    return [out / "hole.csv", out / "hole.json", *plot_hole([result], [hole], out / "hole.png")]


def prepare_out(hole: Hole, found: dict[tuple[int, int], Segment], out: Path, overwrite: bool) -> None:
    """The hole's record and every depth's scene file written into ``out`` before any run; InputError where ``out``
    holds another hole's (unless ``overwrite``)."""
    from ruamel.yaml import YAML

    record = out / RECORD
    resolved = {"hole": hole.spec.model_dump(mode="json"), "source": str(hole.source),
                "segments": {s.key: scene_hash(s.data) for s in found.values()}}
    if record.exists() and not overwrite:
        yaml = YAML(typ="safe")
        before = yaml.load(record.read_text(encoding="utf-8")) or {}
        if before.get("hole") != resolved["hole"]:
            raise InputError(f"--out {out}: holds the runs of another hole file ({before.get('source')}); give a new "
                             "folder, or --overwrite to run this hole there")
    (out / "scenes").mkdir(parents=True, exist_ok=True)
    write_resolved(record, resolved)
    for segment in found.values():
        write_resolved(out / segment.file, segment.data)


def drilled(hole: Hole, found: dict[tuple[int, int], Segment], out: Path, runner: Any,
            options: RunOptions) -> HoleResult:
    """Drill ``hole`` (its segments ``found`` and checked: :func:`segments`, :func:`check_segments`) into ``out``
    (module doc)."""
    prepare_out(hole, found, out, options.overwrite)
    runs = run_segments(hole, found, out, runner, options.quiet)
    for key, run in runs.items():  # each advised point's scene beside the rig's (rpdrill simulate runs it)
        if run.operating:
            write_resolved(out / advised_file(found[key]), apply_changes(found[key].data, run.operating))
    rows = hole_rows(hole, found, runs)
    return HoleResult(hole.spec.name, rows, hole_summary(hole, rows, runs), out,
                      {found[key].key: run for key, run in runs.items()})


def holes_folders(holes: Sequence[Hole], out: Path) -> list[Path]:
    """Where each hole goes: ``out`` for one, ``out/<file name without .yaml>`` for several."""
    if len(holes) == 1:
        return [out]
    return [out / hole.source.stem for hole in holes]
