"""A scene's ``solver`` section resolved into the settings of its formulation, once per run.

An accuracy preset (fast, standard, reference) fills the options the scene does not give; without
a preset and without explicit accuracy options the ``standard`` preset applies.

* exudyn: the preset's fixed-step solver (fast and standard: RK44, reference: RK67) at the smallest of
  a cap, a fraction of the pulse duration (a step must resolve the pulse), a multiple of
  1/|lambda|_max (the stiffest or fastest mode: stability), a smaller multiple of 1/|lambda| of the
  fastest mode still ringing at the next blow (accuracy where errors add up blow by blow) and, for
  the presets that resolve it, a share of m_bit / c_n (the rock damper's force jump at contact:
  StepScales); explicit ``type`` or ``step_s`` win (a step or tolerances without a
  preset and without a type: RK44). The stated errors (penetration rate relative to the exact
  formulation, energy balance relative to the impact work) are the largest measured on the hard
  scenes of tests/stability, rounded up (docs/stability.md); the suite checks them.
* ode: DOP853 at the preset's tolerances (absolute tolerance in the state's SI units), dense
  output sampled every ``sample_interval_s`` (default 2e-6 s).
* exact: exact to round-off at every preset; samples every ``output_interval_s``, every switch
  recorded (the energy outputs' works are integrated exactly from the propagators, whatever the
  samples).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..definition.formulations import DEFAULT_PRESET
from ..definition.scene import Solver


@dataclass(frozen=True)
class StepScales:
    """The rates, in 1/s, a fixed explicit step must resolve (from models.evaluation.stability.step_scales):

    * ``spectral_radius_per_s``: |lambda|_max, for stability;
    * ``ringing_radius_per_s``: the largest |lambda| of the modes that still ring when the next blow
      comes, decaying by less than a factor e over a blow period T (-Re(lambda) T < 1; 0 if none).
      The solver's phase and amplitude error on such a mode is carried into the next blow's contacts
      and adds up blow by blow, so the mode must be resolved, not only kept stable; a mode that dies
      within a blow starts afresh at each contact;
    * ``damper_rate_per_s``: c_n / m_bit. The rock damper's force jumps by c_n v when the bit meets
      the rock; a fixed step that straddles that instant puts the jump in the wrong part of the step,
      an impulse error up to c_n v h, the share c_n h / m_bit of the bit's momentum.
    """

    spectral_radius_per_s: float
    ringing_radius_per_s: float
    damper_rate_per_s: float


@dataclass(frozen=True)
class ExudynPreset:
    """An Exudyn accuracy preset: a fixed-step solver and its step rule (:meth:`step`), and the errors
    it is stated to keep on every hard scene of tests/stability (penetration rate relative to the exact
    formulation, energy balance relative to the impact work), checked by that suite."""

    type: str
    step_s: float
    steps_per_pulse: int
    step_times_radius: float
    step_times_ringing_radius: float
    damper_step_share: float | None  # c_n h / m_bit at most; None: the damper's jump is not resolved
    penetration_rate_error: float
    energy_balance_error: float

    def step_limits(self, pulse_duration_s: float, scales: StepScales) -> dict[str, float]:
        """Each bound on the step, by what sets it (a rate of 0 bounds nothing): ``cap`` step_s,
        ``pulse`` duration / steps_per_pulse, ``stability`` step_times_radius / |lambda|_max,
        ``ringing`` step_times_ringing_radius / |lambda| of the fastest mode still ringing at the next
        blow, ``damper`` damper_step_share m_bit / c_n."""
        def over(factor: float | None, rate_per_s: float) -> float:
            return math.inf if factor is None or rate_per_s <= 0 else factor / rate_per_s
        return {"cap": self.step_s, "pulse": pulse_duration_s / self.steps_per_pulse,
                "stability": over(self.step_times_radius, scales.spectral_radius_per_s),
                "ringing": over(self.step_times_ringing_radius, scales.ringing_radius_per_s),
                "damper": over(self.damper_step_share, scales.damper_rate_per_s)}

    def step(self, pulse_duration_s: float, scales: StepScales) -> float:
        """h = min(step_s, pulse / steps_per_pulse, step_times_radius / |lambda|_max,
        step_times_ringing_radius / |lambda|_ringing, damper_step_share m_bit / c_n)."""
        return min(self.step_limits(pulse_duration_s, scales).values())


# Picked from the measured work-precision fronts (docs/stability.md, python benchmarks/bench_presets.py
# --front): RK44 is the cheapest accurate candidate at the caps on the paper scene (1e-4 s: 6.3e-4 in
# the rate; 5e-5 s: 8.3e-5); the ringing factors bring the undamped scene within the stated errors
# (RK44: 0.3 -> 3.0e-4, 0.2 -> 5.9e-5), the damper share the critically damped one (0.03 -> 1.2e-5;
# the error there is first order in the step with scatter: 0.05 -> 1.4e-4). Reference: RK67, sixth
# order, at a small step everywhere.
EXUDYN_PRESETS: dict[str, ExudynPreset] = {
    "fast": ExudynPreset("rk44", 1e-4, 10, 1.9, 0.3, None, penetration_rate_error=1e-3, energy_balance_error=5e-2),
    "standard": ExudynPreset("rk44", 5e-5, 20, 1.0, 0.2, 0.03, penetration_rate_error=1e-4, energy_balance_error=3e-3),
    "reference": ExudynPreset("rk67", 1e-5, 100, 0.2, 0.2, None, penetration_rate_error=1e-4,
                              energy_balance_error=3e-4),
}
# the solver of a scene that gives its own step or tolerances, neither a preset nor a type
UNPRESET_TYPE = "rk44"
ODE_PRESETS: dict[str, dict[str, float]] = {
    "fast": {"relative_tolerance": 1e-6, "absolute_tolerance": 1e-9},
    "standard": {"relative_tolerance": 1e-8, "absolute_tolerance": 1e-11},
    "reference": {"relative_tolerance": 1e-10, "absolute_tolerance": 1e-13},
}
EXUDYN_ACCURACY_KEYS = ("type", "step_s", "spectral_radius", "relative_tolerance", "absolute_tolerance")
ODE_SAMPLE_INTERVAL_S = 2e-6


@dataclass(frozen=True)
class ExudynSettings:
    formulation: str
    type: str
    step_s: float
    spectral_radius: float
    relative_tolerance: float
    absolute_tolerance: float
    end_time_s: float
    output_interval_s: float
    preset: str | None


@dataclass(frozen=True)
class OdeSettings:
    formulation: str
    method: str
    relative_tolerance: float
    absolute_tolerance: float
    sample_interval_s: float
    end_time_s: float
    output_interval_s: float
    preset: str | None


@dataclass(frozen=True)
class ExactSettings:
    formulation: str
    sample_interval_s: float
    min_switch_interval_s: float
    max_switches_per_blow: int
    end_time_s: float
    output_interval_s: float
    preset: str | None
    wave_step_s: float | None = None  # the characteristics' step of a scene with wave rods (models.waves.steps)


Settings = ExudynSettings | OdeSettings | ExactSettings


def _preset(solver: Solver, accuracy_keys: tuple[str, ...]) -> str | None:
    """The preset in force: the one given, else ``standard`` unless accuracy options are given."""
    if solver.preset is not None:
        return solver.preset
    return None if any(getattr(solver, key) is not None for key in accuracy_keys) else DEFAULT_PRESET


def _given(solver: Solver, key: str, default: float) -> float:
    value = getattr(solver, key)
    return default if value is None else value


def resolve_settings(solver: Solver, pulse_duration_s: float, scales: StepScales | None) -> Settings:
    """The settings of ``solver``'s formulation (module doc): ``scales`` the rates an Exudyn preset's
    step follows (None for the other formulations)."""
    common = {"formulation": solver.formulation, "end_time_s": solver.end_time_s,
              "output_interval_s": solver.output_interval_s}
    if solver.formulation == "exudyn":
        preset = _preset(solver, EXUDYN_ACCURACY_KEYS)
        tier = EXUDYN_PRESETS[preset or DEFAULT_PRESET]
        step = solver.step_s
        if step is None:  # no scales: a scene with wave rods, whose step models.waves.steps sets
            step = tier.step(pulse_duration_s, scales) if scales is not None else tier.step_s
        return ExudynSettings(type=solver.type or (tier.type if preset else UNPRESET_TYPE), step_s=step,
                              spectral_radius=_given(solver, "spectral_radius", 1.0),
                              relative_tolerance=_given(solver, "relative_tolerance", 1e-8),
                              absolute_tolerance=_given(solver, "absolute_tolerance", 1e-12), preset=preset, **common)
    if solver.formulation == "ode":
        preset = _preset(solver, ("relative_tolerance", "absolute_tolerance"))
        tier = ODE_PRESETS[preset or DEFAULT_PRESET]
        return OdeSettings(method=solver.method or "DOP853",
                           relative_tolerance=_given(solver, "relative_tolerance", tier["relative_tolerance"]),
                           absolute_tolerance=_given(solver, "absolute_tolerance", tier["absolute_tolerance"]),
                           sample_interval_s=_given(solver, "sample_interval_s", ODE_SAMPLE_INTERVAL_S),
                           preset=preset, **common)
    return ExactSettings(sample_interval_s=_given(solver, "sample_interval_s", solver.output_interval_s),
                         min_switch_interval_s=_given(solver, "min_switch_interval_s", 1e-12),
                         max_switches_per_blow=int(_given(solver, "max_switches_per_blow", 1000)),
                         preset=solver.preset, wave_step_s=solver.wave_step_s, **common)
