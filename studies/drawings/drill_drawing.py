"""A drawing of the drill string (matplotlib): what a scene builds, every part labelled by its scene name.

Bodies are the steel cylinders of models.drill.shapes along the drilling axis (hammer left, rock right),
their lengths to scale; a body longer than :data:`BREAK_SHARE` of the drawing (a drill pipe of a
kilometre beside a shank of 0.3 m) is drawn shortened to that share, with a break mark and its true
length in its label (a body is shortened by a factor MIN_SHORTENING at least, or drawn to scale).
Labels go on the lowest level where they overlap no other label. Diameters are drawn to their own scale (the thickest body as tall as
:data:`BODY_HEIGHT`), stated in the title. Connectors are drawn in the space between the bodies
they join (schematic length): a spring above the axis, a dashpot below when damped, a coupling as
two open flanges with its gap, a rigid joint (wave rods' faces) as a solid bar; a connector from ground ends on a hatched wall. The rock is a
hatched block at the rock face; the feed and the piston's impact are arrows on the bodies they act on.
:func:`draw` writes the drawing (``.png`` or ``.svg`` by the suffix); :func:`drawn_layout` is where
every body is drawn (the animation, studies.drawings.drill_animation, moves them from there). A built
Exudyn model, or a scene with extensions, is drawn from the system's own graphics instead, every item of
one's own included (studies.drawings.system_drawing).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.axes import Axes
from matplotlib.patches import FancyArrowPatch, Rectangle

from ...models.definition.drill_string import EVERY_BODY, GROUND
from ...models.definition.links import Link
from ...models.definition.scene import Scene
from ...models.drill.shapes import DEFAULT_DIAMETER_M, Layout, axial_order, layout
from ..figures.figure_style import OKABE_ITO, figure
from ..inputs.arguments import built_model_problem, check, either, file_problem, instance_problem
from ..runtime.output_files import check_file_target
from .system_drawing import draw_model

if TYPE_CHECKING:
    from ...models.solvers.exudyn_model import ExudynModel

BREAK_SHARE = 0.35  # the most of the drawing's length one body takes; longer ones are drawn shortened
MIN_SHORTENING = 1.5  # a body is shortened by this factor at least, or drawn to scale
CHAR_SHARE = 0.0052  # the width of a label character as a share of the drawing's width (14 in, 8 pt)
GAP_SHARE = 0.06  # the space drawn for a connector, as a share of the bodies' drawn length
BODY_HEIGHT = 1.0  # the drawn height of the thickest body (diameters to their own scale)
BODY_COLOUR, ROD_COLOUR, ROCK_COLOUR = "#9fb6cd", "#d9d9d9", "#b07b4f"
SPRING_COLOUR, COUPLING_COLOUR = "0.1", OKABE_ITO[5]
FEED_COLOUR, IMPACT_COLOUR = OKABE_ITO[4], OKABE_ITO[5]


@dataclass(frozen=True)
class DrawnBody:
    """Where a chain body (a rod segment too) is drawn: x from ``start`` for ``length``, ``height`` tall."""

    name: str
    group: str
    start: float
    length: float
    height: float
    broken: bool  # drawn shortened (its group longer than BREAK_SHARE of the drawing)

    @property
    def end(self) -> float:
        return self.start + self.length


@dataclass(frozen=True)
class DrawnLayout:
    bodies: tuple[DrawnBody, ...]  # in chain order
    gap: float
    rock_face: float
    shapes: Layout

    @property
    def start(self) -> float:
        return min(b.start for b in self.bodies)

    @property
    def end(self) -> float:
        return max(b.end for b in self.bodies)


def _group_lengths(shapes: Layout) -> dict[str, float]:
    lengths: dict[str, float] = {}
    for cylinder in shapes.cylinders:
        lengths[cylinder.group] = lengths.get(cylinder.group, 0.0) + cylinder.length_m
    return lengths


def drawn_layout(scene: Scene) -> DrawnLayout:
    """Where every body of ``scene`` is drawn (module doc)."""
    shapes = layout(scene)
    lengths = _group_lengths(shapes)
    drawn = dict(lengths)
    for _ in range(len(drawn)):  # shorten the longest while it takes more than its share
        longest = max(drawn, key=drawn.get)
        rest = sum(drawn.values()) - drawn[longest]
        share = BREAK_SHARE / (1 - BREAK_SHARE) * rest
        if rest <= 0 or drawn[longest] <= MIN_SHORTENING * share:
            break
        drawn[longest] = share
    total = sum(drawn.values())
    gap = GAP_SHARE * total
    widest = max(c.diameter_m for c in shapes.cylinders)
    placed: dict[str, DrawnBody] = {}
    x = 0.0
    for group in axial_order(scene):
        scale = drawn[group] / lengths[group]
        for cylinder in (c for c in shapes.cylinders if c.group == group):
            placed[cylinder.name] = DrawnBody(cylinder.name, group, x, cylinder.length_m * scale,
                                              BODY_HEIGHT * cylinder.diameter_m / widest, scale < 1 - 1e-9)
            x += cylinder.length_m * scale
        x += gap
    rock_body = [b for b in placed.values() if b.group == scene.drill_string.foot][-1]
    return DrawnLayout(tuple(placed[c.name] for c in shapes.cylinders), gap, rock_body.end, shapes)


def _zigzag(x0: float, x1: float, y: float, amplitude: float, turns: int = 5) -> tuple[np.ndarray, np.ndarray]:
    lead = 0.15 * (x1 - x0)
    xs = [x0, x0 + lead, *np.linspace(x0 + lead, x1 - lead, 2 * turns + 1)[1:-1], x1 - lead, x1]
    ys = [y, y, *[y + amplitude * (1 if i % 2 == 0 else -1) for i in range(2 * turns - 1)], y, y]
    return np.array(xs), np.array(ys)


def _dashpot(ax: Axes, x0: float, x1: float, y: float, size: float, colour: str) -> None:
    middle, width = 0.5 * (x0 + x1), 0.25 * (x1 - x0)
    ax.plot([x0, middle + 0.2 * width], [y, y], color=colour, lw=1)
    ax.plot([middle - width, middle + width, middle + width, middle - width],
            [y + size, y + size, y - size, y - size], color=colour, lw=1)  # the cylinder, open to the left
    ax.plot([middle + 0.2 * width] * 2, [y - 0.7 * size, y + 0.7 * size], color=colour, lw=1.5)  # the piston
    ax.plot([middle + width, x1], [y, y], color=colour, lw=1)


def _coupling(ax: Axes, x0: float, x1: float, size: float) -> None:
    """Two flanges facing each other across the gap."""
    middle, flange = 0.5 * (x0 + x1), 0.12 * (x1 - x0)
    for start, end, face in ((x0, middle - flange, middle - flange), (x1, middle + flange, middle + flange)):
        ax.plot([start, end], [0, 0], color=COUPLING_COLOUR, lw=1.5)
        ax.plot([face, face], [-size, size], color=COUPLING_COLOUR, lw=3)


def _wall(ax: Axes, x: float, height: float) -> None:
    ax.add_patch(Rectangle((x - 0.25 * height, -height), 0.25 * height, 2 * height, facecolor="0.85",
                           edgecolor="0.3", hatch="///", lw=0.8))


def _connector(ax: Axes, drawing: DrawnLayout, link: Link, level: float) -> tuple[float, float]:
    """Draw one link between the ends it joins; the x of its middle and the y below which its label goes."""
    b = drawing.bodies[link.body_b]
    if link.body_a is None:
        x0 = b.start - drawing.gap
        _wall(ax, x0, 0.6 * BODY_HEIGHT)
    else:
        x0 = drawing.bodies[link.body_a].end
    x1 = b.start
    height = min(b.height, drawing.bodies[link.body_a].height if link.body_a is not None else b.height)
    size = 0.18 * max(height, 0.3 * BODY_HEIGHT)
    if x1 < x0:  # not neighbours along the axis: an arc over the bodies between
        x0, x1 = x1, x0
    span_neighbours = link.body_a is None or abs(link.body_b - link.body_a) == 1 or x1 - x0 <= 1.5 * drawing.gap
    if not span_neighbours:
        top = 1.2 * BODY_HEIGHT
        ax.plot([x0, x0, x1, x1], [0, top, top, 0], color=SPRING_COLOUR, lw=0.8, ls=":")
        return 0.5 * (x0 + x1), level
    if link.rigid:  # the faces joined as one: a solid bar
        ax.plot([x0, x1], [0, 0], color=COUPLING_COLOUR, lw=3)
    elif link.linear:
        xs, ys = _zigzag(x0, x1, 0.35 * size if link.damping_n_s_per_m > 0 else 0.0, size)
        ax.plot(xs, ys, color=SPRING_COLOUR, lw=1)
        if link.damping_n_s_per_m > 0:
            _dashpot(ax, x0, x1, -1.4 * size, 0.6 * size, SPRING_COLOUR)
    else:
        _coupling(ax, x0, x1, size)
    return 0.5 * (x0 + x1), level


def _number(value: float) -> str:
    return f"{value:,.0f}" if abs(value) >= 1e4 else f"{value:.4g}"


def _body_label(scene: Scene, group: str, drawing: DrawnLayout) -> str:
    body = scene.drill_string.bodies[group]
    length = sum(c.length_m for c in drawing.shapes.cylinders if c.group == group)
    text = f"{group}\n{_number(body.total_mass_kg)} kg, {_number(length)} m"
    if body.is_wave:
        text += "\nwaves"
    elif body.segments > 1:
        text += f"\n{body.segments} segments"
    return text


def _connector_label(link: Link, gap_m: float | None) -> str:
    if link.rigid:  # a joint of rigid faces without a stiffness (models.drill.chain)
        return f"{link.name}\nrigid"
    text = f"{link.name}\nk {_number(link.stiffness_n_per_m / 1e6)} MN/m"
    if link.damping_n_s_per_m > 0:
        text += f"\nc {_number(link.damping_n_s_per_m / 1e3)} kN s/m"
    if gap_m is not None:
        text += f"\ngap {gap_m * 1e3:.3g} mm"
    return text


def _arrow(ax: Axes, x: float, y: float, length: float, colour: str, text: str) -> None:
    ax.add_patch(FancyArrowPatch((x - length, y), (x, y), arrowstyle="-|>", mutation_scale=14, color=colour, lw=2,
                                 zorder=5))
    ax.text(x, y + 0.06 * BODY_HEIGHT, text, color=colour, fontsize=8, ha="right", va="bottom", zorder=5)


def draw_string(ax: Axes, scene: Scene, drawing: DrawnLayout | None = None, offsets: np.ndarray | None = None,
                labels: bool = True, rock_offset: float = 0.0) -> tuple[float, float]:
    """Draw the drill string of ``scene`` on ``ax``; ``offsets`` (drawn x units, one per chain body) and
    ``rock_offset`` move the bodies and the rock face (the animation); without ``labels`` the names, values and
    arrows are left out. The y range drawn."""
    from ...models.drill.chain import axial_chain

    drawing = drawing or drawn_layout(scene)
    chain = axial_chain(scene)
    offsets = np.zeros(len(drawing.bodies)) if offsets is None else offsets
    moved = DrawnLayout(tuple(DrawnBody(b.name, b.group, b.start + dx, b.length, b.height, b.broken)
                              for b, dx in zip(drawing.bodies, offsets, strict=True)),
                        drawing.gap, drawing.rock_face, drawing.shapes)
    rods = {name for name, body in scene.drill_string.bodies.items() if body.is_rod}
    for body in moved.bodies:
        ax.add_patch(Rectangle((body.start, -0.5 * body.height), body.length, body.height, lw=0.8, edgecolor="0.2",
                               facecolor=ROD_COLOUR if body.group in rods else BODY_COLOUR, zorder=2))
        if body.broken:  # a break mark across the middle
            middle, h = body.start + 0.5 * body.length, 0.5 * body.height
            for dx in (-0.01, 0.01):
                shift = dx * drawing.end
                ax.plot([middle + shift - 0.15 * h, middle + shift + 0.15 * h], [-1.3 * h, 1.3 * h],
                        color="0.2", lw=1.2, zorder=4)
            ax.add_patch(Rectangle((middle - 0.01 * drawing.end, -0.5 * body.height),
                                   0.02 * drawing.end, body.height, facecolor="white", edgecolor="none",
                                   zorder=3))
    # the rock: a hatched block from the rock face (a connector's gap deep on the drawing)
    depth = 2.5 * drawing.gap
    rock = scene.rock.law != "none"  # a string that ends free: no rock drawn
    if rock:
        ax.add_patch(Rectangle((drawing.rock_face + rock_offset, -0.7 * BODY_HEIGHT), depth, 1.4 * BODY_HEIGHT,
                               facecolor=ROCK_COLOUR, edgecolor="0.3", hatch="..", lw=0.8, alpha=0.8, zorder=1))
    connector_x = []
    gaps = {name: c.gap_m for name, c in scene.drill_string.connectors.items()}
    for link in chain.links:
        if link.name in gaps or link.body_a is None:
            connector_x.append((link, _connector(ax, moved, link, 0.0)[0]))
    if not labels:
        return -0.8 * BODY_HEIGHT, 0.8 * BODY_HEIGHT
    width = drawing.rock_face + 4 * drawing.gap - drawing.start
    above, below = _Levels(width), _Levels(width)
    groups: dict[str, list[DrawnBody]] = {}
    for body in drawing.bodies:
        groups.setdefault(body.group, []).append(body)
    for group, parts in groups.items():
        centre, text = 0.5 * (parts[0].start + parts[-1].end), _body_label(scene, group, drawing)
        y = 0.75 * BODY_HEIGHT + 0.62 * BODY_HEIGHT * above.place(centre, text)
        ax.annotate(text, (centre, 0.5 * parts[0].height), (centre, y), fontsize=8, ha="center", va="bottom",
                    arrowprops={"arrowstyle": "-", "color": "0.5", "lw": 0.6})
    for link, x in connector_x:
        text = _connector_label(link, gaps.get(link.name))
        y = -0.85 * BODY_HEIGHT - 0.75 * BODY_HEIGHT * below.place(x, text)
        ax.annotate(text, (x, -0.2 * BODY_HEIGHT), (x, y), fontsize=8, ha="center", va="top",
                    color=COUPLING_COLOUR if not link.linear else "0.1",
                    arrowprops={"arrowstyle": "-", "color": "0.5", "lw": 0.6})
    if rock:
        ax.text(drawing.rock_face + 0.5 * depth, 0, f"rock\n{_rock_text(scene)}", ha="center", va="center",
                fontsize=8, zorder=5, bbox={"facecolor": "white", "alpha": 0.7, "edgecolor": "none"})
    arrow = 0.8 * drawing.gap
    impact = drawing.bodies[chain.impact_body]
    _arrow(ax, impact.start, 0.42 * BODY_HEIGHT, arrow, IMPACT_COLOUR, _impact_text(scene))
    fed = [parts for group, parts in groups.items() if scene.feed.acts_on in (EVERY_BODY, group)]
    for k, parts in enumerate(fed if scene.feed.force_n > 0 else []):
        body = parts[0]
        x = parts[0].start + 0.3 * (parts[-1].end - parts[0].start)
        ax.add_patch(FancyArrowPatch((x - 0.3 * drawing.gap, -0.22 * body.height), (x, -0.22 * body.height),
                                     arrowstyle="-|>", mutation_scale=12, color=FEED_COLOUR, lw=2, zorder=5))
        if k == 0:
            each = " on each body" if scene.feed.acts_on == EVERY_BODY else ""
            ax.text(x - 0.3 * drawing.gap, -0.12 * body.height, f"feed {scene.feed.force_n / 1e3:.3g} kN{each}",
                    color=FEED_COLOUR, fontsize=8, ha="left", va="bottom", zorder=5)
    return -(0.85 + 0.75 * len(below.rows) + 0.5) * BODY_HEIGHT, (0.75 + 0.62 * len(above.rows) + 0.45) * BODY_HEIGHT


class _Levels:
    """Label rows: a label goes on the lowest row where it overlaps no label already there."""

    def __init__(self, width: float) -> None:
        self.width, self.rows = width, []

    def place(self, centre: float, text: str) -> int:
        half = 0.5 * CHAR_SHARE * self.width * max(len(line) for line in text.splitlines()) + 0.005 * self.width
        for level, row in enumerate(self.rows):
            if all(centre + half < start or centre - half > end for start, end in row):
                row.append((centre - half, centre + half))
                return level
        self.rows.append([(centre - half, centre + half)])
        return len(self.rows) - 1


def _impact_text(scene: Scene) -> str:
    """The impact arrow's label: the prescribed pulse's amplitude, or the piston's mass and strike speed."""
    impact = scene.impact
    if impact.piston is None:
        return f"impact {impact.amplitude_n / 1e3:.4g} kN, {impact.frequency_hz:.4g} Hz"
    piston = impact.piston
    return (f"piston {piston.total_mass_kg:.3g} kg at {piston.strike_velocity_m_per_s:.3g} m/s, "
            f"{impact.frequency_hz:.4g} Hz")


def _rock_text(scene: Scene) -> str:
    rock = scene.rock.completed()
    if rock.own_law:
        return f"law {rock.law.partition(':')[2]}"
    if rock.law == "bilinear":
        return (f"k_l {_number(rock.loading_stiffness_n_per_m / 1e6)} MN/m\n"
                f"k_u {_number(rock.unloading_stiffness_n_per_m / 1e6)} MN/m")
    name = f"{rock.name}\n" if rock.name else ""
    return f"{name}k_n {_number(rock.stiffness_n_per_m / 1e6)} MN/m\nF_th {_number(rock.threshold_n / 1e3)} kN"


def figure_title(scene: Scene, drawing: DrawnLayout) -> str:
    widest = max(c.diameter_m for c in drawing.shapes.cylinders)
    broken = sorted({b.group for b in drawing.bodies if b.broken})
    parts = [f"{scene.name}: the drill string (hammer left, rock right); lengths to scale"
             + (f" except {', '.join(broken)} (shortened, break mark)" if broken else ""),
             (f"diameters to their own scale (thickest {widest * 1e3:.0f} mm); bodies without a stated diameter "
              f"drawn as steel cylinders of {DEFAULT_DIAMETER_M * 1e3:.0f} mm; connectors schematic")]
    return "\n".join(parts)


def draw(scene: Scene | ExudynModel, path: str | Path) -> Path:
    """Draw the scene's drill string to scale, every part labelled, into ``path`` (PNG or SVG by its suffix).

    A built Exudyn model (:func:`build_exudyn`), or a scene with extensions (drawn as its built model), is
    drawn from the system's own graphics with every item of one's own (studies.drawings.system_drawing).
    Drawn without pyplot: the caller's matplotlib is left as it is.

    Parameters
    ----------
    scene : Scene or ExudynModel
        The scene, or a built model.
    path : str or pathlib.Path
        The image file; its folder must exist.

    Returns
    -------
    pathlib.Path
        The file written.

    Raises
    ------
    InputError
        When ``scene`` is neither a scene nor a built model, or ``path`` cannot be written.

    Examples
    --------
    >>> import rpdrill
    >>> rpdrill.draw(rpdrill.load_scene("paper_base"), "drill.svg")
    PosixPath('drill.svg')
    """
    check("rpdrill.draw", "scene", scene, either(built_model_problem, instance_problem(
        Scene, "a rpdrill.Scene (rpdrill.load_scene) or a built model (rpdrill.build_exudyn)")))
    check("rpdrill.draw", "path", path, file_problem)
    path = check_file_target("rpdrill.draw: path", path)  # its folder must exist: refused now, not at the end
    if not isinstance(scene, Scene) or scene.extensions:
        from ...models.solvers.exudyn_model import build_exudyn  # Exudyn only for a model

        return draw_model(build_exudyn(scene) if isinstance(scene, Scene) else scene, path)
    drawing = drawn_layout(scene)
    width = drawing.rock_face + 2.5 * drawing.gap - drawing.start
    fig = figure(figsize=(14, 4.6), layout="constrained")
    ax = fig.subplots()
    ax.set_ylim(*draw_string(ax, scene, drawing))
    ax.set_xlim(drawing.start - 1.6 * drawing.gap, drawing.rock_face + 2.7 * drawing.gap)
    ax.set_yticks([])
    ax.set_xlabel(f"position along the drilling axis as drawn (m; {width:.3g} m shown)")
    for side in ("left", "right", "top"):
        ax.spines[side].set_visible(False)
    ax.set_title(figure_title(scene, drawing), fontsize=9)
    fig.savefig(path, dpi=130)
    return path


__all__ = ["GROUND", "DrawnLayout", "draw", "draw_string", "drawn_layout"]
