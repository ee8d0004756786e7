"""The last blows of a run as an animation, and Exudyn's own viewer on a run's solution file.

:func:`write_animation` draws the drill string (studies.drawings.drill_drawing) at evenly spaced times over the last
blows of a result of any formulation: every body moved by its displacement since the window's start
and the rock face by the borehole bottom's (from the bit's position at the start: the bit's
penetration into the rock shows), all magnified by one factor stated in the title (default: the
largest body motion in the window drawn as half a connector's space, rounded down to 1, 2 or 5 x a
power of ten). A ``.gif`` is written with Pillow; an ``.mp4`` needs ffmpeg (:func:`movie_writer`).

:func:`view_solution` opens a run folder written by ``rpdrill simulate --animate`` (its
``scene.resolved.yaml`` and Exudyn's coordinates solution file ``solution.txt``) in
``exudyn.interactive.SolutionViewer``: the scene's Exudyn model is built again (the same items, with
their graphics, its extensions applied) and the stored coordinates are played on it; or a model that
ran with ``model.write_solution(path)``. It needs a display.

A built Exudyn model (``rpdrill.build_exudyn``, items of one's own added) is animated from its own
graphics (:func:`model_animation`, studies.drawings.system_drawing) at the coordinates of its solution file.
"""

from __future__ import annotations

import io
import math
import shutil
import tempfile
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.animation import AbstractMovieWriter, FFMpegWriter
from matplotlib.figure import Figure
from PIL import Image

from ...models.evaluation.results import SimulationResult
from ...models.evaluation.run_result import Result
from ..figures.figure_style import figure, keep_layout
from ..inputs.arguments import (
    built_model_problem,
    check,
    count_problem,
    either,
    file_problem,
    folder_problem,
    instance_problem,
    optional,
    positive_problem,
)
from ..inputs.reading import InputError, load_scene
from ..runtime.output_files import check_file_target
from .drill_drawing import BODY_HEIGHT, draw_string, drawn_layout, figure_title
from .system_drawing import SystemPicture

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


class GifWriter(AbstractMovieWriter):
    """A ``.gif`` written with Pillow, as matplotlib's ``PillowWriter`` writes it, but each frame reduced to a
    palette of 256 colours as it is grabbed, by Pillow's fast octree: 5 ms a 1400 x 360 frame, against 44 ms for
    the median cut Pillow's GIF writer applies to a full-colour frame (a drawing's few flat colours and their
    anti-aliased edges fit either palette). ``python benchmarks/bench_figures.py --base REV`` measures it."""

    def setup(self, fig: Figure, outfile: str | Path, dpi: float | None = None) -> None:
        super().setup(fig, outfile, dpi=dpi)
        self.frames: list[Image.Image] = []

    def grab_frame(self, **savefig_kwargs: object) -> None:
        buffer = io.BytesIO()
        self.fig.savefig(buffer, **{**savefig_kwargs, "format": "rgba", "dpi": self.dpi})
        frame = Image.frombuffer("RGBA", self.frame_size, buffer.getbuffer(), "raw", "RGBA", 0, 1)
        self.frames.append(frame.quantize(method=Image.Quantize.FASTOCTREE))

    def finish(self) -> None:
        self.frames[0].save(self.outfile, save_all=True, append_images=self.frames[1:],
                            duration=int(1000 / self.fps), loop=0)


def movie_writer(path: Path) -> GifWriter | FFMpegWriter:
    """Pillow for a ``.gif`` (:class:`GifWriter`); ffmpeg for another suffix (ValueError when ffmpeg is not
    installed)."""
    if path.suffix == ".gif":
        return GifWriter(fps=FRAMES_PER_SECOND)
    if shutil.which("ffmpeg") is None:
        raise ValueError(f"{path}: writing {path.suffix} needs ffmpeg, which is not installed; write a .gif")
    return FFMpegWriter(fps=FRAMES_PER_SECOND)


def save_frames(fig: Figure, frame: Callable[[int], None], count: int, path: Path, writer: AbstractMovieWriter) -> None:
    """Write ``count`` frames of ``fig`` to ``path``, ``frame(k)`` drawing the k-th: each drawn once (a
    FuncAnimation draws each frame twice when it saves)."""
    with writer.saving(fig, str(path), fig.dpi):
        for k in range(count):
            frame(k)
            writer.grab_frame()


def write_animation(result: SimulationResult | Result | ExudynModel, path: str | Path, blows: int = 3,
                    magnification: float | None = None) -> float:
    """Animate the last blows of a run into ``path`` (``.gif`` with Pillow; ``.mp4`` needs ffmpeg; module doc).

    Every body moves by its displacement since the window's start, the rock face by the borehole bottom's, all
    magnified by one factor stated in the title. A built Exudyn model is drawn from its own graphics, every item
    of one's own included, at the coordinates of its solution file (:func:`model_animation`).

    Parameters
    ----------
    result : Result, SimulationResult or ExudynModel
        A run of :func:`simulate` (or its raw result), or a built model that ran with a solution file.
    path : str or pathlib.Path
        The animation file.
    blows : int, default 3
        The blows drawn, the last ones of the run.
    magnification : float, optional
        The factor displacements are drawn with (default: the largest motion drawn as half a connector's space,
        rounded down to 1, 2 or 5 x a power of ten).

    Returns
    -------
    float
        The magnification drawn.

    Raises
    ------
    InputError
        When an argument cannot be used.

    Examples
    --------
    >>> import rpdrill
    >>> scene = rpdrill.load_scene("paper_base").with_({"solver.end_time_s": 0.3})
    >>> rpdrill.write_animation(rpdrill.simulate(scene, formulation="exact"), "drill.gif")  # doctest: +SKIP
    200.0
    """
    where = "rpdrill.write_animation"
    result = result.raw if isinstance(result, Result) else result
    check(where, "result", result, either(built_model_problem, instance_problem(
        SimulationResult, "the Result of rpdrill.simulate or a built model (rpdrill.build_exudyn)")))
    check(where, "path", path, file_problem)
    check(where, "blows", blows, count_problem)
    check(where, "magnification", magnification, optional(positive_problem))
    path = check_file_target(f"{where}: path", path)  # its folder must exist: refused now, not at the end
    if not isinstance(result, SimulationResult):
        return model_animation(result, path, blows, magnification)
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
    fig = figure(figsize=(14, 3.6), layout="constrained")
    ax = fig.subplots()
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

    frame(0)
    fig.draw_without_rendering()
    keep_layout(fig)  # laid out once: each frame's drawing, its title and labels keep the first frame's margins
    save_frames(fig, frame, len(times), path, writer)
    return factor


def load_solution(run: str | Path | ExudynModel, allow_code: Sequence[str] | str = ()) -> tuple[ExudynModel, dict]:
    """A run's Exudyn model and its solution file as Exudyn reads it: a run folder's scene rebuilt (its
    extensions applied: ``allow_code``, the modules of one's own it may run, models.definition.own_code) and its
    ``solution.txt``, or a model that ran with ``model.write_solution(path)``.
    InputError when the solution does not fit the model (a run with items added in Python that its scene
    does not name)."""
    from exudyn.utilities import LoadSolutionFile

    from ...models.solvers.exudyn_model import build_exudyn

    if isinstance(run, (str, Path)):
        check("rpdrill.view_solution", "run", run, folder_problem)
        scene = load_scene(Path(run) / RESOLVED_SCENE, allow_code)
        source, model = Path(run) / SOLUTION_FILE, build_exudyn(scene)
    elif built_model_problem(run) is not None:
        check("rpdrill.view_solution", "run", run, built_model_problem)
    elif run.solution_path is None:
        raise InputError("the model wrote no solution file: call model.write_solution(path) before model.run()")
    else:
        source, model = run.solution_path, run
    solution = LoadSolutionFile(str(source), verbose=False)
    stored, built = solution["columnsExported"][0], model.coordinate_count
    if stored != built:
        raise InputError(f"{source}: {stored} coordinates, but the model built from its scene has {built}: the run "
                         "had items added in Python that the scene does not name; give them as an extension "
                         "(docs/extending.md) or pass the model that ran: view_solution(model)")
    return model, solution


def view_solution(run: str | Path | ExudynModel, allow_code: Sequence[str] | str = ()) -> None:
    """Play a run in Exudyn's SolutionViewer (module doc; it needs a display: without one Exudyn's renderer aborts
    the process).

    Parameters
    ----------
    run : str, pathlib.Path or ExudynModel
        A folder of ``rpdrill simulate --animate`` (its ``scene.resolved.yaml`` and ``solution.txt``: the scene's
        model built again, its extensions applied), or a model that ran with ``model.write_solution(path)``.
    allow_code : sequence of str or str, default ()
        The modules of one's own the run's scene may run (its extensions; models.definition.own_code).

    Returns
    -------
    None

    Raises
    ------
    InputError
        When the folder holds no run, or the solution does not fit the model (a run with items added in Python
        that its scene does not name).

    Examples
    --------
    >>> import rpdrill
    >>> # a folder of `rpdrill simulate paper_base --out out/run --animate`
    >>> rpdrill.view_solution("out/run")  # doctest: +SKIP
    """
    import exudyn.interactive

    model, solution = load_solution(run, allow_code)
    exudyn.interactive.SolutionViewer(model.mbs, solution)


def model_animation(model: ExudynModel, path: str | Path, blows: int = 3, magnification: float | None = None) -> float:
    """The last ``blows`` blows of a built model drawn from its own graphics (studies.drawings.system_drawing)
    at the coordinates of its solution file (``model.write_solution``), displacements magnified; a model that
    has not run and has no solution file is run first, writing one into a scratch folder. The magnification
    drawn."""
    path = Path(path)
    writer = movie_writer(path)
    if model.solution_path is not None and model.solution_path.exists():
        _, solution = load_solution(model)
    elif model.has_run:
        raise InputError("the model ran without a solution file: call model.write_solution(path) before model.run()")
    else:
        with tempfile.TemporaryDirectory(prefix="rpdrill-animation-") as scratch:
            model.write_solution(Path(scratch) / SOLUTION_FILE)
            model.run()
            _, solution = load_solution(model)
            model.solution_path = None  # the scratch folder goes
    data = solution["data"]
    period = model.simulation.impact.period_s
    end = data[-1, 0]
    start = max(data[0, 0], end - blows * period)
    rows = np.unique(np.searchsorted(data[:, 0], np.linspace(start, end, max(2, round((end - start) / period *
                                                                                  FRAMES_PER_BLOW)))).clip(0, len(data) - 1))
    coordinates = data[rows, 1:1 + model.coordinate_count]
    moved = coordinates - coordinates[0]
    own = model.built_items["objects"]
    names = {int(body.object): name for name, body in model.bodies.items()}
    fig = figure(figsize=(14, 3.6), layout="constrained")
    ax = fig.subplots()
    picture = SystemPicture(ax, model.mbs, own, names)
    points, _ = picture.show(coordinates[0])
    shapes = model.graphics.layout
    low = shapes.cylinders[model.chain.impact_body].start_m
    low, high = low - 0.15 * (shapes.rock_face_m - low), shapes.rock_face_m + 0.15 * (shapes.rock_face_m - low)
    half = 1.5 * max(max(c.diameter_m for c in shapes.cylinders), float(np.max(np.abs(points[:, 1]))))
    reach = max(float(np.max(np.abs(moved))), 1e-12)
    factor = magnification or nice_factor(0.02 * (high - low) / reach)

    ax.set_xlim(low, high)
    ax.set_ylim(-half, half)
    ax.set_xlabel("x along the drilling axis (m)")

    def frame(k: int) -> None:
        picture.show(coordinates[0] + factor * moved[k])
        ax.set_title(f"{model.simulation.name}: the Exudyn system from its graphics, the last {blows} blows, "
                     f"displacements magnified x {factor:g}\nt = {data[rows[k], 0]:.4f} s "
                     f"(blow {data[rows[k], 0] / period:.2f}); items of one's own in this colour", fontsize=9)

    frame(0)
    fig.draw_without_rendering()
    keep_layout(fig)  # laid out once: every frame is drawn as the first (a layout per frame costs)
    save_frames(fig, frame, len(rows), path, writer)
    return factor
