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

import warnings
from dataclasses import replace

from ..definition.formulations import DEFAULT_PRESET
from ..definition.scene import Impact, Solver
from ..drill.wave_rod import WaveRod
from ..evaluation.solver_settings import EXUDYN_PRESETS, ExactSettings, Settings
from .history import wave_step_s

STEPS_PER_TRANSIT = {"fast": 20, "standard": 50, "reference": 200}
STEPS_PER_PULSE = {"fast": 50, "standard": 100, "reference": 400}
TRANSIT_TOLERANCE = 1e-3  # the largest rounding (N h - T) / T of a transit time (or a pulse's length) run


class WaveStepRounded(UserWarning):
    """A wave step given in the scene run as the nearest one on the rods' grid (said once per run).

    Attributes
    ----------
    args : tuple of str
        The message: the step asked for and the step run.

    Examples
    --------
    >>> import rpdrill
    >>> issubclass(rpdrill.WaveStepRounded, UserWarning)
    True
    """


class WaveStepError(ValueError):
    """A wave step given in the scene that the rods' grid refuses: the solver ``key``, its value, why."""

    def __init__(self, key: str, value: float, message: str) -> None:
        super().__init__(message)
        self.key, self.value = key, value


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
    if given is not None:
        exact = isinstance(settings, ExactSettings)
        _check_given(step, given, durations, [rod.name for rod in rods], impact, exact)
        if abs(step - given) > 1e-9 * given:
            warnings.warn(f"solver.{'wave_step_s' if exact else 'step_s'} {given:g} runs as {step:.6g} s: the nearest "
                          "step that divides the blow period and makes every rod's transit time a whole number of "
                          f"steps to {TRANSIT_TOLERANCE:g} (the rods' grid)", WaveStepRounded, stacklevel=2)
    if isinstance(settings, ExactSettings):
        return replace(settings, wave_step_s=step)
    return replace(settings, step_s=step)


def _check_given(step: float, given: float, durations: list[float], names: list[str], impact: Impact,
                 exact: bool) -> None:
    """WaveStepError when the step near the given one (a whole fraction of the blow period) leaves a rod's
    transit time (or the pulse's length) off a whole number of steps by more than TRANSIT_TOLERANCE: the waves
    would arrive late or early by that share of their transit (a step of 1 ms on a 3.66 m rod: 42 %, and a rate
    11 times the drill's, measured). The message names the largest step that keeps them whole."""
    counts = [max(1, round(d / step)) for d in durations]
    errors = [abs(n * step - d) / d for n, d in zip(counts, durations, strict=True)]
    worst = max(range(len(errors)), key=errors.__getitem__)
    if errors[worst] <= TRANSIT_TOLERANCE:
        return
    what = "the pulse's length" if worst >= len(names) else f"rod {names[worst]}'s transit time"
    fitting = wave_step_s(durations, min(given, min(durations) / STEPS_PER_TRANSIT["fast"]), impact.period_s)
    fits = max(abs(max(1, round(d / fitting)) * fitting - d) / d for d in durations) <= TRANSIT_TOLERANCE
    key = "wave_step_s" if exact else "step_s"
    suggestion = f"; at most {fitting:.4g} s keeps them whole" if fits else ""
    raise WaveStepError(key, given, f"the wave step it gives ({step:.4g} s, a whole fraction of the blow period "
                        f"{impact.period_s:.4g} s) makes {what} ({durations[worst]:.4g} s) {counts[worst]} steps, "
                        f"off by {errors[worst]:.1%}: the waves would arrive off their time; a step must make every "
                        f"rod's transit time (and a prescribed pulse) a whole number of steps to "
                        f"{TRANSIT_TOLERANCE:g}{suggestion}")
