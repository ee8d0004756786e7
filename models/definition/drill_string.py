"""The drill of a scene: the drill string's bodies (rigid, rods, pipes) and connectors with their checks
(names, one chain without loops joining every body to the rock), the torsion line, the bit face, the
rotation and the feed; the strict base of every scene section and the located validation errors they
raise. Data only (models.definition.scene holds the rest of the scene)."""

from __future__ import annotations

import math
import re
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import AfterValidator, BaseModel, ConfigDict, Field, model_validator
from pydantic_core import InitErrorDetails, PydanticCustomError, ValidationError

from .links import LINK_TYPES
from .outputs import LINK_SERIES, SERIES

Positive = Annotated[float, Field(gt=0)]
NonNegative = Annotated[float, Field(ge=0)]
# Counts are bounded so that no count makes a float overflow or an array beyond memory.
MAX_COUNT = 10**6
# A body or connector name: an identifier, so that no name collides with a generated one (the
# segments ``rod[0]`` of a segmented rod, its links ``rod[0-1]``).
NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]{0,63}")


def _name(value: str) -> str:
    if not NAME.fullmatch(value):
        raise ValueError(f"{value!r} is not a name: letters, digits and _, starting with a letter or _, at most 64 "
                         "characters (generated names such as rod[0] are reserved)")
    return value


Name = Annotated[str, AfterValidator(_name)]


class Strict(BaseModel):
    """Unknown keys are errors (a unit typo such as ``force_kn`` must not pass silently); numbers
    are numbers (strict: no true/false, text or null where a number is required; an integer is
    a number) and finite."""

    model_config = ConfigDict(extra="forbid", frozen=True, strict=True, allow_inf_nan=False)


# The formulations assemble dense matrices of the whole chain (models.drill.chain): 1000 lumped bodies is
# a 2000 x 2000 first-order matrix.
MAX_CHAIN_BODIES = 1000
STEEL_YOUNGS_MODULUS_PA = 210e9
STEEL_DENSITY_KG_PER_M3 = 7800.0  # with 210 GPa: bar wave speed sqrt(E / rho) = 5189 m/s
GROUND = "ground"
EVERY_BODY = "every_body"


class SnCurve(Strict):
    """A rod's S-N curve (Basquin): N = cycles (stress_amplitude_pa / S_a)^exponent cycles to failure at a stress
    amplitude S_a; below ``endurance_limit_pa`` (when given) a cycle does no damage."""

    stress_amplitude_pa: Positive = Field(description="S_ref, the amplitude at the reference cycles")
    cycles: Positive = Field(description="N_ref, the cycles to failure at S_ref")
    exponent: Positive = Field(description="m, the slope of log N against log S_a")
    endurance_limit_pa: NonNegative = 0.0

    def cycles_to_failure(self, amplitude_pa: Any) -> Any:
        """N(S_a) (infinite below the endurance limit)."""
        amplitude = np.asarray(amplitude_pa, dtype=float)
        with np.errstate(divide="ignore"):
            cycles = self.cycles * (self.stress_amplitude_pa / amplitude) ** self.exponent
        return np.where(amplitude > self.endurance_limit_pa, cycles, np.inf)


class Body(Strict):
    """One body of the drill string: a rigid ``mass_kg``, a rod given by its geometry, or a pipe
    given by its length and weight per metre.

    A rod (``length_m``, ``diameter_m``, optional ``bore_diameter_m``) has the mass rho A L, or
    ``mass_per_length_kg_per_m`` x L when given (a drill pipe's nominal weight per metre, tool joints
    included), and carries its own axial elasticity: a connector without ``stiffness_n_per_m``
    joining it gets the series stiffness of the two half-rods it joins, 1/k = sum L_i / (2 E_i A_i)
    (two identical rods: k = E A / L). ``segments`` > 1 splits the rod into that many equal lumped
    masses joined by springs E A N / L (a discrete wave-guide, docs/extending.md). A pipe given by
    ``length_m`` and ``mass_per_length_kg_per_m`` alone is a rigid body of that mass (no E A). A rigid
    ``mass_kg`` may state its ``diameter_m``: only its drawings use it (models.drill.shapes).

    ``model`` chooses how a rod is carried: ``lumped`` (default) as its ``segments`` lumped masses, or
    ``waves`` as an exact 1-D wave element between its two end faces (models.waves: d'Alembert's waves,
    impedance Z = A sqrt(E rho), transit time L / c; no segments). A wave rod's faces are massless and
    rigid: a connector without a stiffness joins them rigidly (a wave rod on a wave rod of another
    section is an impedance step).
    """

    mass_kg: Positive | None = Field(None, description="rigid body mass; not with a rod geometry")
    length_m: Positive | None = None
    diameter_m: Positive | None = None
    bore_diameter_m: NonNegative = Field(0.0, description="flushing hole, m")
    mass_per_length_kg_per_m: Positive | None = Field(None, description="weight per metre of a pipe, kg/m")
    youngs_modulus_pa: Positive = STEEL_YOUNGS_MODULUS_PA
    density_kg_per_m3: Positive = STEEL_DENSITY_KG_PER_M3
    segments: Annotated[int, Field(ge=1, le=MAX_CHAIN_BODIES)] = 1
    model: Literal["lumped", "waves"] = Field("lumped", description="a rod as lumped segments or as waves")
    sn_curve: SnCurve | None = Field(None, description="a wave rod's S-N curve: Miner's damage per blow at its gauges")

    @model_validator(mode="after")
    def _mass_or_geometry(self) -> Body:
        sized = [key for key in ("length_m", "diameter_m", "mass_per_length_kg_per_m") if getattr(self, key) is not None]
        if self.mass_kg is not None and set(sized) - {"diameter_m"}:
            raise ValueError(f"give mass_kg (a rigid body, with a diameter_m to draw it) or a length with a diameter "
                             f"or a mass per length, not both (mass_kg with {', '.join(sized)})")
        if self.mass_kg is None and (self.length_m is None or len(sized) < 2):
            raise ValueError("give mass_kg, or length_m with diameter_m (a steel rod) and/or "
                             "mass_per_length_kg_per_m (a pipe)")
        if self.is_rod and self.bore_diameter_m >= self.diameter_m:
            raise ValueError(f"bore_diameter_m {self.bore_diameter_m} must be smaller than diameter_m {self.diameter_m}")
        if self.segments > 1 and not self.is_rod:
            raise ValueError("segments > 1 needs a rod geometry (length_m, diameter_m)")
        if self.model == "waves" and not self.is_rod:
            raise _key_error("Body", ("model",), self.model, "a wave rod needs a rod geometry (length_m, diameter_m)")
        if self.sn_curve is not None and self.model != "waves":
            raise _key_error("Body", ("sn_curve",), None, "a wave rod's (model: waves): its gauges' stresses are counted")
        if self.model == "waves" and self.segments > 1:
            raise _key_error("Body", ("segments",), self.segments, "segments are the lumped model's; a rod with "
                             "model: waves carries its waves exactly and has none (leave segments out)")
        return self

    @property
    def is_wave(self) -> bool:
        """Whether the rod is carried as waves (``model: waves``)."""
        return self.model == "waves"

    @property
    def is_rod(self) -> bool:
        """Whether the body carries an axial elasticity E A / L (a length and a diameter)."""
        return self.length_m is not None and self.diameter_m is not None

    @property
    def area_m2(self) -> float:
        """A = pi (D^2 - d^2) / 4."""
        return math.pi * (self.diameter_m**2 - self.bore_diameter_m**2) / 4

    @property
    def total_mass_kg(self) -> float:
        """mass_kg, the weight per metre x L, or rho A L for a rod."""
        if self.mass_kg is not None:
            return self.mass_kg
        if self.mass_per_length_kg_per_m is not None:
            return self.mass_per_length_kg_per_m * self.length_m
        return self.density_kg_per_m3 * self.area_m2 * self.length_m

    @property
    def wave_speed_m_per_s(self) -> float:
        """Bar wave speed c = sqrt(E / rho) of a rod."""
        return math.sqrt(self.youngs_modulus_pa / self.density_kg_per_m3)

    def half_segment_compliance_m_per_n(self) -> float:
        """(L/N) / (2 E A): the compliance of half a segment (0 for a rigid body and for a wave rod, whose
        faces are rigid)."""
        if not self.is_rod or self.is_wave:
            return 0.0
        return self.length_m / self.segments / (2 * self.youngs_modulus_pa * self.area_m2)


class Connector(Strict):
    """A link from body ``from`` (nearer the hammer, or ``ground``) to body ``to``, of a ``type`` of
    :data:`models.definition.links.LINK_TYPES`: ``spring_damper`` (bonded, F = k delta + c delta') or
    ``coupling`` (compression only once its ``gap_m`` has closed). Without ``stiffness_n_per_m`` the
    stiffness follows from the rods it joins (:class:`Body`), or for a threaded coupling with a sleeve
    (``sleeve_length_m``, ``sleeve_outer_diameter_m``) from the sleeve: k = E pi (D_s^2 - D^2) / (4 L_s), D the
    larger of the joined rods' diameters (the threads' diameter), E the upper rod's (models.drill.chain): bonded
    (``spring_damper``: the threads carry tension) or compression only once a gap has closed (``coupling``). A
    ``coupling`` between two wave rods without a stiffness or a sleeve is a rigid contact: compression only.
    """

    model_config = ConfigDict(populate_by_name=True)

    type: str = "spring_damper"
    from_body: Name = Field(alias="from")
    to_body: Name = Field(alias="to")
    stiffness_n_per_m: Positive | None = None
    damping_n_s_per_m: NonNegative = 0.0
    gap_m: NonNegative | None = Field(None, description="coupling gap, m (type coupling; default 0)")
    sleeve_length_m: Positive | None = Field(None, description="a threaded coupling's sleeve: its length")
    sleeve_outer_diameter_m: Positive | None = Field(None, description="a coupling's sleeve: its outer diameter")

    @model_validator(mode="after")
    def _known_type_and_parameters(self) -> Connector:
        if self.type not in LINK_TYPES:
            raise ValueError(f"type {self.type!r} is not one of {', '.join(LINK_TYPES)}")
        sleeve = [key for key in ("sleeve_length_m", "sleeve_outer_diameter_m") if getattr(self, key) is not None]
        if len(sleeve) == 1:
            missing = ({"sleeve_length_m", "sleeve_outer_diameter_m"} - set(sleeve)).pop()
            raise _key_error("Connector", (missing,), None, "missing: a sleeve is its length and its outer diameter "
                             "(its stiffness E A / L, A over the rods' diameter)")
        if sleeve and self.stiffness_n_per_m is not None:
            raise _key_error("Connector", ("stiffness_n_per_m",), self.stiffness_n_per_m, "give the stiffness or the "
                             "sleeve it follows from, not both")
        taken = LINK_TYPES[self.type].parameters()
        given = [key for key in ("gap_m",) if getattr(self, key) is not None and key not in taken]
        if given:
            raise ValueError(f"{', '.join(given)} does not apply to type {self.type!r} "
                             f"(it takes {', '.join(taken) or 'only stiffness and damping'})")
        return self


class DrillString(Strict):
    """The axial chain: bodies and connectors by name, in order from the hammer to the rock. Without a
    ``rock_body`` the string ends free below its last body (the scene's rock is then ``law: none``)."""

    bodies: Annotated[dict[Name, Body], Field(min_length=1)]
    connectors: dict[Name, Connector] = Field(default_factory=dict)
    impact_body: Name = Field(description="the body the piston strikes")
    rock_body: Name | None = Field(None, description="the body that touches the rock (the bit); none: the string "
                                   "ends free")

    @property
    def foot(self) -> str:
        """The body at the string's lower end: the rock body, or the last body of a string that ends free."""
        return self.rock_body if self.rock_body is not None else list(self.bodies)[-1]

    @model_validator(mode="after")
    def _consistent(self) -> DrillString:
        names = list(self.bodies)
        for reserved in (GROUND, EVERY_BODY):
            if reserved in names:
                raise _key_error("DrillString", ("bodies", reserved), reserved, "a reserved word, not a body name "
                                 "('{ground}' and '{every}' name the ground and every body)", ground=GROUND, every=EVERY_BODY)
        for role in ("impact_body", "rock_body"):
            if getattr(self, role) not in names and (role == "impact_body" or self.rock_body is not None):
                raise ValueError(f"{role} {getattr(self, role)!r} is not a body; bodies: {', '.join(names)}")
        for name, connector in self.connectors.items():
            taken = [column for column in (f"{name}{suffix}" for suffix in LINK_SERIES) if column in SERIES]
            if taken:
                raise _key_error("DrillString", ("connectors", name), name, "its history {column} would be the "
                                 "model's own; give the connector another name", column=taken[0])
            for end, body in (("from", connector.from_body), ("to", connector.to_body)):
                if body not in names and not (end == "from" and body == GROUND):
                    allowed = ", ".join([GROUND, *names] if end == "from" else names)
                    raise ValueError(f"connectors.{name}.{end}: {body!r} is not one of {allowed}")
            if connector.from_body == connector.to_body:
                raise ValueError(f"connectors.{name} joins {connector.to_body!r} to itself")
            ends = [self.bodies[b] for b in (connector.from_body, connector.to_body) if b != GROUND]
            bore = max((b.diameter_m or 0.0 for b in ends), default=0.0)
            if connector.sleeve_outer_diameter_m is not None and connector.sleeve_outer_diameter_m <= bore:
                raise _key_error("DrillString", ("connectors", name, "sleeve_outer_diameter_m"),
                                 connector.sleeve_outer_diameter_m, "must exceed the joined rods' diameter {bore} m",
                                 bore=bore)
            if connector.stiffness_n_per_m is None and connector.sleeve_length_m is None and \
                    not any(b.is_rod for b in ends):
                raise ValueError(f"connectors.{name} needs stiffness_n_per_m: neither end is a rod with a geometry")
            if connector.stiffness_n_per_m is None and all(b.half_segment_compliance_m_per_n() == 0 for b in ends) \
                    and connector.from_body == GROUND:
                raise _key_error("DrillString", ("connectors", name, "stiffness_n_per_m"), None, "needed: a wave rod's "
                                 "face joined to ground without a stiffness would be held fixed")
        total = sum(body.segments for body in self.bodies.values())
        if total > MAX_CHAIN_BODIES:
            largest = max(self.bodies, key=lambda name: self.bodies[name].segments)
            raise _key_error("DrillString", ("bodies", largest, "segments"), self.bodies[largest].segments,
                             "the chain would have {total} lumped bodies; at most {most} (the formulations assemble "
                             "dense matrices of the whole chain)", total=total, most=MAX_CHAIN_BODIES)
        self._check_graph()
        return self

    def _check_graph(self) -> None:
        """The connectors form a chain: no loop (a connector joining two bodies that are joined
        already, through ground too), and every body joined to the rock body. One problem per loop,
        loose body and separate part (a ValidationError naming them)."""
        problems = []
        joined: dict[str, list[tuple[str, str]]] = {name: [] for name in (GROUND, *self.bodies)}  # -> (connector, end)
        for name, connector in self.connectors.items():
            ends = (connector.from_body, connector.to_body)
            route = _route(joined, *ends)
            if route is not None:
                loop = [*route, name]
                problems.append(_problem(("connectors", name), name, "connectors {loop} form a loop; a drill string "
                                         "is a chain from ground or the hammer to the rock, without loops",
                                         loop=", ".join(loop)))
                continue
            joined[ends[0]].append((name, ends[1]))
            joined[ends[1]].append((name, ends[0]))
        for part in _parts(joined):
            bodies = [b for b in self.bodies if b in part]
            if self.foot in part or not bodies:
                continue
            if len(bodies) == 1 and not joined[bodies[0]]:
                problems.append(_problem(("bodies", bodies[0]), bodies[0], "no connector joins this body to the drill "
                                         "string; every body is joined to rock_body '{rock}'", rock=self.foot))
            else:
                to = " and ".join(["each other"] * (len(bodies) > 1) + [GROUND] * (GROUND in part))
                problems.append(_problem(("bodies", bodies[0]), bodies, "a separate part: joined to {to} but not to "
                                         "rock_body '{rock}'; every body is joined to the rock body through connectors",
                                         to=to, rock=self.foot))
        if problems:
            raise ValidationError.from_exception_data("DrillString", problems)


def _route(joined: dict[str, list[tuple[str, str]]], start: str, end: str) -> list[str] | None:
    """The connectors on the path from body ``start`` to ``end`` through ``joined`` (a forest), None
    if they are not joined."""
    came: dict[str, tuple[str, str] | None] = {start: None}  # body -> (connector, previous body)
    frontier = [start]
    while frontier and end not in came:
        body = frontier.pop()
        for connector, other in joined[body]:
            if other not in came:
                came[other] = (connector, body)
                frontier.append(other)
    if end not in came:
        return None
    route, body = [], end
    while came[body] is not None:
        connector, body = came[body]
        route.append(connector)
    return route[::-1]


def _parts(joined: dict[str, list[tuple[str, str]]]) -> list[set[str]]:
    """The connected parts of the graph ``joined`` (bodies and ground)."""
    parts, seen = [], set()
    for start in joined:
        if start in seen:
            continue
        part, frontier = {start}, [start]
        while frontier:
            for _, other in joined[frontier.pop()]:
                if other not in part:
                    part.add(other)
                    frontier.append(other)
        seen |= part
        parts.append(part)
    return parts



def _problem(location: tuple[str, ...], value: object, message: str, **context: object) -> InitErrorDetails:
    """One problem at the key path ``location`` (pydantic prefixes the enclosing path)."""
    return InitErrorDetails(type=PydanticCustomError("invalid_key", message, context), loc=location, input=value)


def _key_error(model: str, location: tuple[str, ...], value: object, message: str, **context: object) -> ValidationError:
    """A validation error of one problem (:func:`_problem`) in ``model``."""
    return ValidationError.from_exception_data(model, [_problem(location, value, message, **context)])


class Torsion(Strict):
    """Fourth line of Eq. 4: J phi'' + c_x phi' + k_x phi = M_x - M_c (decoupled from the axial chain)."""

    inertia_kg_m2: Positive = Field(description="J_x of collar and bit")
    stiffness_n_m_per_rad: NonNegative = Field(description="k_x")
    damping_n_m_s_per_rad: NonNegative = Field(description="c_x")
    drive_torque_n_m: float = Field(description="M_x")
    resisting_torque_n_m: float = Field(description="M_c")


class Bit(Strict):
    """The bit face as the indexing model sees it (models.drill.indexing): bit diameter D, the gauge
    (outermost) buttons' diameter d and count, and the width of the crater one button leaves
    (default d: a crater as wide as the button that made it, the model's assumption)."""

    diameter_m: Positive = Field(description="D, the bit (hole) diameter")
    gauge_button_diameter_m: Positive = Field(description="d, diameter of a gauge button")
    gauge_buttons: Annotated[int, Field(ge=1)] = Field(description="gauge buttons on the gauge circle")
    crater_width_m: Positive | None = Field(None, description="crater width along the gauge track; default d")

    @model_validator(mode="after")
    def _buttons_fit(self) -> Bit:
        if self.gauge_buttons * self.gauge_button_diameter_m > math.pi * self.diameter_m:
            raise ValueError(f"{self.gauge_buttons} gauge buttons of {self.gauge_button_diameter_m} m do not fit on "
                             f"the gauge circle of a {self.diameter_m} m bit (pi D = {math.pi * self.diameter_m:.4g} m)")
        return self

    @property
    def crater_m(self) -> float:
        """The crater width w (the button diameter unless given)."""
        return self.crater_width_m or self.gauge_button_diameter_m


class Rotation(Strict):
    """A prescribed rotation speed n of the bit (a stiff rotation drive): it turns 2 pi n / (60 f)
    between two blow starts. Without this section an indexing model takes the angle from the
    torsion line."""

    speed_rpm: Positive = Field(description="n, bit revolutions per minute")


class Feed(Strict):
    """The feed force: ``force_n`` on body ``acts_on`` (a rig's carriage, say), or on
    ``every_body`` (F_dt on each body, the paper's Eq. 4; a segmented rod's share is split over its
    segments)."""

    force_n: NonNegative
    acts_on: Name = EVERY_BODY
