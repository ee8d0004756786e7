"""The typed scene: everything one simulation needs, SI units in every name; data only.

Symbols refer to the paper (Eq. 4, Table 1). The scene knows nothing of files: build it from a
plain dictionary with :func:`Scene.model_validate`; errors are pydantic ``ValidationError``s
whose locations are the key paths. Validation checks the data for consistency and runs no
physics; what a run derives from it (the effects built, the solver step of a preset, the chain,
the rock law, the initial state) is resolved once per run by :mod:`rpdrill.models.solvers.simulation`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Annotated, Any, Literal

from pydantic import Field, PrivateAttr, ValidationInfo, model_validator

from .drill_string import (
    EVERY_BODY,
    MAX_COUNT,
    Bit,
    Body,
    DrillString,
    Feed,
    Name,
    Positive,
    Rotation,
    Strict,
    Torsion,
    _key_error,
)
from .extensions import Extension
from .formulations import (
    COMMON_SOLVER_KEYS,
    DEFAULT_STEADY_STATE,
    EXUDYN_SOLVERS,
    FORMULATIONS,
    ODE_METHODS,
    PRESETS,
    STEADY_STATES,
)
from .outputs import BODY_METRICS, METRICS, SERIES, Need, metric_need, needs
from .own_code import ALLOW_CODE, allowance, allowed_modules
from .rock import JENKINS_VALUES, ROCK_LAW_KEYS, Rock, refuse_foreign_keys
from .sections import EFFECTS, Effects, Metrics, Outputs
from .validation import InputError, parse, short, with_changes

__all__ = ["JENKINS_VALUES", "ROCK_LAW_KEYS", "Rock", "Scene"]


class Piston(Body):
    """The hammer's piston as a body (models.drill.piston): a rigid ``mass_kg`` or a rod given by its
    geometry (the rod keys of :class:`Body`, ``segments`` lumped masses like the string's rods),
    striking the impact body at ``velocity_m_per_s`` (or with the blow energy ``energy_j`` = m v^2 / 2:
    one of the two) through a compression-only contact of ``contact_stiffness_n_per_m``, the stiffness
    of the faces' contact itself (default: rigid faces). The run couples the two lumped bodies either
    side through that contact in series with the half-segments behind the faces, 1/k = 1/k_c +
    sum L / (2 E A N) (a rigid body adds none: a rigid piston on a rigid impact body must give k_c)."""

    velocity_m_per_s: Positive | None = Field(None, description="v_p, strike speed")
    energy_j: Positive | None = Field(None, description="blow energy m_p v_p^2 / 2")
    contact_stiffness_n_per_m: Positive | None = Field(None, description="k_c, stiffness of the faces' contact (default: rigid faces)")

    @model_validator(mode="after")
    def _speed_or_energy(self) -> Piston:
        if (self.velocity_m_per_s is None) == (self.energy_j is None):
            raise ValueError("give the strike speed velocity_m_per_s or the blow energy energy_j (one of the two)")
        return self

    @property
    def strike_velocity_m_per_s(self) -> float:
        """v_p, given or from the blow energy: sqrt(2 E_blow / m_p)."""
        if self.velocity_m_per_s is not None:
            return self.velocity_m_per_s
        return math.sqrt(2.0 * self.energy_j / self.total_mass_kg)

    @property
    def blow_energy_j(self) -> float:
        """E_blow = m_p v_p^2 / 2."""
        return self.energy_j if self.energy_j is not None else 0.5 * self.total_mass_kg * self.velocity_m_per_s**2


PULSE_KEYS = ("amplitude_n", "duration_s", "shape")


class Impact(Strict):
    """The blows, ``frequency_hz`` per second: a prescribed force pulse on the shank (the paper's:
    ``amplitude_n``, ``shape``, ``duration_s`` at the start of every period), or a ``piston`` that
    strikes the impact body at the start of every period (models.drill.piston)."""

    amplitude_n: Positive | None = Field(None, description="I, the paper's impact 'impulse' (a force amplitude, N)")
    frequency_hz: Positive = Field(description="f, blows per second")
    shape: Literal["half_sine", "rectangular", "triangular"] | None = Field(None, description="default half_sine")
    duration_s: Positive | None = Field(None, description="tau, piston-shank contact time")
    piston: Piston | None = None

    @model_validator(mode="before")
    @classmethod
    def _default_shape(cls, data: Any) -> Any:
        """A prescribed pulse is a half-sine unless its shape is given (a piston has no shape)."""
        if isinstance(data, Mapping) and data.get("piston") is None and data.get("shape") is None:
            return {**data, "shape": "half_sine"}
        return data

    @property
    def period_s(self) -> float:
        return 1.0 / self.frequency_hz

    @model_validator(mode="after")
    def _pulse_or_piston(self) -> Impact:
        if self.piston is not None:
            given = [key for key in PULSE_KEYS if getattr(self, key) is not None]
            if given:
                raise _key_error("Impact", (given[0],), getattr(self, given[0]),
                                 "a key of the prescribed pulse; with a piston the pulse comes from the piston "
                                 "(give amplitude_n, shape, duration_s or piston, not both)")
            return self
        missing = [key for key in ("amplitude_n", "duration_s") if getattr(self, key) is None]
        if missing:
            raise ValueError(f"give the pulse ({', '.join(missing)} missing) or a piston")
        if self.duration_s >= self.period_s:
            raise _key_error("Impact", ("duration_s",), self.duration_s, "must be shorter than the impact period "
                             "1/frequency_hz = {period_s} s", period_s=float(f"{self.period_s:.6g}"))
        return self


class Solver(Strict):
    """How the scene is integrated: the ``formulation`` (models.definition.formulations), an accuracy
    ``preset`` (fast, standard, reference) and/or that formulation's explicit options, the end time
    and the output interval.

    Options (a key of another formulation is an error): exudyn ``type``, ``step_s`` (the fixed step;
    the largest step for dopri5/ode23), ``spectral_radius``, ``relative_tolerance``,
    ``absolute_tolerance``; ode ``method``, ``relative_tolerance``, ``absolute_tolerance`` (SI units
    of the state), ``sample_interval_s`` (dense-output sampling); exact ``sample_interval_s``,
    ``min_switch_interval_s``, ``max_switches_per_blow``, ``wave_step_s`` (the step of the
    characteristics of wave rods, models.waves; Exudyn's wave step is its ``step_s``). A preset fills the options not given;
    without a preset and without explicit accuracy options the ``standard`` preset applies
    (models.evaluation.solver_settings resolves them once per run). ``steady_state`` (every formulation):
    ``time`` (default) runs from the start to the end time and averages the blocks after the transient;
    ``periodic`` solves for the drill's periodic orbit by shooting (models.steady: period-1, period-n, or,
    where none is found, the time run as with ``time``).
    """

    formulation: Literal[tuple(FORMULATIONS)] = "exudyn"  # type: ignore[valid-type]
    preset: Literal[PRESETS] | None = None  # type: ignore[valid-type]
    end_time_s: Positive = 0.5
    output_interval_s: Positive = 1e-4
    type: Literal[EXUDYN_SOLVERS] | None = None  # type: ignore[valid-type]
    step_s: Positive | None = None
    spectral_radius: Annotated[float, Field(ge=0, le=1)] | None = None
    relative_tolerance: Positive | None = None
    absolute_tolerance: Positive | None = None
    method: Literal[ODE_METHODS] | None = None  # type: ignore[valid-type]
    sample_interval_s: Positive | None = None
    min_switch_interval_s: Positive | None = None
    max_switches_per_blow: Annotated[int, Field(ge=1, le=MAX_COUNT)] | None = None
    wave_step_s: Positive | None = None
    steady_state: Literal[STEADY_STATES] = DEFAULT_STEADY_STATE  # type: ignore[valid-type]

    @model_validator(mode="after")
    def _options_of_the_formulation(self) -> Solver:
        keys = {name: (*COMMON_SOLVER_KEYS, *f.option_keys) for name, f in FORMULATIONS.items()}
        refuse_foreign_keys(self, "formulation", self.formulation, keys, "Solver")
        return self


def switch_formulation(solver: dict[str, Any], formulation: str) -> dict[str, Any]:
    """A ``solver`` section (as written) switched to ``formulation``: the options of the old
    formulation dropped, the common ones (end time, preset, output interval) kept."""
    if formulation == solver.get("formulation", Solver.model_fields["formulation"].default):
        return dict(solver)
    return {**{key: value for key, value in solver.items() if key in COMMON_SOLVER_KEYS}, "formulation": formulation}


class Scene(Strict):
    """One drill on one rock with one solver setting: the typed content of a scene file (data only, immutable).

    Its fields are the file's sections, each key with its unit in its name (docs/scenes.md): ``name``,
    ``description``, ``drill_string``, ``torsion``, ``bit``, ``rotation``, ``feed``, ``impact``, ``rock``,
    ``solver``, ``metrics``, ``effects``, ``outputs``, ``start``, ``extensions``; :meth:`with_` makes a validated copy.

    Parameters
    ----------
    **sections
        The sections; :func:`load_scene` reads them from a file (InputError naming the key path), and
        ``Scene.model_validate(mapping)`` from a mapping (pydantic's ValidationError).

    Examples
    --------
    >>> import rpdrill
    >>> scene = rpdrill.load_scene("paper_base")
    >>> scene.name, scene.impact.frequency_hz, sorted(scene.drill_string.bodies)
    ('paper_base', 65.0, ['bit', 'collar', 'pipe', 'shank'])
    """

    name: str
    description: str = ""
    drill_string: DrillString
    torsion: Torsion | None = None
    bit: Bit | None = None
    rotation: Rotation | None = None
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
    extensions: dict[Name, Extension] | None = Field(
        None, description="Python extensions of the Exudyn model by name (models.definition.extensions)")
    # the modules of one's own its reader allowed (models.definition.own_code): kept by copies, with_ and pickles
    _allowed_code: tuple[str, ...] = PrivateAttr(())

    @model_validator(mode="after")
    def _keep_allowance(self, info: ValidationInfo) -> Scene:
        self._allowed_code = allowance(info)
        return self

    @property
    def allowed_code(self) -> tuple[str, ...]:
        """The modules of one's own this scene may run (given by who read it, never by its file)."""
        return self._allowed_code

    def with_(self, changes: dict[str, Any], source: str = "Scene.with_", allow_code: Any = ()) -> Scene:
        """A validated copy with ``changes``: key paths of the scene file to values (None removes a key).

        Parameters
        ----------
        changes : dict of str to object
            ``{"impact.frequency_hz": 70.0}``; a whole section as a mapping.
        source : str, optional
            How messages name the scene (default ``Scene.with_``).
        allow_code : sequence of str or str, default ()
            Modules of one's own the copy may run besides this scene's (models.definition.own_code).

        Returns
        -------
        Scene
            The copy; this scene is unchanged.

        Raises
        ------
        InputError
            Naming the key path, the value and what is allowed, as the command line reports a scene file.

        Examples
        --------
        >>> import rpdrill
        >>> scene = rpdrill.load_scene("paper_base")
        >>> scene.with_({"impact.frequency_hz": 70.0}).impact.frequency_hz, scene.impact.frequency_hz
        (70.0, 65.0)
        """
        return with_changes(self, changes, source, {ALLOW_CODE: self._allowance(source, allow_code)})

    def _allowance(self, source: str, allow_code: Any) -> tuple[str, ...]:
        try:
            return allowed_modules((*self._allowed_code, *allowed_modules(allow_code)))
        except ValueError as error:
            raise InputError(f"{source}: allow_code: {error}") from None

    def with_solver(self, formulation: str | None = None, **options: object) -> Scene:
        """This scene with another formulation (:func:`switch_formulation`: the former one's options dropped) and/or
        other solver options (``scene.with_solver("exact", end_time_s=0.5)``): a new, validated scene; InputError for
        a formulation that is not one, or an option it does not take.
        """
        solver = self.solver.model_dump(exclude_none=True)
        if formulation is not None:
            if not isinstance(formulation, str) or formulation not in FORMULATIONS:
                raise InputError(f"Scene.with_solver: formulation: {short(formulation)}: not a formulation; "
                                 f"allowed: {', '.join(FORMULATIONS)}")
            solver = switch_formulation(solver, formulation)
        data = self.model_dump(by_alias=True, exclude_none=True)
        return parse(Scene, {**data, "solver": {**solver, **options}}, "Scene.with_solver",
                     context={ALLOW_CODE: self._allowed_code})

    @model_validator(mode="before")
    @classmethod
    def _free_string_without_rock(cls, data: Any) -> Any:
        """A string without a rock body ends free: its rock is ``law: none`` when the scene gives none."""
        if isinstance(data, Mapping) and "rock" not in data and isinstance(data.get("drill_string"), Mapping) \
                and data["drill_string"].get("rock_body") is None:
            return {**data, "rock": {"law": "none"}}
        return data

    @model_validator(mode="after")
    def _rock_on_a_rock_body(self) -> Scene:
        if self.drill_string.rock_body is None and self.rock.law != "none":
            raise _key_error("Scene", ("drill_string", "rock_body"), None, "missing: rock law '{law}' acts on the "
                             "rock body; leave out the rock section (or give rock: {{law: none}}) for a string that "
                             "ends free", law=self.rock.law)
        return self

    @model_validator(mode="after")
    def _gauges_on_wave_rods(self) -> Scene:
        for name, gauge in (self.outputs.gauges if self.outputs else {}).items():
            body = self.drill_string.bodies.get(gauge.rod)
            if body is None or not body.is_wave:
                waves = [b for b, value in self.drill_string.bodies.items() if value.is_wave]
                raise _key_error("Scene", ("outputs", "gauges", name, "rod"), gauge.rod, "a gauge sits on a wave rod "
                                 "(model: waves); the scene's: {rods}", rods=", ".join(waves) or "none")
            if gauge.position_m > body.length_m:
                raise _key_error("Scene", ("outputs", "gauges", name, "position_m"), gauge.position_m, "beyond the "
                                 "rod's length {length} m (the distance from its top)", length=body.length_m)
        return self

    @model_validator(mode="after")
    def _feed_body_exists(self) -> Scene:
        bodies = self.drill_string.bodies
        if self.feed.acts_on != EVERY_BODY and self.feed.acts_on not in bodies:
            raise ValueError(f"feed.acts_on: {self.feed.acts_on!r}: not one of {EVERY_BODY}, {', '.join(bodies)}")
        return self

    @model_validator(mode="after")
    def _effects_and_outputs_consistent(self) -> Scene:
        effects = built_effects(self)  # raises where the effects contradict the outputs
        if effects.torsion and self.torsion is None:
            raise ValueError("the torsion effect needs a torsion section (inertia_kg_m2, stiffness_n_m_per_rad, "
                             "damping_n_m_s_per_rad, drive_torque_n_m, resisting_torque_n_m)")
        if effects.indexing and self.bit is None:
            raise ValueError("the indexing effect needs a bit section (diameter_m, gauge_button_diameter_m, "
                             "gauge_buttons)")
        if effects.indexing and not effects.rock_plasticity:
            raise _key_error("Scene", ("effects", "indexing"), True,
                             "needs the rock_plasticity effect, which is false here: an elastic rock never crushes, "
                             "so it leaves no craters for the blows to index; set rock_plasticity true or indexing "
                             "false")
        if effects.indexing and self.rotation is None and not effects.torsion:
            raise ValueError("the indexing effect needs the angle turned between blows: a rotation section "
                             "(speed_rpm) or the torsion effect")
        if effects.rock_damping and self.rock.law != "jenkins":
            raise _key_error("Scene", ("effects", "rock_damping"), True,
                             "rock law '{law}' has no rock damping effect (a law of one's own is built as its "
                             "parameters say); set it false or use law: jenkins", law=self.rock.law)
        if self.rock.own_law and (self.effects and self.effects.rock_plasticity is False or effects.indexing):
            key = "indexing" if effects.indexing else "rock_plasticity"
            raise _key_error("Scene", ("effects", key), getattr(effects, key),
                             "a built-in law's effect; a law of one's own ('{law}') is built as its parameters say",
                             law=self.rock.law)
        outputs = self.outputs or Outputs()
        pistonless = [o for o in outputs.metrics + outputs.timeseries if not _has_piston_data(self, _need(o))]
        if pistonless:
            raise ValueError(f"outputs {', '.join(pistonless)} need a piston (impact.piston)")
        bodies = {f"{name}[{i}]" if body.segments > 1 else name for name, body in self.drill_string.bodies.items()
                  for i in range(body.segments)} | set(self.drill_string.bodies)
        rods = {name for name, body in self.drill_string.bodies.items() if body.is_rod}
        rodless = [o for o in outputs.metrics if "rods" in _need(o).data and _need(o).bodies and not _need(o).bodies <= rods
                   and _need(o).bodies <= bodies] + ([o for o in outputs.metrics if o == "rod_stress_max_pa"] if not rods else [])
        if rodless:
            raise ValueError(f"outputs {', '.join(rodless)} need a rod (a body with length_m and diameter_m)")
        missing = [o for o in outputs.metrics + outputs.timeseries if not _need(o).bodies <= bodies]
        if missing:
            absent = set().union(*(_need(o).bodies for o in missing)) - bodies
            raise ValueError(f"outputs {', '.join(missing)} need a body named {', '.join(sorted(absent))} "
                             f"in drill_string.bodies")
        return self

    @model_validator(mode="after")
    def _end_time_and_step_fit_the_blows(self) -> Scene:
        period = self.impact.period_s
        if self.solver.end_time_s < period * (1 - 1e-12):  # a period of the run's end time, to its rounding
            raise ValueError(
                f"solver.end_time_s {self.solver.end_time_s} is shorter than one impact period ({period:.6g} s)"
            )
        needed = (self.metrics.transient_blows + self.metrics.block_blows) * period
        if self.solver.end_time_s < needed * (1 - 1e-12):
            raise ValueError(
                f"solver.end_time_s: {self.solver.end_time_s}: covers {self.solver.end_time_s / period:.3g} blows; "
                f"the metrics need transient_blows + block_blows = "
                f"{self.metrics.transient_blows + self.metrics.block_blows} blows ({needed:.6g} s)"
            )
        if self.solver.step_s is not None and self.solver.step_s > period / 20:
            raise ValueError(f"solver.step_s: {self.solver.step_s}: must resolve the impact period: at most {period / 20:.3g} s")
        return self


def _need(output: str) -> Need:
    return SERIES[output] if output in SERIES else metric_need(output)


def _has_piston_data(scene: Scene, need: Need) -> bool:
    """Whether the scene has what an output's ``piston`` data need: a piston (impact.piston)."""
    return "piston" not in need.data or scene.impact.piston is not None


@dataclass(frozen=True)
class BuiltEffects:
    """Which effects a run builds (every one true or false) and why (``reasons``)."""

    torsion: bool
    rock_damping: bool
    rock_plasticity: bool
    joint_damping: bool
    indexing: bool
    reasons: Mapping[str, str]

    def as_dict(self) -> dict[str, bool]:
        return {effect: getattr(self, effect) for effect in EFFECTS}


def _available(scene: Scene, effect: str) -> bool:
    """Whether the scene's parameters give the effect anything to do."""
    return {
        "torsion": scene.torsion is not None,
        "rock_damping": scene.rock.law == "jenkins" and scene.rock.completed().damping_n_s_per_m > 0,
        "rock_plasticity": True,
        "joint_damping": any(c.damping_n_s_per_m > 0 for c in scene.drill_string.connectors.values()),
        "indexing": scene.bit is not None and (scene.rotation is not None or scene.torsion is not None)
        and not scene.rock.own_law,
    }[effect]


def built_effects(scene: Scene) -> BuiltEffects:
    """The effects a run of ``scene`` builds (Effects docstring): asked for, needed by an output, or,
    without an effects section, every effect the scene gives parameters for. ValueError when an
    effect switched off is needed by an output."""
    outputs = scene.outputs or Outputs()
    need = needs(outputs.metrics, outputs.timeseries)
    chosen, reasons = {}, {}
    for effect in EFFECTS:
        asked = None if scene.effects is None else getattr(scene.effects, effect)
        users = [o for o in outputs.metrics + outputs.timeseries if effect in _need(o).effects]
        if asked is False and users:
            raise ValueError(f"effects.{effect} is false but outputs {', '.join(users)} need it")
        if scene.effects is None:
            chosen[effect] = _available(scene, effect) or effect in need.effects
            reasons[effect] = "no effects section: full model" if chosen[effect] else \
                "no effects section, and nothing for it to do in this scene"
        elif asked:
            chosen[effect], reasons[effect] = True, "asked for"
        elif users:
            chosen[effect], reasons[effect] = True, f"needed by outputs: {', '.join(users)}"
        else:
            chosen[effect], reasons[effect] = False, "not asked for" if asked is None else "switched off"
    if chosen["indexing"] and not chosen["rock_plasticity"] and scene.effects.rock_plasticity is None:
        chosen["rock_plasticity"] = True  # blows meet craters only on a rock that crushes
        reasons["rock_plasticity"] = "needed by indexing (an elastic rock leaves no craters for the blows to index)"
    return BuiltEffects(**chosen, reasons=reasons)


def requested_outputs(scene: Scene, effects: BuiltEffects) -> Outputs:
    """The scene's outputs, or without an outputs section every metric and history of the effects
    built and the bodies present (a scene with rods: each rod's figures too, ``<rod>_compressive_stress_max_pa``
    ...: models.definition.outputs.BODY_METRICS of the rods' data)."""
    if scene.outputs is not None and (scene.outputs.metrics or scene.outputs.timeseries or not scene.outputs.gauges):
        return scene.outputs
    gauges = scene.outputs.gauges if scene.outputs is not None else {}  # gauges alone: the default outputs besides
    built = {effect for effect, on in effects.as_dict().items() if on}
    bodies = set(scene.drill_string.bodies)
    rods = any(body.is_rod for body in scene.drill_string.bodies.values())
    def available(need: Need) -> bool:
        return need.effects <= built and need.bodies <= bodies and _has_piston_data(scene, need) and \
            (rods or "rods" not in need.data)
    per_rod = [f"{name}{suffix}" for name, body in scene.drill_string.bodies.items() if body.is_rod
               for suffix, need in BODY_METRICS.items() if "rods" in need.data]
    return Outputs(metrics=[m for m, n in METRICS.items() if available(n)] + per_rod,
                   timeseries=[s for s, n in SERIES.items() if available(n)], gauges=gauges)
