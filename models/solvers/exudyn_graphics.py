"""Exudyn graphics of the drill, to scale (models.drill.shapes): what a renderer or ``SolutionViewer`` shows.

Every axial body carries its steel cylinder in its ``VObjectMass1D`` (it moves with the body); the
torsion line a disc at the rock body with a bar that shows its angle. A ``Node1D`` has no position,
so Exudyn cannot draw a coordinate connector itself: every link of the chain is drawn as a spring
(a coupling in its own colour) between the current ends of the bodies it joins by the graphics user
function of one ground object, which also carries the rock block and the ground anchors (called only
when a renderer draws; no cost in a run).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from exudyn import graphics  # rocklaw.exudyn_module imported it first (models.solvers.exudyn_model)

from ..definition.drill_string import STEEL_DENSITY_KG_PER_M3
from ..drill.chain import AxialChain, Link
from ..drill.shapes import DEFAULT_DIAMETER_M, Cylinder, Layout

BODY_COLOUR = graphics.color.steelblue
ROD_COLOUR = graphics.color.lightgrey
SPRING_COLOUR = graphics.color.black
COUPLING_COLOUR = graphics.color.red
ROCK_COLOUR = graphics.color.brown
TORSION_COLOUR = graphics.color.orange
SPRING_TURNS = 6


def body_graphics(cylinder: Cylinder, rod: bool) -> list[dict]:
    """The body's cylinder about its centre (local x: the drilling axis)."""
    half = 0.5 * cylinder.length_m
    return [graphics.Cylinder(pAxis=[-half, 0, 0], vAxis=[cylinder.length_m, 0, 0], radius=0.5 * cylinder.diameter_m,
                              radiusInner=0.5 * cylinder.bore_diameter_m or None,
                              color=ROD_COLOUR if rod else BODY_COLOUR, nTiles=24)]


def torsion_graphics(diameter_m: float) -> list[dict]:
    """A disc about local z (the torsion node's axis, turned onto the drilling axis) with a radial bar."""
    thickness = 0.1 * diameter_m
    return [graphics.Cylinder(pAxis=[0, 0, -thickness], vAxis=[0, 0, 2 * thickness], radius=0.6 * diameter_m,
                              color=TORSION_COLOUR, nTiles=24),
            graphics.Brick(centerPoint=[0.3 * diameter_m, 0, 0], size=[0.6 * diameter_m, 0.1 * diameter_m,
                                                                         3 * thickness], color=graphics.color.black)]


def spring_points(start_m: float, end_m: float, radius_m: float, turns: int = SPRING_TURNS) -> list[list[float]]:
    """A zig-zag spring from x = start to x = end in the x-y plane."""
    points = [[start_m, 0.0, 0.0]]
    for i in range(2 * turns):
        points.append([start_m + (i + 0.5) / (2 * turns) * (end_m - start_m), radius_m * (1 if i % 2 == 0 else -1), 0.0])
    points.append([end_m, 0.0, 0.0])
    return points


class DrillGraphics:
    """The ground object's graphics user function: the links as springs between the bodies' current ends."""

    def __init__(self, chain: AxialChain, layout: Layout, nodes: Sequence[Any], coordinate: Any) -> None:
        self.chain, self.layout, self.nodes, self._coordinate = chain, layout, list(nodes), coordinate

    def link_ends_m(self, link: Link, positions_m: Sequence[float]) -> tuple[float, float]:
        """Where the link meets its bodies along the axis: body_a's rock-side end (ground: a joint gap
        before body_b) and body_b's hammer-side end, displaced by the bodies' coordinates."""
        b = self.layout.cylinders[link.body_b]
        if link.body_a is None:
            return b.start_m - self.layout.joint_gap_m, b.start_m + positions_m[link.body_b]
        return self.layout.cylinders[link.body_a].end_m + positions_m[link.body_a], b.start_m + positions_m[link.body_b]

    def links(self, positions_m: Sequence[float]) -> dict[str, list[dict]]:
        """Every link's graphics, by link name, for the chain's positions."""
        out = {}
        for link in self.chain.links:
            start, end = self.link_ends_m(link, positions_m)
            ends = [self.layout.cylinders[i].diameter_m for i in (link.body_a, link.body_b) if i is not None]
            colour = SPRING_COLOUR if link.linear else COUPLING_COLOUR
            out[link.name] = [graphics.Lines(spring_points(start, end, 0.3 * min(ends)), color=colour)]
        return out

    def static(self) -> list[dict]:
        """The rock (a block beyond the rock face) and a ground plate at each link from ground."""
        layout = self.layout
        size = max(c.diameter_m for c in layout.cylinders)
        depth = max(0.1 * layout.length_m, 2 * size) if math.isfinite(layout.length_m) else 2 * size
        shown = [graphics.Brick(centerPoint=[layout.rock_face_m + 0.5 * depth, 0, 0], size=[depth, 3 * size, 3 * size],
                                color=ROCK_COLOUR)]
        for link in self.chain.links:
            if link.body_a is None:
                x = layout.cylinders[link.body_b].start_m - layout.joint_gap_m
                shown.append(graphics.Brick(centerPoint=[x - 0.05 * size, 0, 0], size=[0.1 * size, 2 * size, 2 * size],
                                            color=graphics.color.darkgrey))
        return shown

    def __call__(self, mbs: Any, item_number: Any) -> list[dict]:
        positions = [mbs.GetNodeOutput(node, self._coordinate, configuration=self._visualization) for node in self.nodes]
        return [shape for shapes in self.links(positions).values() for shape in shapes]

    @property
    def _visualization(self) -> Any:
        import exudyn

        return exudyn.ConfigurationType.Visualization


def chain_cylinders(shapes: Layout, chain: AxialChain) -> list[Cylinder]:
    """The drawn cylinder of every body of the dynamic chain: the string's from its layout, a piston's
    bodies (after the string's) as steel cylinders of the default diameter behind the string."""
    cylinders = list(shapes.cylinders)
    start_m = min((c.start_m for c in cylinders), default=0.0)
    for body in chain.bodies[len(cylinders):]:
        length_m = body.mass_kg / (STEEL_DENSITY_KG_PER_M3 * math.pi * DEFAULT_DIAMETER_M**2 / 4)
        start_m -= length_m + shapes.joint_gap_m
        cylinders.append(Cylinder(body.name, "piston", start_m, length_m, DEFAULT_DIAMETER_M))
    return cylinders
