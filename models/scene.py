"""The typed scene: everything one simulation needs, SI units in every name.

Symbols refer to the paper (Eq. 4, Table 1). The scene knows nothing of files: build it from a
plain dictionary with :func:`Scene.model_validate`; errors are pydantic ``ValidationError``s
whose locations are the key paths.
"""

from __future__ import annotations

import math
from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

from models.outputs import METRICS, SERIES, needs
from rocklaw.catalog import TABLE_1
from rocklaw.jenkins import JenkinsRock

Positive = Annotated[float, Field(gt=0, allow_inf_nan=False)]
NonNegative = Annotated[float, Field(ge=0, allow_inf_nan=False)]
Finite = Annotated[float, Field(allow_inf_nan=False)]


class Strict(BaseModel):
    """Unknown keys are errors (a unit typo such as ``force_kn`` must not pass silently)."""

    model_config = ConfigDict(extra="forbid", frozen=True)


class Bodies(Strict):
    """Masses of the paper's three axial bodies."""

    shank_mass_kg: Positive = Field(description="m1, hammer shank")
    collar_mass_kg: Positive = Field(description="m2, drill collar (lumped string and rig mass)")
    bit_mass_kg: Positive = Field(description="m3, drill bit")


class SpringDamper(Strict):
    """A linear spring k [N/m] in parallel with a viscous damper c [N s/m]."""

    stiffness_n_per_m: Positive
    damping_n_s_per_m: NonNegative = 0.0


class Connectors(Strict):
    """k1/c1 shock absorber, k2/c2 and k3/c3 threaded joints."""

    shock_absorber: SpringDamper
    shank_collar_joint: SpringDamper
    collar_bit_joint: SpringDamper


class Torsion(Strict):
    """Fourth line of Eq. 4: J phi'' + c_x phi' + k_x phi = M_x - M_c (decoupled from the axial chain)."""

    inertia_kg_m2: Positive = Field(description="J_x of collar and bit")
    stiffness_n_m_per_rad: NonNegative = Field(description="k_x")
    damping_n_m_s_per_rad: NonNegative = Field(description="c_x")
    drive_torque_n_m: Finite = Field(description="M_x")
    resisting_torque_n_m: Finite = Field(description="M_c")


class Feed(Strict):
    """How the feed force reaches the string.

    ``per_body``: the paper's Eq. 4, the shock absorber k1/c1 anchored to ground and ``force_n``
    (F_dt) applied to every body. ``carriage``: a carriage of ``carriage_mass_kg`` pushed by
    ``force_n`` carries the shock absorber and follows the hole, as a rig's feed does.
    """

    arrangement: Literal["per_body", "carriage"] = "carriage"
    force_n: NonNegative
    carriage_mass_kg: Positive | None = None

    @model_validator(mode="after")
    def _carriage_needs_mass(self) -> Feed:
        if self.arrangement == "carriage" and self.carriage_mass_kg is None:
            raise ValueError("arrangement 'carriage' needs carriage_mass_kg (a positive mass in kg)")
        return self


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


class Rock(Strict):
    """The rock of Eq. 1, 2: a Table 1 ``name``, explicit values, or a name with overrides."""

    name: Literal[tuple(TABLE_1)] | None = None  # type: ignore[valid-type]
    stiffness_n_per_m: Positive | None = None
    damping_n_s_per_m: NonNegative | None = None
    threshold_n: Positive | None = None
    damping_mode: Literal["contact", "always"] = "contact"

    @model_validator(mode="after")
    def _complete(self) -> Rock:
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

    def law(self) -> JenkinsRock:
        return JenkinsRock(self.stiffness_n_per_m, self.damping_n_s_per_m, self.threshold_n, self.damping_mode)


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
    bodies: Bodies
    connectors: Connectors
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
        c = self.connectors
        return {
            "torsion": self.torsion is not None,
            "rock_damping": self.rock.damping_n_s_per_m > 0,
            "rock_plasticity": True,
            "joint_damping": any(link.damping_n_s_per_m > 0 for link in (
                c.shock_absorber, c.shank_collar_joint, c.collar_bit_joint)),
        }[effect]

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
        if self.outputs is None:
            built = {e for e, on in chosen.items() if on}
            object.__setattr__(self, "outputs", Outputs(
                metrics=[m for m, n in METRICS.items() if n.effects <= built],
                timeseries=[s for s, n in SERIES.items() if n.effects <= built]))
        return self

    def needed_data(self) -> frozenset[str]:
        """What must be recorded for the requested outputs: ``forces``, ``energy``."""
        return needs(self.outputs.metrics, self.outputs.timeseries).data

    def rock_law(self) -> JenkinsRock:
        """The rock law as built: without damping or plasticity when those effects are off."""
        rock = self.rock
        return JenkinsRock(
            rock.stiffness_n_per_m,
            rock.damping_n_s_per_m if self.effects.rock_damping else 0.0,
            rock.threshold_n if self.effects.rock_plasticity else math.inf,
            rock.damping_mode,
        )

    @model_validator(mode="after")
    def _resolve_preset_and_check_length(self) -> Scene:
        if self.solver.preset is not None:
            from models.stability import spectral_radius_per_s  # needs a complete scene

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
            from models.chain import initial_positions_m  # needs a complete scene

            initial_positions_m(self)  # raises when the static feed alone would crush the rock
        return self
