"""The drill string as steel cylinders along the drilling axis: what Exudyn's graphics and the drawings show.

A rod is drawn from its geometry (outer and bore diameter; each of its N segments L / N long; a rod
carried as waves as its two faces' halves, one cylinder per node of the chain as for segments). Any
other body is a solid cylinder of its ``diameter_m`` (a rigid body may state one) or
:data:`DEFAULT_DIAMETER_M`, as long as its ``length_m`` (a pipe) or, for a rigid ``mass_kg``, as long
as that mass of its density (steel unless given) makes it: L = m / (rho pi D^2 / 4). The shapes do
not enter the dynamics (the chain's masses and stiffnesses do).

At rest the bodies follow one another along +x (into the rock) from the hammer to the rock
(:func:`axial_order`: along the connectors, whatever order a file lists them in), a rod's
segments end to end, other neighbours :attr:`Layout.joint_gap_m` apart (room to draw the connector
between them); the rock face is at the far end of the rock body.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..definition.drill_string import Body
from ..definition.scene import Scene

DEFAULT_DIAMETER_M = 0.15  # a rigid body without a stated diameter: about a 6 in drill collar


@dataclass(frozen=True)
class Cylinder:
    """One chain body (a rod segment ``rod[0]``, a wave rod's face ``rod[top]`` too) as a cylinder along the
    axis, at rest."""

    name: str
    group: str  # the scene's body name
    start_m: float  # hammer-side end
    length_m: float
    diameter_m: float
    bore_diameter_m: float = 0.0

    @property
    def end_m(self) -> float:
        return self.start_m + self.length_m

    @property
    def centre_m(self) -> float:
        return self.start_m + 0.5 * self.length_m


@dataclass(frozen=True)
class Layout:
    """Every chain body's cylinder in chain order, the gap left between bodies and the rock face."""

    cylinders: tuple[Cylinder, ...]
    joint_gap_m: float
    rock_face_m: float

    def __getitem__(self, name: str) -> Cylinder:
        return next(c for c in self.cylinders if c.name == name)

    @property
    def length_m(self) -> float:
        return self.rock_face_m - self.cylinders[0].start_m


def body_size_m(body: Body) -> tuple[float, float, float]:
    """(length, outer diameter, bore diameter) of a scene body as drawn (module doc)."""
    if body.is_rod:
        return body.length_m, body.diameter_m, body.bore_diameter_m
    diameter = body.diameter_m or DEFAULT_DIAMETER_M
    if body.length_m is not None:
        return body.length_m, diameter, 0.0
    return body.total_mass_kg / (body.density_kg_per_m3 * math.pi * diameter**2 / 4), diameter, 0.0


def axial_order(scene: Scene) -> list[str]:
    """The scene's bodies from the hammer to the rock: every connector's ``from`` before its ``to`` (the
    scene's order where the connectors leave it open), whatever order the file lists them in."""
    names = list(scene.drill_string.bodies)
    before = {name: set() for name in names}
    for connector in scene.drill_string.connectors.values():
        if connector.from_body in before:
            before[connector.to_body].add(connector.from_body)
    order: list[str] = []
    while len(order) < len(names):
        ready = next(name for name in names if name not in order and before[name] <= set(order))
        order.append(ready)
    return order


def layout(scene: Scene) -> Layout:
    """The cylinders of ``scene``'s drill string at rest, in chain order (module doc)."""
    bodies = scene.drill_string.bodies
    sizes = {name: body_size_m(body) for name, body in bodies.items()}
    gap = max(diameter for _, diameter, _ in sizes.values())
    placed: dict[str, list[Cylinder]] = {}
    x = 0.0
    for name in axial_order(scene):
        length, diameter, bore = sizes[name]
        parts = [f"{name}[{i}]" for i in range(bodies[name].segments)] if bodies[name].segments > 1 else [name]
        if bodies[name].is_wave:  # the chain's two face nodes (models.drill.chain): each drawn as half the rod
            parts = [f"{name}[top]", f"{name}[bottom]"]
        placed[name] = []
        for part in parts:
            placed[name].append(Cylinder(part, name, x, length / len(parts), diameter, bore))
            x += length / len(parts)
        x += gap
    cylinders = tuple(cylinder for name in bodies for cylinder in placed[name])  # the chain's order
    return Layout(cylinders, gap, placed[scene.drill_string.foot][-1].end_m)
