"""The rotation-speed note (docs/rotation.md), generated from the two rotation studies: the rpm x
frequency map of one rock with its optimum ridge, and the model's best speed for the Epiroc COP M
manual's DTH example against the manual's rule.

    rpdrill rotation-report RUNS_DIR --out DIR [--rock sandstone] [--docs docs]

RUNS_DIR holds ``rpm_frequency_map/`` and ``dth_example/`` as written by ``rpdrill study
studies/rotation/<name>.yaml --out RUNS_DIR/<name>``. The figure is written beside the note. Nothing
in the note is typed by hand: the numbers come from the results tables and the studies' resolved
scenes.
"""

from __future__ import annotations

import json
import math
import shlex
import shutil
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ...models.definition.scene import Bit
from ...models.drill.indexing import Indexing
from ..display.catalogue import metric
from ..figures.rotation_map import draw_rotation_map
from ..inputs.arguments import boolean_problem, check, folder_problem, instance_problem, optional
from ..inputs.reading import InputError
from ..runtime.output_files import check_out, staged_directory, write_atomic
from ..runtime.tables import read_table

if TYPE_CHECKING:
    import pandas as pd

RATE, ADVANCE = "penetration_rate_m_per_s", "advance_per_blow_m"
SPEED, FREQUENCY, ROCK = "rotation.speed_rpm", "impact.frequency_hz", "rock.name"
# The manual's rule: rpm = 1600 d / (pi D) at 2160 blows per minute, i.e. the gauge buttons move
# 1600 / 2160 = 0.741 button diameters per blow.
MANUAL_RPM_FACTOR, MANUAL_BLOWS_PER_MINUTE = 1600.0, 2160.0
MANUAL_INDEX_PER_BUTTON = MANUAL_RPM_FACTOR / MANUAL_BLOWS_PER_MINUTE
CHALK_SPIRAL_MM = (10.0, 19.0)  # the manual's field check: penetration per turn
TIE = 1e-6  # relative: rates closer than this are equal (aliased speeds give the same rate to round-off)
DRILLED = 0.01  # a frequency counts as drilled where its best rate reaches 1 % of the rock's best on the map


def manual_speed_rpm(bit: Bit, frequency_hz: float) -> float:
    """The manual's starting speed, rpm = 0.741 d (60 f) / (pi D) (1600 d / (pi D) at 2160 blows/min)."""
    return MANUAL_INDEX_PER_BUTTON * bit.gauge_button_diameter_m * 60.0 * frequency_hz / (math.pi * bit.diameter_m)


def _rows(results: Path) -> pd.DataFrame:
    """A study's results table without its failed points and those without a rate (unsettled ones kept: their
    values stand; a metric that is not a finite number is empty: models.evaluation.run_status)."""
    table = read_table(results)
    return table[(table["status"] != "failed") & table[RATE].notna()]


def _study(run: Path) -> dict:
    return json.loads((run / "study.json").read_text())


def _bit(run: Path) -> Bit:
    return Bit.model_validate(_study(run)["resolved_study"]["base_scene"]["bit"])


def _by_rock(table: pd.DataFrame) -> dict[str, pd.DataFrame]:
    """The rows of each rock, sorted by rotation speed."""
    return {rock: members.sort_values(SPEED, kind="stable") for rock, members in table.groupby(ROCK, sort=False)}


def dth_rows(run: Path) -> tuple[list[str], float, float]:
    """Table rows of the DTH example per rock; (rows, frequency, the model's best speed)."""
    bit, rows = _bit(run), _rows(run / "results.csv")
    frequency = float(_study(run)["resolved_study"]["base_scene"]["impact"]["frequency_hz"])
    manual, best = manual_speed_rpm(bit, frequency), Indexing(bit, None, frequency).best_speed_rpm()
    lines = []
    for rock, members in _by_rock(rows).items():
        speeds, rates = members[SPEED].to_numpy(dtype=float), members[RATE].to_numpy(dtype=float)
        top = int(np.argmax(rates >= rates.max() - TIE * abs(rates.max())))  # the slowest of equal rates
        if rates[top] <= 0:
            lines.append(f"| {rock} | no penetration at any speed | 0 | 0 | - |")
            continue
        at_manual = rates[int(np.argmin(np.abs(speeds - manual)))]
        per_turn_mm = 1e3 * rates[top] * 60.0 / speeds[top]
        lines.append(f"| {rock} | {speeds[top]:g} | {rates[top] * 1e3:.3g} | {at_manual * 1e3:.3g} "
                     f"({at_manual / rates[top]:.0%}) | {per_turn_mm:.2g} |")
    return lines, frequency, best


def ridge_points(run: Path) -> list[tuple[str, float, float, float, float]]:
    """(rock, frequency, best scanned speed, rate there, the model's best speed 60 f w / (pi D)) at every
    frequency where the rock is drilled (the best rate at least DRILLED of the rock's best on the map)."""
    bit, found = _bit(run), []
    for rock, members in _by_rock(_rows(run / "results.csv")).items():
        best: dict[float, tuple[float, float]] = {}
        for speed, frequency, rate in zip(*(members[c].to_numpy(dtype=float) for c in (SPEED, FREQUENCY, RATE)),
                                          strict=True):
            # the slowest of equal rates: speeds whose index per blow differ by a button pitch are aliases
            if frequency not in best or rate > best[frequency][1] + TIE * abs(best[frequency][1]):
                best[frequency] = (float(speed), float(rate))
        peak = max(rate for _, rate in best.values())
        found += [(rock, frequency, speed, rate, Indexing(bit, None, frequency).best_speed_rpm())
                  for frequency, (speed, rate) in sorted(best.items()) if rate > 0 and rate >= DRILLED * peak]
    return found


def render(runs: Path, figure: Path, rock: str, made_by: str) -> str:
    map_run, dth_run = (runs / name for name in STUDIES)
    bit = _bit(dth_run)
    dth, frequency, best = dth_rows(dth_run)
    manual = manual_speed_rpm(bit, frequency)
    speeds = _study(map_run)["resolved_study"]["scan"][SPEED]
    step = speeds[1] - speeds[0]
    crater_mm, pitch_mm = 1e3 * bit.crater_m, 1e3 * math.pi * bit.diameter_m / bit.gauge_buttons
    ridge_points_ = ridge_points(map_run)
    table = "\n".join(f"| {rock} | {f:g} | {speed:g} | {rate * 1e3:.3g} | {model:.1f} | {speed / model - 1:+.0%} |"
                      for rock, f, speed, rate, model in ridge_points_)
    table = table or "| no rock drilled on the map | - | - | - | - | - |"
    far = max(ridge_points_, key=lambda p: abs(p[2] / p[4] - 1), default=None)
    furthest = (f" (the furthest here: {far[0]} at {far[1]:g} Hz, {far[2]:g} rpm against {far[4]:.1f} rpm)"
                if far else "")
    spiral_rate = [mm * manual / 60.0 for mm in CHALK_SPIRAL_MM]
    at_manual = Indexing(bit, manual, frequency)
    meets, share = at_manual.regime(at_manual.prescribed_angle_rad), at_manual.fresh_fraction(at_manual.prescribed_angle_rad)
    return f"""# Rotation speed: the model's best indexing against the manual's rule

Generated by {made_by}, from the runs of
`rpdrill study studies/rotation/rpm_frequency_map.yaml --out {runs}/rpm_frequency_map` and
`rpdrill study studies/rotation/dth_example.yaml --out {runs}/dth_example`
(exact formulation, the drill of `studies/scenes/dth_drill.yaml`, bit indexing on:
`models/drill/indexing.py`, docs/model.md); do not edit by hand.

## The DTH example

Bit {1e3 * bit.diameter_m:g} mm, gauge buttons {1e3 * bit.gauge_button_diameter_m:g} mm
({bit.gauge_buttons} on the gauge circle, pitch {pitch_mm:.3g} mm), crater width {crater_mm:g} mm,
{frequency * 60:g} blows per minute. The manual's starting speed: 1600 d / (pi D) =
**{manual:.1f} rpm** (the gauge buttons move {MANUAL_INDEX_PER_BUTTON:.3f} d per blow). The model's best
speed: **{best:.1f} rpm**, one crater width per blow ({best / manual - 1:+.0%} against the manual). At the
manual's speed each blow meets a {meets}: a share eta = {share:.2f} of it on fresh rock.

| rock | best speed in the scan (rpm) | rate there (mm/s) | rate at the manual's speed (share of best) | penetration per turn at best (mm) |
|---|---|---|---|---|
{chr(10).join(dth)}

Why the model turns faster than the manual:

* The model's optimum is where a gauge button lands one crater width from the last crater (the craters
  just touch): it is the assumed crater width, here the button diameter (`bit.crater_width_m` left
  out). The manual's 0.74 d per blow is the model's optimum for a crater 0.74 d wide; a crater as wide
  as the button is the model's assumption, not a measurement. Give `bit.crater_width_m` to move it.
* The model values penetration only: it has no button wear. The manual sets its rule as a start
  (its four methods: the 1600 d / (pi D) rule gives the highest speed, the chalk spiral and the wear
  of the buttons lower ones), because turning faster drags the buttons over the rock; a rule that
  balances wear against penetration sits below the penetration optimum.
* Penetration per turn is far below the manual's chalk spiral ({CHALK_SPIRAL_MM[0]:g}-{CHALK_SPIRAL_MM[1]:g}
  mm per turn, i.e. {spiral_rate[0]:.3g}-{spiral_rate[1]:.3g} mm/s at its {manual:.1f} rpm): the drill
  at {frequency:g} Hz, far from its resonance, drills much slower than a {1e3 * bit.diameter_m:g} mm DTH
  hammer. The spiral checks the drill's penetration, not the indexing model.

## The rpm x frequency map ({rock})

![penetration rate over rotation speed and impact frequency]({figure.name})

The white ridge is the best scanned speed at each frequency ({step:g} rpm steps), the dashed lines the
model's best speed 60 f w / (pi D) and the manual's rule 0.741 d (60 f) / (pi D): the optimum is a
constant index per blow, so the best speed grows in proportion to the blow frequency. Above half
the button pitch per blow ({pitch_mm / 2:.3g} mm) the gauge buttons approach the next button's last
crater and the share of fresh rock rises again (a second ridge at an index of pitch - crater width).

The drill drills in bands of frequency around the rock modes (docs/reproduction.md); outside
them the rate is zero or a few um/s. At each frequency where a rock is drilled (its best rate at least
{DRILLED:.0%} of the rock's best on the map), the best scanned speed ({step:g} rpm steps) against the
model's geometric best speed:

| rock | frequency (Hz) | best scanned speed (rpm) | rate there (mm/s) | 60 f w / (pi D) (rpm) | difference |
|---|---|---|---|---|---|
{table}

Away from a drill resonance the rate falls on both sides of the geometric best speed (less fresh rock
per blow: re-crushed craters below it, ridges above it). Close to a resonance the dynamics can move
it: a share of re-crushed rock stiffens the crushing contact (its force hardens along k_n (1 - eta)),
which shifts the drill's resonance; where that gains more than the lost share, the best speed moves
off the geometric one{furthest}.
"""


STUDIES = ("rpm_frequency_map", "dth_example")  # studies/rotation/<name>.yaml, run into RUNS_DIR/<name>


def check_runs(runs: Path, rock: str) -> None:
    """InputError unless ``runs`` holds both studies' results and the map has rows of ``rock``."""
    for name in STUDIES:
        for file in ("results.csv", "study.json"):
            if not (runs / name / file).is_file():
                raise InputError(f"{runs}: {name}/{file}: missing; run `rpdrill study studies/rotation/{name}.yaml "
                                 f"--out {runs / name}` first")
    rocks = sorted(_by_rock(_rows(runs / STUDIES[0] / "results.csv")))
    if rock not in rocks:
        raise InputError(f"--rock: {rock!r}: not on the map in {runs / STUDIES[0]}; rocks there: {', '.join(rocks)}")


def write_report(runs: Path, out: Path, rock: str, made_by: str) -> list[Path]:
    """rotation.md and the map of ``rock`` (PNG and SVG) into ``out``; the files written."""
    figure = out / f"rotation_map_{rock}.png"
    run = runs / STUDIES[0]
    table = _rows(run / "results.csv")
    bit = _bit(run)
    draw_rotation_map(table[table[ROCK] == rock], figure, f"{rock}: {metric(RATE).label()}",
                      lambda f: Indexing(bit, None, f).best_speed_rpm(), lambda f: manual_speed_rpm(bit, f), DRILLED)
    note = out / "rotation.md"
    write_atomic(note, render(runs, figure, rock, made_by))
    return [note, figure, figure.with_suffix(".svg")]


@dataclass(frozen=True)
class RotationReport:
    """The rotation-speed note (:func:`rotation_report`).

    Parameters
    ----------
    text : str
        The note in Markdown.
    files : list of pathlib.Path
        The files written into ``out`` (the note and the map, PNG and SVG; none without ``out``).
    ridge : pandas.DataFrame
        Per rock and drilled frequency the best scanned speed, the rate there and the model's best speed
        60 f w / (pi D) (columns ``rock``, ``frequency_hz``, ``best_speed_rpm``, ``penetration_rate_m_per_s``,
        ``model_speed_rpm``).
    out : pathlib.Path or None
        The folder written.

    Examples
    --------
    >>> import rpdrill
    >>> note = rpdrill.rotation_report("runs/rotation")  # doctest: +SKIP
    >>> print(note.text)  # doctest: +SKIP
    """

    text: str
    files: list[Path]
    ridge: pd.DataFrame
    out: Path | None


def rotation_report(runs: str | Path, out: str | Path | None = None, rock: str = "sandstone",
                    docs: str | Path | None = None, overwrite: bool = False) -> RotationReport:
    """The rotation-speed note (docs/rotation.md) from the two rotation studies' results: ``rpdrill
    rotation-report`` as a library call (module doc).

    Parameters
    ----------
    runs : str or pathlib.Path
        The folder holding ``rpm_frequency_map/`` and ``dth_example/``, as written by ``rpdrill study
        studies/rotation/<name>.yaml --out RUNS/<name>``.
    out : str or pathlib.Path, optional
        Where the note and its map go (new, empty or an earlier report's); without, a scratch folder removed
        after.
    rock : str, default "sandstone"
        The rock of the map.
    docs : str or pathlib.Path, optional
        Where the note and map are also copied (with ``out``).
    overwrite : bool, default False
        Write ``out`` whatever it holds.

    Returns
    -------
    RotationReport
        The note, the files written and the map's ridge.

    Raises
    ------
    InputError
        When a study's results or the rock are missing, before anything is written.

    Examples
    --------
    >>> import rpdrill
    >>> note = rpdrill.rotation_report("runs/rotation", out="runs/rotation_note")  # doctest: +SKIP
    >>> note.ridge.head()  # doctest: +SKIP
    """
    import pandas as pd

    where = "rpdrill.rotation_report"
    check(where, "runs", runs, folder_problem)
    check(where, "out", out, optional(folder_problem))
    check(where, "rock", rock, instance_problem(str, "a rock's name (text)"))
    check(where, "docs", docs, optional(folder_problem))
    check(where, "overwrite", overwrite, boolean_problem)
    runs = Path(runs)
    folder = None if out is None else check_out(out, overwrite, "rotation.md")
    docs_folder = None if docs is None else check_out(docs, True, option="--docs")
    check_runs(runs, rock)
    words = ["rpdrill", "rotation-report", str(runs), *(["--out", str(out)] if out is not None else [])]
    words += (["--rock", rock] if rock != "sandstone" else []) + (["--docs", str(docs)] if docs is not None else [])
    with tempfile.TemporaryDirectory(prefix="rpdrill-rotation-") as scratch:
        target = folder or Path(scratch) / "rotation"
        with staged_directory(target) as stage:
            written = [target / p.name for p in write_report(runs, stage, rock, f"`{shlex.join(words)}`")]
        text = written[0].read_text(encoding="utf-8")
    if folder is not None and docs_folder is not None:
        docs_folder.mkdir(parents=True, exist_ok=True)
        for path in written:
            shutil.copy(path, docs_folder / path.name)
    ridge = pd.DataFrame(ridge_points(runs / STUDIES[0]), columns=["rock", "frequency_hz", "best_speed_rpm",
                                                                     "penetration_rate_m_per_s", "model_speed_rpm"])
    return RotationReport(text, written if folder is not None else [], ridge, folder)
