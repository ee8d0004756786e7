"""A scene's ``solver`` section resolved into the settings of its formulation, once per run.

An accuracy preset (fast, standard, reference) fills the options the scene does not give; without
a preset and without explicit accuracy options the ``standard`` preset applies.

* exudyn: RK44 at a fixed step, the smallest of a cap, a fraction of the pulse duration (a step
  must resolve the pulse) and a multiple of 1/|lambda|_max (the stiffest or fastest mode,
  models.stability.spectral_radius_per_s). The stated errors (relative to the reference preset,
  and of the energy balance relative to the impact work) are the largest measured on the hard
  scenes of tests/stability, rounded up (docs/stability.md); the suite checks them.
* ode: DOP853 at the preset's tolerances (absolute tolerance in the state's SI units), dense
  output sampled every ``sample_interval_s`` (default 2e-6 s).
* exact: exact to round-off at every preset; samples every ``output_interval_s`` (at most
  ENERGY_SAMPLE_S when an energy output is asked for: the trapezoidal energy integrals then close
  the balance to ~1e-4 of the impact work), every switch recorded.
"""

from __future__ import annotations

from dataclasses import dataclass

from rpdrill.models.formulations import DEFAULT_PRESET
from rpdrill.models.scene import Solver

EXUDYN_PRESETS: dict[str, dict[str, float]] = {
    "fast": {"step_s": 1e-4, "steps_per_pulse": 10, "step_times_radius": 0.8,
             "penetration_rate_error": 0.03, "energy_balance_error": 0.03},
    "standard": {"step_s": 4e-5, "steps_per_pulse": 25, "step_times_radius": 0.4,
                 "penetration_rate_error": 0.003, "energy_balance_error": 0.003},
    "reference": {"step_s": 5e-6, "steps_per_pulse": 200, "step_times_radius": 0.05,
                  "penetration_rate_error": 1e-4, "energy_balance_error": 1e-4},
}
ODE_PRESETS: dict[str, dict[str, float]] = {
    "fast": {"relative_tolerance": 1e-6, "absolute_tolerance": 1e-9},
    "standard": {"relative_tolerance": 1e-8, "absolute_tolerance": 1e-11},
    "reference": {"relative_tolerance": 1e-10, "absolute_tolerance": 1e-13},
}
EXUDYN_ACCURACY_KEYS = ("type", "step_s", "spectral_radius", "relative_tolerance", "absolute_tolerance")
ODE_SAMPLE_INTERVAL_S = 2e-6
ENERGY_SAMPLE_S = 1e-5


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


def resolve_settings(solver: Solver, pulse_duration_s: float, spectral_radius_per_s: float | None,
                     energy: bool) -> Settings:
    """The settings of ``solver``'s formulation (module doc): ``spectral_radius_per_s`` is |lambda|_max
    (an Exudyn preset's step follows it; None for the other formulations); ``energy``: an energy output
    is asked for."""
    common = {"formulation": solver.formulation, "end_time_s": solver.end_time_s,
              "output_interval_s": solver.output_interval_s}
    if solver.formulation == "exudyn":
        preset = _preset(solver, EXUDYN_ACCURACY_KEYS)
        step = solver.step_s
        if step is None:
            tier = EXUDYN_PRESETS[preset or DEFAULT_PRESET]
            step = min(tier["step_s"], pulse_duration_s / tier["steps_per_pulse"],
                       tier["step_times_radius"] / spectral_radius_per_s)
        return ExudynSettings(type=solver.type or "rk44", step_s=step, spectral_radius=_given(solver, "spectral_radius", 1.0),
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
    automatic = min(solver.output_interval_s, ENERGY_SAMPLE_S) if energy else solver.output_interval_s
    return ExactSettings(sample_interval_s=_given(solver, "sample_interval_s", automatic),
                         min_switch_interval_s=_given(solver, "min_switch_interval_s", 1e-12),
                         max_switches_per_blow=int(_given(solver, "max_switches_per_blow", 1000)),
                         preset=solver.preset, **common)
