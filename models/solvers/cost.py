"""What a prepared run will cost, estimated before it runs: steps, memory and CPU time, and the
scene key that makes it cost that much.

With T = ``solver.end_time_s``, r the rate of the fastest element (models.evaluation.stability.fastest_element,
of the order of the spectral radius |lambda|_max), n bodies and a state of m = 2 n + rock states
+ 2 (torsion) + 3 (the constant and the pulse generator) values:

* exudyn: T / ``step_s`` steps (for dopri5 and ode23 ``step_s`` is the largest step: a lower
  bound; a scene with extensions: the step of its built model, sized for the assembled system); it
  stores every step when an energy output is asked for, else every
  ``output_interval_s``, two values (time, value) per sensor of 2 n + 4;
* exact: T / h sub-grid points, h the exact solver's own sub-step (models.solvers.exact_system.sub_step:
  the sample interval over ceil(sample interval x ||A_bal||_1)); it stores m + 2 values per
  sample and per allowed switch, and about OPERATOR_VALUES m^2 values per (mode, pulse phase) of
  the rock law;
* ode: T r ODE_STEPS_PER_RADIAN steps (measured), DOP853's dense output (ODE_STAGES
  states per step) and m values per sample.

* a scene with wave rods (models.waves), either formulation: T / h steps of the characteristics, h the
  wave step (models.waves.steps), at a measured cost per step and body; it stores its samples, every rod
  end's waves over the longest rod's transit (T_rod / h steps: a tiny step on a long rod is refused naming the
  key that makes that rod's transit long against the step) and the levels of its keys.

Histories resampled after the run (``rpdrill simulate``: every ``output_interval_s``) add 2 n + 8
columns. Memory is 8 bytes per value times the copies held at the peak (MEMORY_COPIES,
OUTPUT_COPIES); CPU time is steps x the measured cost of a step, a + b n^p seconds (p = 2 for the
exact formulation, whose sub-step is a product with a dense m x m propagator, with and without its
energy works; 1 otherwise).
``python benchmarks/bench_budgets.py`` measures the constants and prints estimate against
measurement on the shipped scenes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..definition.formulations import DEFAULT_PRESET
from ..drill.piston import PISTON
from ..drill.pulse import phase_pieces
from ..evaluation.solver_settings import EXUDYN_PRESETS
from ..evaluation.stability import SimulationFailed, element_rates
from ..waves.steps import STEPS_PER_PULSE, STEPS_PER_TRANSIT
from .exact_system import sub_step
from .simulation import Simulation

# Measured by benchmarks/bench_budgets.py (one BLAS thread, shared 2-core machine):
# (a, b, p) of a + b n^p; the exact formulation with its energy works (an energy output asked for), and
# without (a scan of the penetration rate)
CPU_S_PER_STEP = {"exudyn": (3e-6, 6e-7, 1), "exact": (2.6e-7, 3.2e-9, 2), "exact without energy": (1e-7, 2.9e-9, 2),
                  "ode": (4.5e-4, 0.0, 1),
                  # a step of the characteristics (benchmarks/bench_waves.py --strings: 14 and 12 bodies)
                  "exact waves": (0.0, 2e-6, 1), "exudyn waves": (0.0, 1.7e-5, 1)}
ODE_STEPS_PER_RADIAN = 2.0  # DOP853 steps per unit of r T
# a rod end's stored waves per step of the characteristics held (models.waves.history: left, right, start, square,
# mean, broken) over the longest rod's transit; the levels of one key of the characteristics' system (models.waves.levels:
# 33 propagators, their Gram matrices and integrals) per state^2, and at most this many keys held
WAVE_VALUES_PER_CELL = 6
WAVE_KEY_VALUES = 100
WAVE_KEYS = 64
ODE_STAGES = 10  # state vectors per step kept by DOP853's dense output
OPERATOR_VALUES = 55  # values per state^2 of one exact propagator key (expm, anchors, read-outs, Taylor)
# stored values held at once at the peak of a run (its storage, the result's arrays and their copies),
# and of the histories resampled at the output interval (the columns and the table written)
MEMORY_COPIES = {"exudyn": 4, "exact": 2, "ode": 3}
OUTPUT_COPIES = 2
BYTES_PER_VALUE = 8
# What a run usually is: the key that departs most from these is named as the cause.
USUAL_END_TIME_S, USUAL_STEP_S, USUAL_INTERVAL_S = 1.0, 1e-5, 1e-4


@dataclass(frozen=True)
class Cause:
    """The scene key (dotted path) and value that make a run cost what it does."""

    key: str
    value: float | str


@dataclass(frozen=True)
class RunCost:
    """A run's estimated steps (and the step), memory and CPU time, and the keys that set them."""

    steps: float
    step_s: float
    steps_cause: Cause
    memory_bytes: float
    memory_cause: Cause
    cpu_s: float


def _named(cause: Cause, interval_s: float | None, usual_s: float, end_time_s: float) -> Cause:
    """The key that makes T / interval large: ``cause`` (which sets the step or storage interval),
    or the end time when it departs more from a usual run (log scale)."""
    if interval_s is not None and math.log10(end_time_s / USUAL_END_TIME_S) > math.log10(usual_s / interval_s):
        return Cause("solver.end_time_s", end_time_s)
    return cause


def _fastest(simulation: Simulation) -> Cause:
    return Cause(simulation.fastest.key, simulation.fastest.value)


def _pulse(simulation: Simulation) -> Cause:
    """The key of the impact pulse's duration (a piston's contact: the piston)."""
    if simulation.piston is None:
        return Cause("impact.duration_s", simulation.scene.impact.duration_s)
    return Cause("impact.piston", f"a contact of {simulation.pulse_duration_s:.3g} s")


def _fastest_or_pulse(simulation: Simulation) -> Cause:
    """The key of the fastest rate of the exact formulation's matrices: the drill's fastest element, or the
    pulse generator's pi / duration (a half-sine's angular rate) when that is faster (a 1 ns pulse)."""
    if math.pi / simulation.pulse_duration_s > simulation.fastest.rate_per_s:
        return _pulse(simulation)
    return _fastest(simulation)


def _rock_damper(simulation: Simulation) -> Cause:
    """The key of the rock damper's rate c_n / m_bit that departs more from the drill's other values."""
    damper = next(e for e in element_rates(simulation.scene, simulation.chain, simulation.rock, simulation.torsion)
                  if "rock.damping_n_s_per_m" in (e.key, e.other_key))
    return Cause(damper.key, damper.value)


def _interval(simulation: Simulation) -> Cause:
    """The key of the sample interval of the exact and ODE formulations (given, or the output interval)."""
    key = "sample_interval_s" if simulation.scene.solver.sample_interval_s is not None else "output_interval_s"
    return Cause(f"solver.{key}", simulation.settings.sample_interval_s)


# A part of the memory: what sets it, values, and the interval it stores at (None: not per time)
Part = tuple[Cause, float, float | None]


def _extended(simulation: Simulation) -> tuple[Simulation, Cause | None]:
    """The simulation as the Exudyn model of a scene with extensions sizes it (the step of the assembled
    system, models.solvers.exudyn_model), and the extensions as the cause when they made it faster. Where an
    extension fails on the model, the drill's own (the run fails and says why: models.solvers.exudyn_messages).
    A step the scene fixes (``solver.step_s``) or the wave rods' is the step whatever they add: no model is built."""
    if not simulation.scene.extensions or simulation.scene.solver.step_s is not None or simulation.dynamic_chain.waves:
        return simulation, None
    from .exudyn_model import build_exudyn  # Exudyn only for a scene with extensions

    try:
        sized = build_exudyn(simulation, graphics=False).simulation
    except SimulationFailed:
        return simulation, None
    faster = sized.spectral_radius_per_s > simulation.spectral_radius_per_s * (1 + 1e-9)
    return sized, Cause("extensions", ", ".join(simulation.scene.extensions)) if faster else None


def _exudyn(simulation: Simulation) -> tuple[float, Cause, list[Part]]:
    simulation, extended = _extended(simulation)
    settings, scene, n = simulation.settings, simulation.scene, simulation.dynamic_chain.size
    step = settings.step_s
    limits = EXUDYN_PRESETS[settings.preset or DEFAULT_PRESET].step_limits(simulation.pulse_duration_s,
                                                                          simulation.step_scales)
    if scene.solver.step_s is not None:
        cause = Cause("solver.step_s", step)
    elif extended is not None and min(limits["stability"], limits["ringing"]) <= step * (1 + 1e-9):
        cause = extended
    elif math.isclose(step, limits["pulse"]):
        cause = _pulse(simulation)
    elif math.isclose(step, limits["damper"]):
        cause = _rock_damper(simulation)
    else:
        cause = _fastest(simulation)
    every_step = "energy" in simulation.needed_data or settings.output_interval_s < step
    storage = (cause, step) if every_step else (Cause("solver.output_interval_s", settings.output_interval_s),
                                                settings.output_interval_s)
    return step, cause, [(storage[0], settings.end_time_s / storage[1] * 2 * (2 * n + 4), storage[1])]


def _state_size(simulation: Simulation) -> int:
    return 2 * simulation.dynamic_chain.size + len(simulation.rock.state_names) + 2 * (simulation.torsion is not None) + 3


def _exact(simulation: Simulation) -> tuple[float, Cause, list[Part]]:
    settings, m, sampled = simulation.settings, _state_size(simulation), _interval(simulation)
    one_period = phase_pieces(simulation.impact, simulation.impact.period_s)[1]  # every pulse phase of the run
    _, _, step = sub_step(simulation, one_period)
    switches = settings.max_switches_per_blow * math.ceil(settings.end_time_s * simulation.impact.frequency_hz)
    keys = len(simulation.rock.modes()) * len(set(one_period))
    return step, sampled if step == settings.sample_interval_s else _fastest_or_pulse(simulation), [
        (sampled, settings.end_time_s / settings.sample_interval_s * (m + 2), settings.sample_interval_s),
        (Cause("solver.max_switches_per_blow", settings.max_switches_per_blow), 2 * switches * (m + 3), None),
        (Cause("drill_string.bodies", f"{simulation.dynamic_chain.size} lumped bodies"), keys * OPERATOR_VALUES * m**2, None)]


def _ode(simulation: Simulation) -> tuple[float, Cause, list[Part]]:
    settings, m, sampled = simulation.settings, _state_size(simulation), _interval(simulation)
    steps = max(1.0, settings.end_time_s * simulation.fastest.rate_per_s * ODE_STEPS_PER_RADIAN)
    fastest = _fastest(simulation)
    return settings.end_time_s / steps, fastest, [
        (sampled, settings.end_time_s / settings.sample_interval_s * m, settings.sample_interval_s),
        (fastest, steps * ODE_STAGES * m, settings.end_time_s / steps)]


def _waves(simulation: Simulation) -> tuple[float, Cause, list[Part]]:
    """A scene with wave rods (models.waves.steps): T / h steps of the characteristics in either formulation,
    h the scene's step or the shortest rod transit (or the pulse) over the preset's steps per transit;
    its samples hold the state, two ends per rod and the rigid joints' forces."""
    settings, scene, waves = simulation.settings, simulation.scene, simulation.dynamic_chain.waves
    step = settings.wave_step_s if settings.formulation == "exact" else settings.step_s
    given = "wave_step_s" if settings.formulation == "exact" else "step_s"
    if getattr(scene.solver, given) is not None:
        cause = Cause(f"solver.{given}", step)
    else:
        preset = settings.preset or DEFAULT_PRESET
        shortest = min(waves, key=lambda rod: rod.transit_time_s)
        cause = _rod_cause(scene, shortest.name)
        if simulation.pulse_duration_s / STEPS_PER_PULSE[preset] < shortest.transit_time_s / STEPS_PER_TRANSIT[preset]:
            cause = _pulse(simulation)
    sampled = _interval(simulation) if settings.formulation == "exact" else \
        Cause("solver.output_interval_s", settings.output_interval_s)
    values = _state_size(simulation) + 2 + 2 * len(waves) + len(simulation.dynamic_chain.links)
    longest = max(waves, key=lambda rod: rod.transit_time_s)
    grid = cause if getattr(scene.solver, given) is not None else _rod_cause(scene, longest.name)
    cells = 2 * len(waves) * (longest.transit_time_s / step + 2) * WAVE_VALUES_PER_CELL
    m = _state_size(simulation) + 4 * len(waves)  # the characteristics' state: every port's (a, b)
    keys = min(2 ** len(simulation.dynamic_chain.nonlinear_links()) * len(simulation.rock.modes()), WAVE_KEYS)
    return step, cause, [(sampled, settings.end_time_s / sampled.value * values, sampled.value), (grid, cells, None),
                         (Cause("drill_string.bodies", f"{len(waves)} wave rods"), keys * WAVE_KEY_VALUES * m**2, None)]


def _rod_cause(scene, name: str) -> Cause:
    """The key of a rod's transit time that departs most from a steel rod of a metre (log scale): its length,
    its Young's modulus or its density (a piston's under impact.piston)."""
    body = scene.impact.piston if name == PISTON else scene.drill_string.bodies[name]
    where = "impact.piston" if name == PISTON else f"drill_string.bodies.{name}"
    departures = {"length_m": abs(math.log10(body.length_m / 1.0)),
                  "youngs_modulus_pa": abs(math.log10(body.youngs_modulus_pa / 2.1e11)),
                  "density_kg_per_m3": abs(math.log10(body.density_kg_per_m3 / 7850.0))}
    key = max(departures, key=departures.get)
    return Cause(f"{where}.{key}", getattr(body, key))


ESTIMATES = {"exudyn": _exudyn, "exact": _exact, "ode": _ode}


def cost_key(simulation: Simulation) -> str:
    """The key of CPU_S_PER_STEP for ``simulation``: its formulation (the exact one with or without
    the energy works its outputs need)."""
    formulation = simulation.settings.formulation
    if formulation == "exact" and "energy" not in simulation.needed_data:
        return "exact without energy"
    return formulation


def run_cost(simulation: Simulation, resampled: Cause | None = None) -> RunCost:
    """The estimated cost of running ``simulation`` (module doc), its histories then resampled at the
    interval ``resampled`` names (``rpdrill simulate``: ``solver.output_interval_s``) or not (None)."""
    settings, n = simulation.settings, simulation.dynamic_chain.size
    end = settings.end_time_s
    waves = bool(simulation.dynamic_chain.waves) and settings.formulation != "ode"
    step, cause, parts = (_waves if waves else ESTIMATES[settings.formulation])(simulation)
    values = sum(part[1] for part in parts) * MEMORY_COPIES[settings.formulation]
    if resampled is not None:
        parts.append((resampled, end / resampled.value * (2 * n + 8), resampled.value))
        values += parts[-1][1] * OUTPUT_COPIES
    largest, _, interval = max(parts, key=lambda part: part[1])
    a, b, power = CPU_S_PER_STEP[f"{settings.formulation} waves" if waves else cost_key(simulation)]
    return RunCost(steps=end / step, step_s=step, steps_cause=_named(cause, step, USUAL_STEP_S, end),
                   memory_bytes=values * BYTES_PER_VALUE, memory_cause=_named(largest, interval, USUAL_INTERVAL_S, end),
                   cpu_s=end / step * (a + b * n**power))
