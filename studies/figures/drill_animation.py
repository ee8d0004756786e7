"""The last blows of a run as an animation, and Exudyn's own viewer on a run's solution file.

:func:`write_animation` draws the drill string (studies.figures.drill_drawing) at evenly spaced times over the last
blows of a result of any formulation: every body moved by its displacement since the window's start
and the rock face by the borehole bottom's (from the bit's position at the start: the bit's
penetration into the rock shows), all magnified by one factor stated in the title (default: the
largest body motion in the window drawn as half a connector's space, rounded down to 1, 2 or 5 x a
power of ten). A ``.gif`` is written with Pillow; an ``.mp4`` needs ffmpeg (:func:`movie_writer`).

:func:`view_solution` opens a run folder written by ``rpdrill simulate --animate`` (its
``scene.resolved.yaml`` and Exudyn's coordinates solution file ``solution.txt``) in
``exudyn.interactive.SolutionViewer``: the scene's Exudyn model is built again (the same items, with
their graphics) and the stored coordinates are played on it. It needs a display.
"""

from __future__ import annotations

import math
import shutil
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.animation import FFMpegWriter, FuncAnimation, PillowWriter

from ...models.evaluation.results import SimulationResult
from ...models.solvers.simulation import Simulation
from ...models.steady.steady_run import run_scene
from ..inputs.reading import load_scene
from .drill_drawing import BODY_HEIGHT, draw_string, drawn_layout, figure_title
from .figure_style import plt

if TYPE_CHECKING:
    from ...models.solvers.exudyn_model import ExudynModel

SOLUTION_FILE = "solution.txt"
RESOLVED_SCENE = "scene.resolved.yaml"
FRAMES_PER_BLOW = 20
FRAMES_PER_SECOND = 15


def nice_factor(value: float) -> float:
    """The largest 1, 2 or 5 x 10^n not above ``value`` (> 0)."""
    power = 10.0 ** math.floor(math.log10(value))
    return max(step * power for step in (1.0, 2.0, 5.0) if step * power <= value * (1 + 1e-12))


def movie_writer(path: Path) -> PillowWriter | FFMpegWriter:
    """Pillow for a ``.gif``; ffmpeg for another suffix (ValueError when ffmpeg is not installed)."""
    if path.suffix == ".gif":
        return PillowWriter(fps=FRAMES_PER_SECOND)
    if shutil.which("ffmpeg") is None:
        raise ValueError(f"{path}: writing {path.suffix} needs ffmpeg, which is not installed; write a .gif")
    return FFMpegWriter(fps=FRAMES_PER_SECOND)


def write_animation(result: SimulationResult, path: str | Path, blows: int = 3,
                    magnification: float | None = None) -> float:
    """Write the last ``blows`` blows of ``result`` to ``path`` (module doc); the magnification drawn."""
    path = Path(path)
    writer = movie_writer(path)
    scene, drawing = result.scene, drawn_layout(result.scene)
    period = scene.impact.period_s
    end = result.time_s[-1]
    start = max(result.time_s[0], end - blows * period)
    times = np.linspace(start, end, max(2, round((end - start) / period * FRAMES_PER_BLOW)))
    positions = np.column_stack([np.interp(times, result.time_s, column) for column in result.position_m.T])
    bottom = result.bottom_at(times)
    moved = positions - positions[0]
    rock = bottom - positions[0, result.chain.bit_body]
    # metres of displacement -> drawn x units: lengths are drawn to scale but for shortened bodies
    reach = max(float(np.max(np.abs(moved))), float(np.max(np.abs(rock))), 1e-12)
    factor = magnification or nice_factor(0.5 * drawing.gap / reach)
    fig, ax = plt.subplots(figsize=(14, 3.6), layout="constrained")
    title = figure_title(scene, drawing).splitlines()[0].split(";")[0]

    def frame(k: int) -> None:
        ax.clear()
        low, high = draw_string(ax, scene, drawing, factor * moved[k], labels=False, rock_offset=factor * rock[k])
        ax.set_xlim(drawing.start - 1.6 * drawing.gap, drawing.rock_face + 2.7 * drawing.gap)
        ax.set_ylim(low - 0.3 * BODY_HEIGHT, high + 0.3 * BODY_HEIGHT)
        ax.set_yticks([])
        ax.set_xlabel("position along the drilling axis as drawn (m)")
        ax.set_title(f"{title}: the last {blows} blows, displacements magnified x {factor:g}\n"
                     f"t = {times[k]:.4f} s (blow {times[k] / period:.2f}), bit "
                     f"{1e3 * (positions[k, result.chain.bit_body] - positions[0, result.chain.bit_body]):+.3f} mm, "
                     f"borehole bottom {1e3 * (bottom[k] - bottom[0]):+.3f} mm since the window's start", fontsize=9)

    animation = FuncAnimation(fig, frame, frames=len(times))
    animation.save(path, writer=writer)
    plt.close(fig)
    return factor


def run_with_solution(simulation: Simulation, progress: Callable[[float], None] | None = None,
                      solution: Path | None = None) -> SimulationResult:
    """Run ``simulation`` as its scene asks (models.steady.steady_run.run_scene: a time run, or its steady
    state); with ``solution``, a time run and the Exudyn formulation, write Exudyn's coordinates solution
    file there during the run (every output interval). The other formulations write none."""
    if solution is None or simulation.settings.formulation != "exudyn" \
            or simulation.scene.solver.steady_state != "time":
        return run_scene(simulation, progress=progress)
    from ...models.solvers.exudyn_model import build_exudyn

    model = build_exudyn(simulation)
    model.write_solution(solution)
    return model.solve(progress)


def load_solution(run_dir: str | Path) -> tuple[ExudynModel, dict]:
    """The run folder's scene rebuilt as an Exudyn model and its solution file as Exudyn reads it."""
    from exudyn.utilities import LoadSolutionFile

    from ...models.solvers.exudyn_model import build_exudyn

    run_dir = Path(run_dir)
    model = build_exudyn(load_scene(run_dir / RESOLVED_SCENE))
    return model, LoadSolutionFile(str(run_dir / SOLUTION_FILE), verbose=False)


def view_solution(run_dir: str | Path) -> None:
    """Play a run folder's ``solution.txt`` on its scene's Exudyn model in Exudyn's SolutionViewer (module doc;
    it needs a display: without one Exudyn's renderer aborts the process)."""
    import exudyn.interactive

    model, solution = load_solution(run_dir)
    exudyn.interactive.SolutionViewer(model.mbs, solution)
