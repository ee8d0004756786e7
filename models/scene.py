"""The typed scene: everything one simulation needs, SI units in every name.

Symbols refer to the paper (Eq. 4, Table 1). The scene knows nothing of files: build it from a
plain dictionary with :func:`Scene.model_validate`; errors are pydantic ``ValidationError``s
whose locations are the key paths.
"""

from __future__ import annotations

import math
from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator
from pydantic_core import InitErrorDetails, PydanticCustomError, ValidationError
from rpdrill.models.links import LINK_TYPES
from rpdrill.models.outputs import METRICS, SERIES, needs
from rpdrill.rocklaw import LAWS, BilinearRock, JenkinsRock, RockLaw
from rpdrill.rocklaw.catalog import TABLE_1

Positive = Annotated[float, Field(gt=0, allow_inf_nan=False)]
NonNegative = Annotated[float, Field(ge=0, allow_inf_nan=False)]
Finite = Annotated[float, Field(allow_inf_nan=False)]


class Strict(BaseModel):
    """Unknown keys are errors (a unit typo such as ``force_kn`` must not pass silently)."""

    model_config = ConfigDict(extra="forbid", frozen=True)


STEEL_YOUNGS_MODULUS_PA = 210e9
STEEL_DENSITY_KG_PER_M3 = 7800.0  # with 210 GPa: bar wave speed sqrt(E / rho) = 5189 m/s
GROUND = "ground"
EVERY_BODY = "every_body"


class Body(Strict):
    """One body of the drill string: a rigid ``mass_kg``, or a rod given by its geometry.

    A rod (``length_m``, ``diameter_m``, optional ``bore_diameter_m``) has the mass rho A L and
    carries its own axial elasticity: a connector without ``stiffness_n_per_m`` joining it gets the
    series stiffness of the two half-rods it joins, 1/k = sum L_i / (2 E_i A_i) (two identical rods:
    k = E A / L). ``segments`` > 1 splits the rod into that many equal lumped masses joined by
    springs E A N / L (a discrete wave-guide, docs/extending.md).
    """

    mass_kg: Positive | None = Field(None, description="rigid body mass; not with a rod geometry")
    length_m: Positive | None = None
    diameter_m: Positive | None = None
    bore_diameter_m: NonNegative = Field(0.0, description="flushing hole, m")
    youngs_modulus_pa: Positive = STEEL_YOUNGS_MODULUS_PA
    density_kg_per_m3: Positive = STEEL_DENSITY_KG_PER_M3
    segments: Annotated[int, Field(ge=1)] = 1

    @model_validator(mode="after")
    def _mass_or_geometry(self) -> Body:
        geometry = self.length_m is not None or self.diameter_m is not None
        if self.mass_kg is not None and geometry:
            raise ValueError("give mass_kg (a rigid body) or length_m and diameter_m (a steel rod), not both")
        if self.mass_kg is None and (self.length_m is None or self.diameter_m is None):
            raise ValueError("give mass_kg, or both length_m and diameter_m")
        if geometry and self.bore_diameter_m >= self.diameter_m:
            raise ValueError(f"bore_diameter_m {self.bore_diameter_m} must be smaller than diameter_m {self.diameter_m}")
        if self.segments > 1 and not geometry:
            raise ValueError("segments > 1 needs a rod geometry (length_m, diameter_m)")
        return self

    @property
    def is_rod(self) -> bool:
        return self.length_m is not None

    @property
    def area_m2(self) -> float:
        """A = pi (D^2 - d^2) / 4."""
        return math.pi * (self.diameter_m**2 - self.bore_diameter_m**2) / 4

    @property
    def total_mass_kg(self) -> float:
        """mass_kg, or rho A L for a rod."""
        return self.mass_kg if self.mass_kg is not None else self.density_kg_per_m3 * self.area_m2 * self.length_m

    @property
    def wave_speed_m_per_s(self) -> float:
        """Bar wave speed c = sqrt(E / rho) of a rod."""
        return math.sqrt(self.youngs_modulus_pa / self.density_kg_per_m3)

    def half_segment_compliance_m_per_n(self) -> float:
        """(L/N) / (2 E A): the compliance of half a segment (0 for a rigid body)."""
        if not self.is_rod:
            return 0.0
        return self.length_m / self.segments / (2 * self.youngs_modulus_pa * self.area_m2)


class Connector(Strict):
    """A link from body ``from`` (nearer the hammer, or ``ground``) to body ``to``, of a ``type`` of
    :data:`models.links.LINK_TYPES`: ``spring_damper`` (bonded, F = k delta + c delta') or
    ``coupling`` (compression only once its ``gap_m`` has closed). Without ``stiffness_n_per_m`` the
    stiffness follows from the rods it joins (:class:`Body`).
    """

    model_config = ConfigDict(extra="forbid", frozen=True, populate_by_name=True)

    type: str = "spring_damper"
    from_body: str = Field(alias="from")
    to_body: str = Field(alias="to")
    stiffness_n_per_m: Positive | None = None
    damping_n_s_per_m: NonNegative = 0.0
    gap_m: NonNegative | None = Field(None, description="coupling gap, m (type coupling; default 0)")

    @model_validator(mode="after")
    def _known_type_and_parameters(self) -> Connector:
        if self.type not in LINK_TYPES:
            raise ValueError(f"type {self.type!r} is not one of {', '.join(LINK_TYPES)}")
        taken = LINK_TYPES[self.type].parameters()
        given = [key for key in ("gap_m",) if getattr(self, key) is not None and key not in taken]
        if given:
            raise ValueError(f"{', '.join(given)} does not apply to type {self.type!r} "
                             f"(it takes {', '.join(taken) or 'only stiffness and damping'})")
        return self


class DrillString(Strict):
    """The axial chain: bodies and connectors by name, in order from the hammer to the rock."""

    bodies: Annotated[dict[str, Body], Field(min_length=1)]
    connectors: dict[str, Connector] = Field(default_factory=dict)
    impact_body: str = Field(description="the body the piston strikes")
    rock_body: str = Field(description="the body that touches the rock (the bit)")

    @model_validator(mode="after")
    def _consistent(self) -> DrillString:
        names = list(self.bodies)
        if GROUND in names or EVERY_BODY in names:
            raise ValueError(f"'{GROUND}' and '{EVERY_BODY}' are reserved, not body names")
        for role in ("impact_body", "rock_body"):
            if getattr(self, role) not in names:
                raise ValueError(f"{role} {getattr(self, role)!r} is not a body; bodies: {', '.join(names)}")
        for name, connector in self.connectors.items():
            for end, body in (("from", connector.from_body), ("to", connector.to_body)):
                if body not in names and not (end == "from" and body == GROUND):
                    allowed = ", ".join([GROUND, *names] if end == "from" else names)
                    raise ValueError(f"connectors.{name}.{end}: {body!r} is not one of {allowed}")
            if connector.from_body == connector.to_body:
                raise ValueError(f"connectors.{name} joins {connector.to_body!r} to itself")
            ends = [self.bodies[b] for b in (connector.from_body, connector.to_body) if b != GROUND]
            if connector.stiffness_n_per_m is None and not any(b.is_rod for b in ends):
                raise ValueError(f"connectors.{name} needs stiffness_n_per_m: neither end is a rod with a geometry")
        self._check_connected(names)
        return self

    def _check_connected(self, names: list[str]) -> None:
        """Every body must be held: linked through connectors to ground or to the rock body."""
        reached, frontier = {GROUND}, {GROUND, self.rock_body}
        while frontier:
            reached |= frontier
            frontier = {b for c in self.connectors.values() for a, b in ((c.from_body, c.to_body), (c.to_body, c.from_body))
                        if a in reached and b not in reached}
        loose = [n for n in names if n not in reached]
        if loose:
            raise ValueError(f"bodies {', '.join(loose)} are not connected to the rock body or ground by any connector")


class Torsion(Strict):
    """Fourth line of Eq. 4: J phi'' + c_x phi' + k_x phi = M_x - M_c (decoupled from the axial chain)."""

    inertia_kg_m2: Positive = Field(description="J_x of collar and bit")
    stiffness_n_m_per_rad: NonNegative = Field(description="k_x")
    damping_n_m_s_per_rad: NonNegative = Field(description="c_x")
    drive_torque_n_m: Finite = Field(description="M_x")
    resisting_torque_n_m: Finite = Field(description="M_c")


class Feed(Strict):
    """The feed force: ``force_n`` on body ``acts_on`` (a rig's carriage, say), or on
    ``every_body`` (F_dt on each body, the paper's Eq. 4; a segmented rod's share is split over its
    segments)."""

    force_n: NonNegative
    acts_on: str = EVERY_BODY


class Impact(Strict):
    """Periodic piston force on the shank: one pulse of ``duration_s`` at the start of every period."""

    amplitude_n: Positive = Field(description="I, the paper's impact 'impulse' (a force amplitude, N)")
    frequency_hz: Positive = Field(description="f, blows per second")
    shape: Literal["half_sine", "rectangular", "triangular"] = "half_sine"
    duration_s: Positive = Field(description="tau, piston-shank contact time")

    @property
    def period_s(self) -> float:
        return 1.0 / self.frequency_hz

    @model_validator(mode="after")
    def _pulse_fits_period(self) -> Impact:
        if self.duration_s >= self.period_s:
            raise ValueError(
                f"duration_s {self.duration_s} must be shorter than the impact period "
                f"1/frequency_hz = {self.period_s:.6g} s"
            )
        return self


def _problem(location: tuple[str, ...], value: object, message: str, **context: object) -> InitErrorDetails:
    """One problem at the key path ``location`` (pydantic prefixes the enclosing path)."""
    return InitErrorDetails(type=PydanticCustomError("rock_law", message, context), loc=location, input=value)


def _key_error(model: str, location: tuple[str, ...], value: object, message: str, **context: object) -> ValidationError:
    """A validation error of one problem (:func:`_problem`) in ``model``."""
    return ValidationError.from_exception_data(model, [_problem(location, value, message, **context)])


# the keys of each rock law (``law`` itself is common)
ROCK_LAW_KEYS = {
    "jenkins": ("name", "stiffness_n_per_m", "damping_n_s_per_m", "threshold_n", "damping_mode"),
    "bilinear": ("loading_stiffness_n_per_m", "unloading_stiffness_n_per_m"),
}


class Rock(Strict):
    """The rock under the bit: ``law`` and that law's keys (keys of another law are errors).

    ``jenkins`` (default; the paper's Eq. 1, 2): a Table 1 ``name``, explicit values, or a name
    with overrides; ``damping_mode`` ``contact`` (default) or ``always``. ``bilinear``: loading
    stiffness k_l and unloading stiffness k_u > k_l (rocklaw.bilinear).
    """

    law: Literal[tuple(LAWS)] = "jenkins"  # type: ignore[valid-type]
    name: Literal[tuple(TABLE_1)] | None = None  # type: ignore[valid-type]
    stiffness_n_per_m: Positive | None = None
    damping_n_s_per_m: NonNegative | None = None
    threshold_n: Positive | None = None
    damping_mode: Literal["contact", "always"] | None = None
    loading_stiffness_n_per_m: Positive | None = Field(None, description="bilinear: k_l")
    unloading_stiffness_n_per_m: Positive | None = Field(None, description="bilinear: k_u > k_l")

    @model_validator(mode="after")
    def _complete(self) -> Rock:
        allowed = ", ".join(("law", *ROCK_LAW_KEYS[self.law]))
        foreign = [_problem((key,), getattr(self, key), "a key of rock law '{other}', not of law '{law}'; "
                            "allowed keys: {allowed}", other=law, law=self.law, allowed=allowed)
                   for law, keys in ROCK_LAW_KEYS.items() if law != self.law
                   for key in keys if getattr(self, key) is not None]
        if foreign:
            raise ValidationError.from_exception_data("Rock", foreign)
        return self._complete_bilinear() if self.law == "bilinear" else self._complete_jenkins()

    def _complete_jenkins(self) -> Rock:
        if self.damping_mode is None:
            object.__setattr__(self, "damping_mode", "contact")
        if self.name is None:
            missing = [k for k in ("stiffness_n_per_m", "damping_n_s_per_m", "threshold_n") if getattr(self, k) is None]
            if missing:
                raise ValueError(f"give a Table 1 name ({', '.join(TABLE_1)}) or all of: {', '.join(missing)}")
            return self
        row = TABLE_1[self.name]
        for key in ("stiffness_n_per_m", "damping_n_s_per_m", "threshold_n"):
            if getattr(self, key) is None:
                object.__setattr__(self, key, getattr(row, key))
        return self

    def _complete_bilinear(self) -> Rock:
        for key in ROCK_LAW_KEYS["bilinear"]:
            if getattr(self, key) is None:
                raise _key_error("Rock", (key,), None, "missing: rock law 'bilinear' needs {key}", key=key)
        if self.unloading_stiffness_n_per_m <= self.loading_stiffness_n_per_m:
            raise _key_error("Rock", ("unloading_stiffness_n_per_m",), self.unloading_stiffness_n_per_m,
                             "must be greater than loading_stiffness_n_per_m ({loading})",
                             loading=f"{self.loading_stiffness_n_per_m:g}")
        return self

    def build(self, damping: bool = True, plasticity: bool = True) -> RockLaw:
        """The law; without ``damping`` no rock damper, without ``plasticity`` an elastic rock at the
        loading stiffness (Jenkins: F_th infinite; bilinear: k_u = k_l)."""
        if self.law == "bilinear":
            loading = self.loading_stiffness_n_per_m
            return BilinearRock(loading, self.unloading_stiffness_n_per_m if plasticity else loading)
        return JenkinsRock(self.stiffness_n_per_m, self.damping_n_s_per_m if damping else 0.0,
                           self.threshold_n if plasticity else math.inf, self.damping_mode)


EXUDYN_SOLVERS = (
    "rk44", "rk33", "explicit_midpoint", "explicit_euler", "generalized_alpha",
    "trapezoidal_index2", "dopri5", "ode23",
)
AUTOMATIC_STEP_SOLVERS = ("dopri5", "ode23")


# Accuracy presets: RK44 at a fixed step, the smallest of a cap, a fraction of the pulse duration
# (a step must resolve the pulse) and a multiple of 1/|lambda|_max (the stiffest or fastest
# mode, models.stability.spectral_radius_per_s). The stated errors (relative to the reference
# preset, and of the energy balance relative to the impact work) are the largest measured on the
# hard scenes of tests/stability, rounded up (docs/stability.md); the suite checks them.
SOLVER_PRESETS: dict[str, dict[str, float]] = {
    "fast": {"step_s": 1e-4, "steps_per_pulse": 10, "step_times_radius": 0.8,
             "penetration_rate_error": 0.03, "energy_balance_error": 0.03},
    "standard": {"step_s": 4e-5, "steps_per_pulse": 25, "step_times_radius": 0.4,
                 "penetration_rate_error": 0.003, "energy_balance_error": 0.003},
    "reference": {"step_s": 5e-6, "steps_per_pulse": 200, "step_times_radius": 0.05,
                  "penetration_rate_error": 1e-4, "energy_balance_error": 1e-4},
}
DEFAULT_PRESET = "standard"
ACCURACY_KEYS = ("type", "step_s", "spectral_radius", "relative_tolerance", "absolute_tolerance")


class Solver(Strict):
    """Time integration: a ``preset`` (fast, standard, reference) and/or explicit settings.

    ``step_s`` is the fixed step (the largest step for dopri5/ode23). A preset sets ``type`` and
    ``step_s``; explicit values given next to it win. Without either, the ``standard`` preset applies.
    """

    preset: Literal[tuple(SOLVER_PRESETS)] | None = None  # type: ignore[valid-type]
    type: Literal[EXUDYN_SOLVERS] = "rk44"  # type: ignore[valid-type]
    step_s: Positive = SOLVER_PRESETS[DEFAULT_PRESET]["step_s"]
    spectral_radius: Annotated[float, Field(ge=0, le=1)] = 1.0
    relative_tolerance: Positive = 1e-8
    absolute_tolerance: Positive = 1e-12
    end_time_s: Positive = 0.5
    output_interval_s: Positive = 1e-4

    @model_validator(mode="before")
    @classmethod
    def _default_preset(cls, data: object) -> object:
        if isinstance(data, dict) and data.get("preset") is None and not any(k in data for k in ACCURACY_KEYS):
            return {**data, "preset": DEFAULT_PRESET}
        return data


EFFECTS = ("torsion", "rock_damping", "rock_plasticity", "joint_damping")


class Effects(Strict):
    """Which parts of the model are built (the axial impact chain always is).

    In a scene: ``true`` builds an effect, ``false`` leaves it out, a key absent leaves it out
    unless a requested output needs it; no ``effects`` section at all builds every effect the
    scene gives parameters for (the full model). After validation every key is true or false and
    ``reasons`` says why. ``rock_plasticity`` off gives an elastic rock that never crushes.
    """

    torsion: bool | None = None
    rock_damping: bool | None = None
    rock_plasticity: bool | None = None
    joint_damping: bool | None = None
    reasons: dict[str, str] = Field(default_factory=dict)


class Outputs(Strict):
    """Requested metrics and time histories (time, positions and velocities always come).

    No ``outputs`` section: every metric and history of the effects that are built. A list left
    out of a given section is empty.
    """

    metrics: list[Literal[tuple(METRICS)]] = Field(default_factory=list)  # type: ignore[valid-type]
    timeseries: list[Literal[tuple(SERIES)]] = Field(default_factory=list)  # type: ignore[valid-type]


class Metrics(Strict):
    """Averaging window: skip ``transient_blows`` blows, then whole blocks of ``block_blows`` blows."""

    transient_blows: Annotated[int, Field(ge=0)] = 10
    block_blows: Annotated[int, Field(ge=1)] = 5


class Scene(Strict):
    """One drill on one rock with one solver setting."""

    name: str
    description: str = ""
    drill_string: DrillString
    torsion: Torsion | None = None
    feed: Feed
    impact: Impact
    rock: Rock
    solver: Solver = Solver()
    metrics: Metrics = Metrics()
    effects: Effects | None = None
    outputs: Outputs | None = None
    start: Literal["rest", "preloaded"] = Field(
        "rest", description="rest: every coordinate zero (Eq. 4 from rest); preloaded: the static "
        "equilibrium under the feed (and torque) with the bit pressed on the rock")

    def _available(self, effect: str) -> bool:
        """Whether the scene's parameters give the effect anything to do."""
        return {
            "torsion": self.torsion is not None,
            "rock_damping": self.rock.law == "jenkins" and self.rock.damping_n_s_per_m > 0,
            "rock_plasticity": True,
            "joint_damping": any(c.damping_n_s_per_m > 0 for c in self.drill_string.connectors.values()),
        }[effect]

    @model_validator(mode="after")
    def _feed_body_exists(self) -> Scene:
        bodies = self.drill_string.bodies
        if self.feed.acts_on != EVERY_BODY and self.feed.acts_on not in bodies:
            raise ValueError(f"feed.acts_on {self.feed.acts_on!r} is not one of {EVERY_BODY}, {', '.join(bodies)}")
        return self

    @model_validator(mode="after")
    def _resolve_effects_and_outputs(self) -> Scene:
        outputs = self.outputs or Outputs()
        need = needs(outputs.metrics, outputs.timeseries)
        chosen, reasons = {}, {}
        for effect in EFFECTS:
            asked = None if self.effects is None else getattr(self.effects, effect)
            users = [o for o in outputs.metrics + outputs.timeseries
                     if effect in (METRICS.get(o) or SERIES[o]).effects]
            if asked is False and users:
                raise ValueError(f"effects.{effect} is false but outputs {', '.join(users)} need it")
            if self.effects is None:
                chosen[effect] = self._available(effect) or effect in need.effects
                reasons[effect] = "no effects section: full model" if chosen[effect] else \
                    "no effects section, and nothing for it to do in this scene"
            elif asked:
                chosen[effect], reasons[effect] = True, "asked for"
            elif users:
                chosen[effect], reasons[effect] = True, f"needed by outputs: {', '.join(users)}"
            else:
                chosen[effect], reasons[effect] = False, "not asked for" if asked is None else "switched off"
        if chosen["torsion"] and self.torsion is None:
            raise ValueError("the torsion effect needs a torsion section (inertia_kg_m2, stiffness_n_m_per_rad, "
                             "damping_n_m_s_per_rad, drive_torque_n_m, resisting_torque_n_m)")
        object.__setattr__(self, "effects", Effects(**chosen, reasons=reasons))
        bodies = set(self.drill_string.bodies)
        missing = [o for o in outputs.metrics + outputs.timeseries
                   if not (METRICS.get(o) or SERIES[o]).bodies <= bodies]
        if missing:
            raise ValueError(f"outputs {', '.join(missing)} need a body named "
                             f"{', '.join(sorted(need.bodies - bodies))} in drill_string.bodies")
        if self.outputs is None:
            built = {e for e, on in chosen.items() if on}
            object.__setattr__(self, "outputs", Outputs(
                metrics=[m for m, n in METRICS.items() if n.effects <= built and n.bodies <= bodies],
                timeseries=[s for s, n in SERIES.items() if n.effects <= built and n.bodies <= bodies]))
        return self

    def needed_data(self) -> frozenset[str]:
        """What must be recorded for the requested outputs: ``forces``, ``energy``."""
        return needs(self.outputs.metrics, self.outputs.timeseries).data

    def rock_law(self) -> RockLaw:
        """The rock law as built: without damping or plasticity when those effects are off."""
        return self.rock.build(damping=self.effects.rock_damping, plasticity=self.effects.rock_plasticity)

    @model_validator(mode="after")
    def _rock_damping_needs_a_damped_law(self) -> Scene:
        if self.effects.rock_damping and self.rock.law == "bilinear":
            raise _key_error("Scene", ("effects", "rock_damping"), True,
                             "rock law 'bilinear' has no rock damping; set it false or use law: jenkins")
        return self

    @model_validator(mode="after")
    def _resolve_preset_and_check_length(self) -> Scene:
        if self.solver.preset is not None:
            from rpdrill.models.stability import spectral_radius_per_s  # needs a complete scene

            preset = SOLVER_PRESETS[self.solver.preset]
            step = min(preset["step_s"], self.impact.duration_s / preset["steps_per_pulse"],
                       preset["step_times_radius"] / spectral_radius_per_s(self))
            given = self.solver.model_fields_set
            update = {key: value for key, value in (("type", "rk44"), ("step_s", step)) if key not in given}
            object.__setattr__(self, "solver", self.solver.model_copy(update=update))
        period = self.impact.period_s
        if self.solver.end_time_s < period:
            raise ValueError(
                f"solver.end_time_s {self.solver.end_time_s} is shorter than one impact period ({period:.6g} s)"
            )
        needed = (self.metrics.transient_blows + self.metrics.block_blows) * period
        if self.solver.end_time_s < needed * (1 - 1e-12):
            raise ValueError(
                f"solver.end_time_s {self.solver.end_time_s} covers {self.solver.end_time_s / period:.3g} blows; "
                f"the metrics need transient_blows + block_blows = "
                f"{self.metrics.transient_blows + self.metrics.block_blows} blows ({needed:.6g} s)"
            )
        if self.solver.step_s > period / 20:
            raise ValueError(f"solver.step_s {self.solver.step_s} must resolve the impact period: at most {period / 20:.3g} s")
        return self

    @model_validator(mode="after")
    def _preload_does_not_crush(self) -> Scene:
        if self.start == "preloaded":
            from rpdrill.models.chain import initial_positions_m  # needs a complete scene

            initial_positions_m(self)  # raises when the static feed alone would crush the rock
        return self
