"""A drawing of an Exudyn system from its own graphics, headless (matplotlib): what Exudyn's renderer shows,
seen from the side (the x-y plane; x the drilling axis), for a built model with every item of one's own.

Every object Exudyn shows is drawn where the system's coordinates put it: its graphics data (triangle
lists as filled polygons, lines, circles, spheres, texts) moved and turned with its body, and an object's
graphics user function (the drill's links and rock: models.solvers.exudyn_graphics) called as the renderer
calls it. A body without graphics data (a ``Mass1D`` or mass point of one's own) is a dot labelled with its
name and mass; a connector without graphics data (Exudyn's spring-dampers, which its renderer draws
itself) a zig-zag between the points it joins, labelled with its name; an item of one's own is drawn in
its own colour. A drill is often long beside its struck end (a drill pipe of a kilometre): the whole
system is drawn in one panel and the part from the impact body to the rock in a second, each with x and
y to their own scales (a drill is thin beside its length).

:func:`draw_model` writes the drawing of a model (``rpdrill.draw`` of a model); :func:`draw_system` draws
one configuration on axes (the animation of a model, studies.drawings.drill_animation, draws each frame).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.collections import PolyCollection
from matplotlib.patches import Circle

from ..figures.figure_style import OKABE_ITO, figure

USER_COLOUR = OKABE_ITO[6]  # items of one's own
CONNECTOR_KINDS = ("Connector", "Contact")  # objectType prefixes of items joining two markers


def _exudyn() -> Any:
    import exudyn

    return exudyn


def set_configuration(mbs: Any, coordinates: Sequence[float] | None) -> None:
    """Put ``coordinates`` (the system's ODE2 coordinates; None: the initial ones) in Exudyn's visualization
    configuration, which the drawing reads."""
    exu = _exudyn()
    if not mbs.systemIsConsistent:
        mbs.Assemble()
    data = mbs.systemData
    if coordinates is None:
        coordinates = data.GetODE2Coordinates(configuration=exu.ConfigurationType.Initial)
    data.SetODE2Coordinates(list(map(float, coordinates)), configuration=exu.ConfigurationType.Visualization)


def _pose(mbs: Any, index: int, item: dict[str, Any]) -> tuple[np.ndarray, np.ndarray] | None:
    """(position, rotation) of a body object in the visualization configuration; None for a connector."""
    exu = _exudyn()
    if item["objectType"].startswith(CONNECTOR_KINDS):
        return None
    if item["objectType"] == "Ground":
        return np.asarray(item.get("referencePosition", np.zeros(3)), dtype=float), np.eye(3)
    visual = exu.ConfigurationType.Visualization
    try:
        position = np.asarray(mbs.GetObjectOutputBody(index, exu.OutputVariableType.Position, [0.0, 0.0, 0.0], visual))
    except Exception:  # noqa: BLE001 - an object without a position (a node-less item): not drawn
        return None
    try:
        rotation = np.reshape(mbs.GetObjectOutputBody(index, exu.OutputVariableType.RotationMatrix, [0.0, 0.0, 0.0],
                                                      visual), (3, 3))
    except Exception:  # noqa: BLE001 - a point mass: no rotation
        rotation = np.eye(3)
    return position, rotation


def _marker_point(mbs: Any, marker: int, bodies: dict[int, int]) -> np.ndarray | None:
    """Where a marker is: its position, or for a coordinate marker the body on its node (``bodies``: node ->
    body object; None on ground)."""
    exu = _exudyn()
    item = mbs.GetMarker(marker)
    if not item["markerType"].endswith("Coordinate"):
        return np.asarray(mbs.GetMarkerOutput(marker, exu.OutputVariableType.Position,
                                              exu.ConfigurationType.Visualization), dtype=float)
    index = bodies.get(int(item["nodeNumber"]))  # a coordinate has no position: the body on its node
    pose = None if index is None else _pose(mbs, index, mbs.GetObject(index))
    return None if pose is None else pose[0]


def _flat_triangles(shape: dict[str, Any]) -> dict[str, Any]:
    """A triangle list with its 6-node (curved) triangles as flat ones (Exudyn's own conversion)."""
    from exudyn import graphics

    return graphics.Triangles6ToTriangles(shape) if "triangles6" in shape else shape


def _zigzag(start: np.ndarray, end: np.ndarray, width: float, turns: int = 6) -> np.ndarray:
    along, length = end[:2] - start[:2], float(np.linalg.norm(end[:2] - start[:2]))
    if length == 0:
        return np.array([start[:2], end[:2]])
    normal = np.array([-along[1], along[0]]) / length
    steps = np.linspace(0.0, 1.0, 2 * turns + 1)
    offsets = [0.0, *(width * (1 if i % 2 else -1) for i in range(1, 2 * turns)), 0.0]
    return np.array([start[:2] + s * along + o * normal for s, o in zip(steps, offsets, strict=True)])


Tag = tuple[np.ndarray, str, bool, int]  # a label: the point it names, its text, of one's own, above (1) or below (-1)


class _Solid:
    """One triangle list of a body, its artist made once and moved with the body (painter's order by depth)."""

    def __init__(self, ax: Axes, shape: dict[str, Any]) -> None:
        shape = _flat_triangles(shape)
        self.points = np.reshape(shape["points"], (-1, 3))
        self.triangles = np.reshape(shape.get("triangles", []), (-1, 3)).astype(int)
        colours = np.reshape(shape.get("colors", []), (-1, 4))
        colours = colours if len(colours) == len(self.points) else np.full((len(self.points), 4), 0.6)
        self.colours = np.clip(colours[self.triangles].mean(axis=1), 0.0, 1.0)
        self.artist = ax.add_collection(PolyCollection([], edgecolors="none", zorder=2))

    def place(self, position: np.ndarray, rotation: np.ndarray) -> np.ndarray:
        points = self.points @ rotation.T + position
        order = np.argsort(points[self.triangles, 2].mean(axis=1))  # far side first
        self.artist.set_verts(points[self.triangles[order], :2])
        self.artist.set_facecolor(self.colours[order])
        return points


class SystemPicture:
    """An Exudyn system drawn on axes (module doc), its artists made once: :meth:`show` puts it in a
    configuration (an animation shows one after the other). Objects from number ``own`` on are of one's own
    (their colour); ``names`` names the others."""

    def __init__(self, ax: Axes, mbs: Any, own: int = 0, names: dict[int, str] | None = None) -> None:
        self.ax, self.mbs, names = ax, mbs, names or {}
        set_configuration(mbs, None)
        self.bodies: list[tuple[int, dict[str, Any], list[Any], Any]] = []  # index, item, solids and lines, function
        self.joins: list[tuple[int, dict[str, Any], Any]] = []
        self.tags: list[tuple[int, str, bool, int]] = []  # object, text, of one's own, side
        self.drawn: list[Any] = []  # the artists of the graphics user functions, made again each time
        self.on_node: dict[int, int] = {}  # node -> the body object on it
        for index in range(mbs.systemData.NumberOfObjects()):
            item = mbs.GetObject(index, addGraphicsData=True)
            if not item.get("Vshow", True):
                continue
            user, name = index >= own, names.get(index, item["name"])
            if "nodeNumber" in item and not item["objectType"].startswith(CONNECTOR_KINDS):
                self.on_node.setdefault(int(item["nodeNumber"]), index)
            if _pose(mbs, index, item) is None:
                if "markerNumbers" in item:
                    self.joins.append((index, item, ax.plot([], [], color=USER_COLOUR if user else "0.1", lw=1.0,
                                                            zorder=4)[0]))
                    if user or index in names:
                        self.tags.append((index, name, user, -1))
                continue
            parts = [_Solid(ax, shape) if shape.get("type") == "TriangleList" else shape
                     for shape in item.get("VgraphicsData") or []]
            function = item.get("VgraphicsDataUserFunction")
            function = function.get("function") if isinstance(function, dict) else function
            inertia = item.get("mass", item.get("inertia"))
            if not parts and not callable(function):
                if inertia is None:
                    continue
                parts = [ax.plot([], [], "o", color=USER_COLOUR if user else "0.3", ms=7, zorder=6)[0]]
            self.bodies.append((index, item, parts, function if callable(function) else None))
            if user or index in names:
                unit = "kg" if "mass" in item else "kg m^2"
                self.tags.append((index, f"{name}\n{inertia:.4g} {unit}" if user and inertia is not None else name, user, 1))

    def show(self, coordinates: Sequence[float] | None = None) -> tuple[np.ndarray, list[Tag]]:
        """The system at ``coordinates`` (its ODE2 coordinates; None: the initial ones): the points drawn
        and the labels (:func:`label`)."""
        set_configuration(self.mbs, coordinates)
        for artist in self.drawn:
            artist.remove()
        self.drawn, points, where = [], [], {}
        for index, _, parts, function in self.bodies:
            position, rotation = _pose(self.mbs, index, self.mbs.GetObject(index))
            where[index] = position
            for part in parts:
                if isinstance(part, _Solid):
                    points.append(part.place(position, rotation))
                elif isinstance(part, dict):
                    points += self._shape(part, position, rotation)
                else:  # a body without graphics: a dot
                    part.set_data([position[0]], [position[1]])
                    points.append(position[None, :])
            if function is not None:  # its shapes in the object's frame, as the renderer places them
                for shape in function(self.mbs, index):
                    points += self._shape(shape, position, rotation)
        span = np.ptp(np.vstack(points), axis=0) if points else np.ones(3)
        for index, item, line in self.joins:
            ends = [_marker_point(self.mbs, marker, self.on_node) for marker in item["markerNumbers"][:2]]
            if ends[0] is None and ends[1] is None:
                continue
            if ends[0] is None or ends[1] is None:  # from ground: a short stub before the body
                end = ends[1] if ends[1] is not None else ends[0]
                ends = [end - np.array([0.02 * max(span[0], 1e-3), 0, 0]), end]
            length = float(np.linalg.norm(ends[1][:2] - ends[0][:2]))
            if length < 1e-6 * max(span[0], 1e-3):  # coincident ends (a joint of two coordinates): a ring
                line.set_data([ends[0][0]], [ends[0][1]])
                line.set(marker="o", mfc="none", ms=11, linestyle="none", mec=line.get_color())
            else:
                zigzag = _zigzag(ends[0], ends[1], 0.12 * length)
                line.set_data(zigzag[:, 0], zigzag[:, 1])
            where[index] = 0.5 * (ends[0] + ends[1])
        tags = [(where[index], text, user, side) for index, text, user, side in self.tags if index in where]
        return (np.vstack(points) if points else np.zeros((1, 3))), tags

    def _shape(self, shape: dict[str, Any], position: np.ndarray, rotation: np.ndarray) -> list[np.ndarray]:
        """Draw one shape that is not a body's triangle list (made again at every :meth:`show`)."""
        ax, kind = self.ax, shape.get("type")
        if kind == "TriangleList":
            solid = _Solid(ax, shape)
            self.drawn.append(solid.artist)
            return [solid.place(position, rotation)]
        if kind == "Line":
            points = np.reshape(shape["data"], (-1, 3)) @ rotation.T + position
            self.drawn += ax.plot(points[:, 0], points[:, 1], color=tuple(np.clip(shape["color"], 0, 1)), lw=0.8,
                                  zorder=3)
            return [points]
        if kind in ("Circle", "Text"):
            point = rotation @ np.asarray(shape["position"], dtype=float) + position
            self.drawn.append(ax.add_patch(Circle(point[:2], shape["radius"], fill=False, color="0.2", zorder=3))
                              if kind == "Circle" else ax.text(point[0], point[1], shape["text"], fontsize=7, zorder=5))
            return [point[None, :]]
        if kind == "Spheres":
            points = np.reshape(shape["points"], (-1, 3)) @ rotation.T + position
            self.drawn += [ax.add_patch(Circle(point[:2], radius, color="0.5", zorder=3))
                           for point, radius in zip(points, np.ravel(shape["radii"]), strict=False)]
            return [points]
        return []


def draw_system(ax: Axes, mbs: Any, coordinates: Sequence[float] | None = None, own: int = 0,
                names: dict[int, str] | None = None) -> tuple[np.ndarray, list[Tag]]:
    """Draw ``mbs`` at ``coordinates`` once (:class:`SystemPicture`): the points drawn (for the view's limits)
    and the labels of the named items and of one's own (:func:`label` places them once the limits are set)."""
    return SystemPicture(ax, mbs, own, names).show(coordinates)


CHAR_WIDTH = 0.0055  # a label character's width as a share of the axes' width (14 in, 7 pt)


def label(ax: Axes, tags: list[Tag]) -> None:
    """Labels in rows along the top (bodies) and the bottom (connectors) of the axes, each on the first row
    where it overlaps no other, with a line to the point it names; points outside the view are left out."""
    low, high = ax.get_xlim()
    rows: dict[int, list[list[tuple[float, float]]]] = {1: [], -1: []}
    for point, text, user, side in sorted(tags, key=lambda tag: tag[0][0]):
        if not low <= point[0] <= high:
            continue
        x = (point[0] - low) / (high - low)
        half = 0.5 * CHAR_WIDTH * max(len(line) for line in text.splitlines()) + 0.004
        level = next((k for k, row in enumerate(rows[side]) if all(x + half < a or x - half > b for a, b in row)),
                     len(rows[side]))
        if level == len(rows[side]):
            rows[side].append([])
        rows[side][level].append((x - half, x + half))
        y = 0.97 - 0.11 * level if side > 0 else 0.03 + 0.11 * level
        ax.annotate(text, point[:2], (x, y), textcoords="axes fraction", ha="center", va="top" if side > 0 else "bottom",
                    fontsize=7, color=USER_COLOUR if user else "0.25", zorder=7,
                    bbox={"facecolor": "white", "alpha": 0.8, "edgecolor": "none", "pad": 1},
                    arrowprops={"arrowstyle": "-", "color": "0.6", "lw": 0.5})


def _window(model: Any, points: np.ndarray) -> tuple[float, float, float]:
    """The x range from the impact body to the rock (with a margin) and the y half-height that shows the
    bodies there and every point drawn in that range."""
    shapes = model.graphics.layout
    low, high = shapes.cylinders[model.chain.impact_body].start_m, shapes.rock_face_m
    margin = 0.15 * (high - low) + 0.05
    low, high = low - margin, high + margin
    inside = points[(points[:, 0] >= low) & (points[:, 0] <= high)]
    widest = max(c.diameter_m for c in shapes.cylinders)
    return low, high, max(1.5 * widest, 1.2 * float(np.max(np.abs(inside[:, 1]), initial=0.0)))


def draw_model(model: Any, path: str | Path, coordinates: Sequence[float] | None = None, title: str | None = None) -> Path:
    """Write the drawing of a built model (module doc) to ``path`` (PNG or SVG by its suffix)."""
    path = Path(path)
    model.prepare()
    own = model.built_items["objects"]
    names = {int(body.object): name for name, body in model.bodies.items()}
    names.update({int(c.object): name for name, c in model.connectors.items()})
    points, _ = draw_system(figure().add_subplot(), model.mbs, coordinates, own, names)
    low, high, half = _window(model, points)
    whole_too = np.ptp(points[:, 0]) > 3 * (high - low)  # else the part near the rock is most of the system
    fig = figure(figsize=(14, 7.5 if whole_too else 4.4), layout="constrained")
    axes = fig.subplots(2 if whole_too else 1, 1, squeeze=False)
    told = ", ".join(f"{count} {kind}" for kind, count in model.user_items().items()) or "none"
    heading = (title or f"{model.simulation.name}: the Exudyn system from its graphics, seen from the side") + \
        f"\nitems of one's own (labelled in this colour): {told}"
    near = axes[-1, 0]
    if whole_too:
        whole = axes[0, 0]
        draw_system(whole, model.mbs, coordinates, own, names)
        (x_low, y_low), (x_high, y_high) = points[:, :2].min(axis=0), points[:, :2].max(axis=0)
        whole.set_xlim(x_low - 0.02 * (x_high - x_low), x_high + 0.02 * (x_high - x_low))
        whole.set_ylim(y_low - 0.1 * (y_high - y_low), y_high + 0.1 * (y_high - y_low))
        whole.set_title(f"{heading}; the whole system", fontsize=9)
    _, tags = draw_system(near, model.mbs, coordinates, own, names)
    near.set_xlim(low, high)
    near.set_ylim(-2 * half, 2 * half)  # room for the labels above and below
    label(near, tags)
    near.set_title(("" if whole_too else f"{heading}\n") +
                   "from the impact body to the rock (x and y to their own scales: see the axes)", fontsize=9)
    for ax in axes[:, 0]:
        ax.set_xlabel("x along the drilling axis (m)")
        ax.set_ylabel("y (m)")
    fig.savefig(path, dpi=130)
    return path
