"""One scene prepared for a run: everything a formulation needs, resolved once.

:func:`prepare` turns a validated :class:`~rpdrill.models.definition.scene.Scene` (data only) into a
:class:`Simulation`: the effects built and why, the outputs asked for, the axial chain, the rock law
as built, the solver settings of the scene's formulation (an accuracy preset resolved into a step
or tolerances), the initial state (rest, or the static preload), and the indexing model (the
``indexing`` effect: models.drill.indexing) whose blow starts every formulation applies. Every formulation, the metrics,
the energy account and the stability checks read these fields; nothing derives them again.
models.solvers.time_run runs it through the formulation registry (models.definition.formulations):
:func:`implementation` imports a formulation's module on first use (the exact and ODE formulations never import
Exudyn); each provides ``simulate(simulation, progress=None)`` and, if it cannot run every scene,
``unsupported(simulation) -> str | None``, there or in the lighter ``checks`` module the registry names (the
exact formulation's exact_system: a study checks its points before any run without loading the compiled kernels).
"""

from __future__ import annotations

import importlib
import math
import sys
from dataclasses import dataclass, replace
from types import ModuleType
from typing import Any

import numpy as np

from ...rocklaw import RockLaw, State
from ..definition.extensions import CodeRecords, refusal
from ..definition.extensions import records as extension_records
from ..definition.formulations import AUTOMATIC_STEP_SOLVERS, FORMULATIONS
from ..definition.outputs import needs
from ..definition.scene import (
    BuiltEffects,
    Impact,
    Outputs,
    Scene,
    Torsion,
    built_effects,
    requested_outputs,
)
from ..drill.chain import (
    STATIC_CONDITION_LIMIT,
    AxialChain,
    axial_chain,
    static_preload_m,
    static_torsion_angle_rad,
)
from ..drill.indexing import BlowStarts, Indexing
from ..drill.piston import PistonSetup, piston_setup
from ..drill.pulse import impulse_per_blow_n_s
from ..drill.wave_rod import WaveRod
from ..evaluation.solver_settings import ExudynSettings, Settings, resolve_settings
from ..evaluation.stability import FastestElement, StepScales, fastest_element, spring_spread, step_scales
from ..waves.statics import wave_preload_m
from ..waves.steps import WaveStepError, wave_settings


class SceneError(ValueError):
    """A scene that validates but cannot be run as given: names the key path and its value."""

    def __init__(self, location: tuple[str, ...], value: Any, message: str) -> None:
        super().__init__(message)
        self.location, self.value = location, value


@dataclass(frozen=True)
class ExtensionCoordinates:
    """The ODE2 coordinates an Exudyn model's extensions add, as a steady-state run follows them
    (models.steady.extension_section): a label each, their ``drift`` with the hole (the shift of each when the
    whole drill moves by one: 1 for a position that moves with it, 0 for one that does not) and their
    ``start`` (positions, then velocities; None: as the extensions make them). The Exudyn model records them
    (SimulationResult.extension_state) and starts them there."""

    labels: tuple[str, ...]
    drift: tuple[float, ...]
    start: tuple[float, ...] | None = None


@dataclass(frozen=True)
class Simulation:
    """A scene prepared for a run (module doc)."""

    scene: Scene
    effects: BuiltEffects
    outputs: Outputs
    chain: AxialChain
    rock: RockLaw
    settings: Settings
    initial_positions_m: np.ndarray
    initial_rock_state: State
    initial_torsion_angle_rad: float
    step_scales: StepScales | None  # the rates a fixed step resolves, bit on the rock (Exudyn runs only)
    fastest: FastestElement  # the element of the highest rate and the keys that set it
    indexing: Indexing | None = None
    piston: PistonSetup | None = None  # a piston striking the impact body (models.drill.piston), or the pulse
    # a start in motion (models.steady: a periodic orbit's state at a blow start); None and 0: at rest
    initial_velocities_m_per_s: np.ndarray | None = None
    initial_torsion_rate_rad_per_s: float = 0.0
    extension_coordinates: ExtensionCoordinates | None = None  # followed by a steady-state run (Exudyn only)

    @property
    def initial_velocities(self) -> np.ndarray:
        """The chain's initial velocities (zero at rest)."""
        given = self.initial_velocities_m_per_s
        return np.zeros(self.chain.size) if given is None else given

    @property
    def dynamic_chain(self) -> AxialChain:
        """What the formulations integrate: the chain, with the piston's bodies appended when there is one."""
        return self.chain if self.piston is None else self.piston.dynamic_chain(self.chain)

    @property
    def pulse_duration_s(self) -> float:
        """The prescribed pulse's duration, or the piston's contact time (an estimate: models.drill.piston)."""
        return self.impact.duration_s if self.piston is None else self.piston.pulse_duration_s

    @property
    def name(self) -> str:
        return self.scene.name

    @property
    def spectral_radius_per_s(self) -> float | None:
        """|lambda|_max with the bit on the rock (Exudyn runs only)."""
        return None if self.step_scales is None else self.step_scales.spectral_radius_per_s

    @property
    def impact(self) -> Impact:
        return self.scene.impact

    @property
    def torsion(self) -> Torsion | None:
        """The torsion line when its effect is built."""
        return self.scene.torsion if self.effects.torsion else None

    def blow_starts(self) -> BlowStarts | None:
        """A new per-run tracker of the blow starts, or None when a blow start changes no rock state
        (no indexing, a law without blows: the paper's Eq. 4)."""
        if not self.rock.resets_at_blows:
            return None
        return BlowStarts(self.rock, self.indexing, self.initial_torsion_angle_rad)

    @property
    def feed_total_n(self) -> float:
        """The sum of the feed forces on the chain (F_dt, or F_dt on every body)."""
        return float(np.sum(self.chain.constant_forces()))

    @property
    def mean_thrust_n(self) -> float:
        """The mean force on the rock in steady drilling, F_feed + f J (J the impulse of one blow): over a
        period the chain's momentum returns, so the rock takes all the feed and the blows push (a link
        from ground would take a share). Where it reaches the rock's threshold F_th, a Jenkins rock
        yields under the mean load and the bit sinks at a rate set only by the rock damper."""
        return self.feed_total_n + impulse_per_blow_n_s(self.impact) * self.impact.frequency_hz

    @property
    def needed_data(self) -> frozenset[str]:
        """What must be recorded for the requested outputs: ``forces``, ``energy``."""
        return needs(self.outputs.metrics, self.outputs.timeseries).data

    def code_records(self) -> CodeRecords:
        """The code of one's own the run imports, as provenance keeps it: every extension (import path,
        package and version where it has one, the file, its parameters) and a rock law of one's own."""
        return CodeRecords(extension_records(self.scene.extensions),
                           self.scene.rock.code_record() if self.scene.rock.own_law else None)

    def resolved_scene(self) -> dict[str, Any]:
        """The scene as run: rock values filled in, the effects built and why, the outputs, and the
        solver settings of the formulation (a preset resolved)."""
        data = self.scene.model_dump(mode="json", by_alias=True, exclude_none=True)
        data["rock"] = self.scene.rock.completed().model_dump(mode="json", exclude_none=True)
        data["effects"] = {**self.effects.as_dict(), "reasons": dict(self.effects.reasons)}
        data["outputs"] = self.outputs.model_dump(mode="json")
        data["solver"] = {key: value for key, value in vars(self.settings).items() if value is not None}
        for name, recorded in self.code_records().extensions.items():  # informational (Extension)
            data["extensions"][name]["recorded"] = {key: value for key, value in recorded.as_dict().items()
                                                    if key != "parameters"}
        data["solver"]["steady_state"] = self.scene.solver.steady_state
        if self.piston is not None:  # the coupling across the contact as run
            given = self.scene.impact.piston.contact_stiffness_n_per_m
            faces = "rigid faces" if given is None else f"the faces' contact {given:.6g} N/m"
            data["effects"]["reasons"]["piston_contact"] = (
                f"coupling {self.piston.contact_stiffness_n_per_m:.6g} N/m: {faces} in series with the "
                "half-segments behind the faces")
        return data


def implementation(name: str, checks: bool = False) -> ModuleType:
    """The module of formulation ``name`` in this package (``checks``: its lighter checks module, if any)."""
    formulation = FORMULATIONS[name]
    return importlib.import_module(f".{(checks and formulation.checks) or formulation.module}", __package__)


def unsupported(name: str, simulation: Simulation) -> str | None:
    """Why formulation ``name`` cannot run ``simulation``, or None if it can: an extension that changes the
    motion of the Exudyn model, or what the formulation's own check says."""
    refused = refusal(simulation.scene.extensions, name)
    if refused:
        return refused[1]
    check = getattr(implementation(name, checks=True), "unsupported", None)
    return check(simulation) if check else None


def solver_settings(scene: Scene, piston: PistonSetup | None, scales: StepScales | None,
                    waves: tuple[WaveRod, ...] = ()) -> Settings:
    """The settings of the scene's formulation for a drill of these step scales (an Exudyn preset's step
    follows them; models.evaluation.solver_settings), and with wave rods the characteristics' step
    (models.waves.steps: blows start on its grid)."""
    pulse_s = scene.impact.duration_s if piston is None else piston.pulse_duration_s
    settings = resolve_settings(scene.solver, pulse_s, scales)
    if waves:
        try:
            return wave_settings(settings, scene.solver, waves, scene.impact, pulse_s)
        except WaveStepError as error:
            raise SceneError(("solver", error.key), error.value, str(error)) from None
    if piston is not None and isinstance(settings, ExudynSettings) and scene.solver.step_s is None:
        # the strikes fall on step starts: a whole number of steps per period (a strike one step late
        # shifts the blow against the string's ringing; 2 % in the rate of the top-hammer scene)
        settings = replace(settings, step_s=scene.impact.period_s / math.ceil(scene.impact.period_s / settings.step_s))
    return settings


def prepare(scene: Scene) -> Simulation:
    """Resolve ``scene`` for a run (module doc); SceneError where it cannot run as given."""
    effects = built_effects(scene)
    outputs = requested_outputs(scene, effects)
    chain = axial_chain(scene, joint_damping=effects.joint_damping)
    rock = scene.rock.build(damping=effects.rock_damping, plasticity=effects.rock_plasticity,
                            indexed=effects.indexing)
    torsion = scene.torsion if effects.torsion else None
    try:
        piston = piston_setup(scene, chain)
    except ValueError as err:
        raise SceneError(("impact", "piston", "contact_stiffness_n_per_m"), None, str(err)) from None
    dynamic = chain if piston is None else piston.dynamic_chain(chain)
    fastest = fastest_element(scene, chain, rock, torsion)
    waves = dynamic.waves
    scales = step_scales(dynamic, rock, torsion, scene.impact.period_s) \
        if scene.solver.formulation == "exudyn" and not waves else None
    if not math.isfinite(fastest.rate_per_s) or not math.isfinite(scales.spectral_radius_per_s if scales else 0.0):
        raise SceneError(tuple(fastest.key.split(".")), fastest.value,
                         f"with {fastest.other_key} {fastest.other_value:g} the model's fastest rate overflows "
                         f"(k/m or c/m beyond {sys.float_info.max:.3g}); give values of a physical drill")
    settings = solver_settings(scene, piston, scales, waves)
    if waves and settings.formulation == "exudyn" and settings.type in AUTOMATIC_STEP_SOLVERS:
        raise SceneError(("solver", "type"), settings.type, "wave rods step at the characteristics' fixed step "
                         "(every step advances the waves once): use a fixed-step type such as rk44")
    positions, angle = np.zeros(chain.size), 0.0
    if scene.start == "preloaded":
        try:
            positions = static_preload_m(chain, rock) if not chain.waves else wave_preload_m(chain, rock)
        except ValueError as err:
            key, value, stiffest, softest = spring_spread(scene, chain, rock)
            if stiffest > STATIC_CONDITION_LIMIT * softest:  # the cause, rather than a body with no rest position
                raise SceneError(tuple(key.split(".")), value, (
                    f"a spring of {stiffest:.3g} N/m against the softest one's {softest:.3g} N/m: more than "
                    f"{STATIC_CONDITION_LIMIT:.0e} apart, the static preload (start: preloaded) cannot be solved in "
                    "double precision; give the values of a physical drill, or use start: rest")) from None
            raise SceneError(("start",), scene.start, str(err)) from None
        if effects.torsion:
            angle = static_torsion_angle_rad(scene.torsion)
    state = rock.return_map(float(positions[chain.bit_body]), rock.initial_state())
    indexing = None
    if effects.indexing:
        indexing = Indexing(scene.bit, scene.rotation.speed_rpm if scene.rotation else None, scene.impact.frequency_hz)
        if indexing.speed_rpm is not None:  # the same share every blow: the law has it from the start
            rock = replace(rock, fresh_fraction=indexing.fresh_fraction(indexing.prescribed_angle_rad))
    return Simulation(scene, effects, outputs, chain, rock, settings, positions, state, angle, scales, fastest,
                      indexing, piston)


def as_simulation(run: Scene | Simulation) -> Simulation:
    """A prepared simulation (a scene is prepared here)."""
    return run if isinstance(run, Simulation) else prepare(run)


def exudyn_simulation(run: Scene | Simulation) -> tuple[Simulation, str]:
    """The prepared simulation the Exudyn model builds (models.solvers.exudyn_model.build_exudyn), and the
    formulation the scene named: a scene of another formulation is run by Exudyn with its common solver keys
    (end time, preset, output interval)."""
    simulation = as_simulation(run)
    named = simulation.settings.formulation
    if named != "exudyn":
        simulation = prepare(simulation.scene.with_solver("exudyn"))
    return simulation, named
