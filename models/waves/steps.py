"""The step of the characteristics of a run with wave rods, from the scene's solver section.

The step h is the grid of the waves (models.waves.history) and, in the Exudyn formulation, Exudyn's
own fixed step. It divides the blow period (blows start on the grid) and is chosen so that every rod's
transit time, and a prescribed pulse's length, are whole numbers of steps to 1e-3 where such a step
exists near the target (:func:`models.waves.history.wave_step_s`; the rounding is stated in the run's
info, ``transit_time_errors``). The target is the scene's (exact: ``wave_step_s``; Exudyn: ``step_s``) or
the preset's: the shortest transit time over STEPS_PER_TRANSIT and the pulse over STEPS_PER_PULSE,
and at most the preset's cap.
"""

from __future__ import annotations

from dataclasses import replace

from ..definition.formulations import DEFAULT_PRESET
from ..definition.scene import Impact, Solver
from ..drill.wave_rod import WaveRod
from ..evaluation.solver_settings import EXUDYN_PRESETS, ExactSettings, Settings
from .history import wave_step_s

STEPS_PER_TRANSIT = {"fast": 20, "standard": 50, "reference": 200}
STEPS_PER_PULSE = {"fast": 50, "standard": 100, "reference": 400}


def target_step_s(preset: str, rods: tuple[WaveRod, ...], pulse_duration_s: float) -> float:
    """min(shortest transit / STEPS_PER_TRANSIT, pulse / STEPS_PER_PULSE, the preset's cap)."""
    shortest = min(rod.transit_time_s for rod in rods)
    return min(shortest / STEPS_PER_TRANSIT[preset], pulse_duration_s / STEPS_PER_PULSE[preset],
               EXUDYN_PRESETS[preset].step_s)


def wave_settings(settings: Settings, solver: Solver, rods: tuple[WaveRod, ...], impact: Impact,
                  pulse_duration_s: float) -> Settings:
    """``settings`` with the run's wave step (module doc): ``wave_step_s`` (exact) or ``step_s`` (Exudyn); the
    ode formulation's unchanged (it refuses wave rods)."""
    if settings.formulation == "ode":
        return settings
    given = solver.wave_step_s if isinstance(settings, ExactSettings) else solver.step_s
    target = given or target_step_s(settings.preset or DEFAULT_PRESET, rods, pulse_duration_s)
    durations = [rod.transit_time_s for rod in rods]
    if impact.piston is None:
        durations.append(impact.duration_s)
    step = wave_step_s(durations, target, impact.period_s)
    if isinstance(settings, ExactSettings):
        return replace(settings, wave_step_s=step)
    return replace(settings, step_s=step)
