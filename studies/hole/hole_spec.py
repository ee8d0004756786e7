"""The hole file (``rpdrill hole HOLE.yaml``): a rig, the string added rod by rod (or a down-the-hole hammer),
the rock column in layers, the depth and its rows, the operating point and the time to add a rod.

Read strictly (unknown keys, wrong types and values refused naming the file and the key path, exit status 2
before anything runs): layers top down that neither overlap nor leave a gap, a depth within the last layer, a
string rod that fits the rig's rod chain (:func:`check_fits`). The rig is a scene file relative to the
hole file, or a shipped scene's name.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

from pydantic import Field, model_validator

from ...models.definition.drill_string import Body
from ...models.definition.scene import Scene
from ...models.definition.validation import InputError, parse
from ..inputs.reading import load_scene, read_yaml
from ..inputs.shipped import shipped_path
from ..inputs.specs import StrictSpec

Positive = Field(gt=0.0)


class StringRod(StrictSpec):
    """One extension rod (or, with a down-the-hole hammer, one drill tube) as a scene's rod body takes it."""

    length_m: float = Positive
    diameter_m: float = Positive
    bore_diameter_m: float | None = Field(None, ge=0.0)
    model: Literal["waves"] = "waves"
    youngs_modulus_pa: float | None = Field(None, gt=0.0)
    density_kg_per_m3: float | None = Field(None, gt=0.0)

    @model_validator(mode="after")
    def _bore_inside(self) -> StringRod:
        if self.bore_diameter_m is not None and self.bore_diameter_m >= self.diameter_m:
            raise ValueError(f"bore_diameter_m {self.bore_diameter_m} must be below diameter_m {self.diameter_m}")
        return self

    def body(self) -> dict[str, Any]:
        """The scene's body entry."""
        return self.model_dump(exclude_none=True)

    @property
    def mass_kg(self) -> float:
        """The rod's mass as the scene's rod body has it (rho A L)."""
        return Body.model_validate(self.body()).total_mass_kg


class Coupling(StrictSpec):
    """A threaded coupling between two wave rods, as the scene's connectors take it (no stiffness: rigid)."""

    type: Literal["spring_damper", "coupling"] | None = None
    stiffness_n_per_m: float | None = Field(None, gt=0.0)
    damping_n_s_per_m: float | None = Field(None, ge=0.0)
    gap_m: float | None = Field(None, ge=0.0)
    sleeve_length_m: float | None = Field(None, gt=0.0)
    sleeve_outer_diameter_m: float | None = Field(None, gt=0.0)


class DrillString(StrictSpec):
    """The rods added one at a time as the hole deepens: ``first_rods`` at the collar."""

    rod: StringRod
    coupling: Coupling | None = None
    first_rods: int = Field(1, ge=1, le=200)


class Layer(StrictSpec):
    """One layer of the rock column, down to ``to_m`` (from the layer above's ``to_m``, or ``from_m``): its rock as
    a scene's ``rock`` takes it (``{name: sandstone}`` or the law's values)."""

    to_m: float = Positive
    from_m: float | None = Field(None, ge=0.0)
    rock: dict[str, Any]


class Advise(StrictSpec):
    """The best operating point at each rod count and layer, as ``rpdrill advise`` takes it (``bounds`` by key path,
    SI units: ``impact.frequency_hz`` and ``feed.force_n`` at least), its search's budget and the simulated time of
    each of its runs (studies.hole.hole_advice)."""

    bounds: dict[str, list[float]]
    power_kw: float | None = Field(None, gt=0.0)
    max_rod_stress_mpa: float | None = Field(None, gt=0.0)
    popsize: int = Field(4, ge=1, le=100)
    max_generations: int = Field(3, ge=1, le=1000)
    seed: int = Field(1, ge=0)
    search_end_time_s: float = Field(0.4, gt=0.0)

    @model_validator(mode="after")
    def _bounds(self) -> Advise:
        for path, pair in self.bounds.items():
            if len(pair) != 2 or not pair[0] < pair[1]:
                raise ValueError(f"bounds.{path}: {pair}: give [low, high] with low below high")
        missing = [path for path in ("impact.frequency_hz", "feed.force_n") if path not in self.bounds]
        if missing:
            raise ValueError(f"bounds: give {' and '.join(missing)} [low, high]")
        return self


class Operating(StrictSpec):
    """``operating: {advise: {...}}``."""

    advise: Advise

    @property
    def options(self) -> dict[str, Any]:
        return self.advise.model_dump()


class HoleSpec(StrictSpec):
    """The hole file (module doc)."""

    name: str
    description: str = ""
    rig: str
    hammer: Literal["top_hammer", "down_the_hole"] = "top_hammer"
    string: DrillString
    layers: list[Layer] = Field(min_length=1, max_length=100)
    depth_m: float = Positive
    depth_step_m: float | Literal["at_changes"] = "at_changes"
    operating: Literal["fixed"] | Operating = "fixed"
    rod_change_s: float = Field(0.0, ge=0.0)
    rig_overrides: dict[str, Any] = Field(default_factory=dict)

    @model_validator(mode="after")
    def _column(self) -> HoleSpec:
        top = 0.0
        for i, layer in enumerate(self.layers):
            start = top if layer.from_m is None else layer.from_m
            if start > top + 1e-12:
                raise ValueError(f"layers.{i}.from_m: {start}: leaves a gap below {top} m (the layer above ends there)")
            if start < top - 1e-12:
                raise ValueError(f"layers.{i}.from_m: {start}: overlaps the layer above, which ends at {top} m")
            if layer.to_m <= top:
                raise ValueError(f"layers.{i}.to_m: {layer.to_m}: overlaps the layer above, which ends at {top} m; "
                                 "layers go top down, each to_m deeper than the last")
            top = layer.to_m
        if self.depth_m > top + 1e-12:
            raise ValueError(f"depth_m: {self.depth_m}: beyond the last layer, which ends at {top} m")
        if isinstance(self.depth_step_m, float) and self.depth_step_m <= 0:
            raise ValueError(f"depth_step_m: {self.depth_step_m}: must be above 0 (or at_changes)")
        return self


@dataclass(frozen=True)
class Hole:
    """A hole file read and checked: its spec, its file, the rig's scene and the rig's file."""

    spec: HoleSpec
    source: Path
    rig: Scene
    rig_source: str

    def rods_at(self, depth_m: float) -> int:
        """The rods (tubes) in the hole to drill the interval just above ``depth_m``."""
        rods = math.ceil(depth_m / self.spec.string.rod.length_m - 1e-9)
        return max(self.spec.string.first_rods, rods)

    def layer_at(self, depth_m: float) -> int:
        """The layer of the interval just above ``depth_m`` (the first layer at the collar)."""
        return next(i for i, layer in enumerate(self.spec.layers) if depth_m <= layer.to_m + 1e-12)


def load_hole(path: str | Path, allow_code: tuple[str, ...] = ()) -> Hole:
    """The hole file at ``path`` (or a shipped hole's name), read and checked (module doc); InputError naming the file
    and the key path otherwise."""
    path = Path(shipped_path(path, "hole", "rpdrill hole"))
    data = read_yaml(path)
    spec = parse(HoleSpec, data, str(path))
    rig_path = shipped_path(spec.rig, "scene", f"{path}: rig")
    rig_file = rig_path if Path(rig_path).is_absolute() or not (path.parent / rig_path).exists() else \
        path.parent / rig_path
    try:
        rig = load_scene(rig_file, allow_code)
    except InputError as error:
        raise InputError(f"{path}: rig: {spec.rig!r}: {error}") from None
    if spec.rig_overrides:
        rig = rig.with_(dict(spec.rig_overrides), f"{path}: rig_overrides")
    hole = Hole(spec, path, rig, str(rig_file))
    check_fits(hole)
    return hole


def rod_chain(scene: Scene) -> list[str]:
    """The bodies from the impact body to the rock body along the connectors (the rig's rod chain)."""
    string = scene.drill_string
    nexts = {c.from_body: c.to_body for c in string.connectors.values() if c.from_body != "ground"}
    chain, body = [string.impact_body], string.impact_body
    while body != string.rock_body and body in nexts and len(chain) <= len(string.bodies):
        body = nexts[body]
        chain.append(body)
    return chain if body == string.rock_body else []


def rig_rods(scene: Scene) -> list[str]:
    """The rig's extension rods: the wave rods of its rod chain between the impact and the rock body."""
    bodies = scene.drill_string.bodies
    return [name for name in rod_chain(scene)[1:-1] if bodies[name].is_rod and bodies[name].model == "waves"]


def check_fits(hole: Hole) -> None:
    """InputError naming the hole file and the key unless the rig has a rod chain with wave rods the string's rod
    replaces, and the rod is no wider than them (the rig's shank and couplings take that rod)."""
    spec, source = hole.spec, hole.source
    chain, rods = rod_chain(hole.rig), rig_rods(hole.rig)
    if not rods:
        shown = " -> ".join(chain) or f"{hole.rig.drill_string.impact_body} .. {hole.rig.drill_string.rock_body}"
        raise InputError(f"{source}: rig: {spec.rig!r}: its rod chain ({shown}) has no wave rod between the impact "
                         "body and the rock body for the string to replace; give a rig with extension rods "
                         "(model: waves) joined by connectors from its impact body to its rock body")
    widest = max(hole.rig.drill_string.bodies[name].diameter_m for name in rods)
    if spec.hammer == "top_hammer" and spec.string.rod.diameter_m > widest + 1e-12:  # (DTH tubes carry no blow)
        raise InputError(f"{source}: string.rod.diameter_m: {spec.string.rod.diameter_m}: does not fit the rig's rod "
                         f"chain ({' -> '.join(chain)}), whose rods are at most {widest} m; give at most {widest}")
