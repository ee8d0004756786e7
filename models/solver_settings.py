"""A scene's ``solver`` section resolved into the settings of its formulation, once per run.

An accuracy preset (fast, standard, reference) fills the options the scene does not give; without
a preset and without explicit accuracy options the ``standard`` preset applies.

* exudyn: the preset's fixed-step solver (fast: RK44, standard and reference: RK67) at the smallest of
  a cap, a fraction of the pulse duration (a step must resolve the pulse) and a multiple of
  1/|lambda|_max (the stiffest or fastest mode, models.stability.spectral_radius_per_s); explicit
  ``type`` or ``step_s`` win (a step or tolerances without a preset and without a type: RK44). The
  stated errors (penetration rate relative to the exact formulation, energy balance relative to the
  impact work) are the largest measured on the hard scenes of tests/stability, rounded up
  (docs/stability.md); the suite checks them.
* ode: DOP853 at the preset's tolerances (absolute tolerance in the state's SI units), dense
  output sampled every ``sample_interval_s`` (default 2e-6 s).
* exact: exact to round-off at every preset; samples every ``output_interval_s``, every switch
  recorded (the energy outputs' works are integrated exactly from the propagators, whatever the
  samples).
"""

from __future__ import annotations

from dataclasses import dataclass

from rpdrill.models.formulations import DEFAULT_PRESET
from rpdrill.models.scene import Solver


@dataclass(frozen=True)
class ExudynPreset:
    """An Exudyn accuracy preset: a fixed-step solver and its step rule, step = min(step_s,
    pulse duration / steps_per_pulse, step_times_radius / |lambda|_max), and the errors it is stated to
    keep on every hard scene of tests/stability (penetration rate relative to the exact formulation,
    energy balance relative to the impact work), checked by that suite."""

    type: str
    step_s: float
    steps_per_pulse: int
    step_times_radius: float
    penetration_rate_error: float
    energy_balance_error: float

    def step(self, pulse_duration_s: float, spectral_radius_per_s: float) -> float:
        """The step of this preset for a pulse of ``pulse_duration_s`` and |lambda|_max ``spectral_radius_per_s``."""
        return min(self.step_s, pulse_duration_s / self.steps_per_pulse, self.step_times_radius / spectral_radius_per_s)


# Picked from the measured work-precision fronts (docs/stability.md, python benchmarks/bench_presets.py):
# fast: rk44 near its stability limit (2.4 / |lambda|_max), the step capped at 1e-4 s; standard and
# reference: rk67, whose sixth order makes a step of the same cost ~10 times more accurate than rk44's
# on the paper scene (its stability limit is ~1.0 / |lambda|_max).
EXUDYN_PRESETS: dict[str, ExudynPreset] = {
    "fast": ExudynPreset("rk44", 1e-4, 10, 1.9, penetration_rate_error=0.04, energy_balance_error=0.12),
    "standard": ExudynPreset("rk67", 5e-5, 20, 0.8, penetration_rate_error=5e-4, energy_balance_error=5e-3),
    "reference": ExudynPreset("rk67", 1e-5, 100, 0.2, penetration_rate_error=1e-4, energy_balance_error=3e-4),
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


Settings = ExudynSettings | OdeSettings | ExactSettings


def _preset(solver: Solver, accuracy_keys: tuple[str, ...]) -> str | None:
    """The preset in force: the one given, else ``standard`` unless accuracy options are given."""
    if solver.preset is not None:
        return solver.preset
    return None if any(getattr(solver, key) is not None for key in accuracy_keys) else DEFAULT_PRESET


def _given(solver: Solver, key: str, default: float) -> float:
    value = getattr(solver, key)
    return default if value is None else value


def resolve_settings(solver: Solver, pulse_duration_s: float, spectral_radius_per_s: float | None) -> Settings:
    """The settings of ``solver``'s formulation (module doc): ``spectral_radius_per_s`` is |lambda|_max
    (an Exudyn preset's step follows it; None for the other formulations)."""
    common = {"formulation": solver.formulation, "end_time_s": solver.end_time_s,
              "output_interval_s": solver.output_interval_s}
    if solver.formulation == "exudyn":
        preset = _preset(solver, EXUDYN_ACCURACY_KEYS)
        tier = EXUDYN_PRESETS[preset or DEFAULT_PRESET]
        step = solver.step_s
        if step is None:
            step = tier.step(pulse_duration_s, spectral_radius_per_s)
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
                         preset=solver.preset, **common)
