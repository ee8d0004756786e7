"""The paper's Eq. 4 as a plain ODE with event-located switches (no Exudyn).

State y = [x (n bodies), v (n bodies), rock law states (, phi, omega)] of the prepared
simulation's chain and rock law:

    (x, v)' = A (x, v, 1) + (F_d(t) e_shank / m_shank) - F_rock e_bit / m_bit
              + sum over nonlinear links of F_link (e_a - e_b) / m     (couplings, models.definition.links)
    state' = rates of the rock law's mode             (Jenkins: Eq. 2, x_n' = x_bit' while crushing)
    (phi, omega)' = T (phi, omega, 1)                 (Eq. 4, torsion line, if its effect is on)

with A the chain's first-order matrix (models.drill.chain: x' = v, M v' = -K x - C v + F_feed over the
linear links) and T its torsion matrix. F_rock is the law's closed-form ``force`` at (x_bit,
x_bit', state) (Jenkins: Eq. 1 at d = x_bit - x_n), each nonlinear link's force its closed form.
The laws are piecewise; the integration never steps over a switch. Each piece runs in one mode of
every piecewise element (models.drill.piecewise: the rock law and the nonlinear links, whose mode tables
are the laws' own declarations) and stops at the first zero crossing of one of the current modes'
exits; the next piece starts in the element's next mode from its entry state. The piston pulse's
switch times (models.drill.pulse.switch_times) are breakpoints: the run is integrated segment by segment
between them, and the pulse is evaluated on the segment's own side of each switch. At a blow start
the rock law's blow reset (models.drill.indexing.BlowStarts: the state the blow meets) is applied to the
rock states when the law has one, and the rock's mode is found again.

A piston (models.drill.piston) adds its bodies to x and v (the dynamic chain) and its contact to the
nonlinear links (models.drill.piston.PistonContact, whose modes carry the catch); its strike is a state
jump at every blow start (a segment boundary). A jump replaces the last sample, so that every
sample is after the jumps at its time.
"""

from __future__ import annotations

import itertools
import time
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
from scipy.integrate import solve_ivp

from ...rocklaw.backends import NUMERIC, SCALAR
from ..definition.links import CLOSED, OPEN, Link
from ..definition.scene import Impact
from ..drill.chain import AxialChain, link_load_n, torsion_first_order_matrix
from ..drill.indexing import BlowStarts
from ..drill.piecewise import Element, elements, rock_element, undeclared
from ..drill.piston import CAUGHT, CONTACT, PistonJumps, PistonSetup, piston_history
from ..drill.pulse import blow_start_times, impact_force, switch_times
from ..evaluation.results import SimulationResult
from ..evaluation.run_record import OdeSolverRecord
from ..evaluation.stability import SimulationFailed, diverged_index
from .simulation import Scene, Simulation, as_simulation

# Mode switches at one instant beyond this mean a law chatters: report instead of looping.
MAX_SWITCHES_AT_ONE_TIME = 20
EventFunction = Callable[[float, np.ndarray], float]
Modes = tuple[str, ...]  # the mode of every piecewise element


@dataclass(frozen=True)
class _System:
    """Eq. 4 in first-order form (module doc) with its piecewise elements."""

    simulation: Simulation
    linear_states: np.ndarray  # A of (x, v)' = A (x, v) + a
    linear_constant: np.ndarray  # a
    torsion: np.ndarray | None  # T of (phi, omega)' = T (phi, omega, 1)
    pieces: tuple[Element, ...]  # the rock first, then the nonlinear links
    n: int
    bit: int
    impact: int
    masses_kg: np.ndarray
    chain: AxialChain  # the dynamic chain (models.solvers.simulation.Simulation.dynamic_chain)
    rock_states: slice  # where the rock law's states sit in y
    nonlinear_links: tuple[Link, ...]
    rates_by_mode: dict[str, list[tuple[int, np.ndarray, float]]]  # per rock mode: (index in y, row, constant)

    @property
    def state_size(self) -> int:
        return self.rock_states.stop + (2 if self.torsion is not None else 0)

    def rock_force_n(self, y: np.ndarray) -> np.ndarray:
        return self.simulation.rock.force(y[self.bit], y[self.n + self.bit], y[self.rock_states], NUMERIC)

    def rhs(self, t_s: float, y: np.ndarray, pulse_n: _SegmentPulse, modes: Modes) -> np.ndarray:
        """y' of Eq. 4 in ``modes``: (x, v)' = A (x, v, 1) + the pulse on the impact body - F_r on the bit + the
        nonlinear links' loads, the rock states' rates, the torsion line's."""
        n, rock_states = self.n, self.rock_states
        x, v = y[:n], y[n:2 * n]
        dy = np.zeros_like(y)
        dy[:2 * n] = self.linear_states @ y[:2 * n] + self.linear_constant
        acceleration = dy[n:2 * n]
        acceleration[self.impact] += pulse_n(t_s) / self.masses_kg[self.impact]
        # one state: plain floats (the SCALAR backend), as fast as a law evaluates in Python
        rock_force_n = self.simulation.rock.force(y[self.bit], y[n + self.bit], y[rock_states], SCALAR)
        acceleration[self.bit] -= rock_force_n / self.masses_kg[self.bit]
        if self.nonlinear_links:
            acceleration += link_load_n(self.chain, x, v, self.nonlinear_links) / self.masses_kg
        for index, row, constant in self.rates_by_mode[modes[0]]:
            dy[index] = row @ y + constant
        if self.torsion is not None:
            dy[-2:] = self.torsion[:, :2] @ y[-2:] + self.torsion[:, 2]
        return dy

    def transitions(self, modes: Modes) -> list[tuple[EventFunction, int, int, str]]:
        """(event function of (t, y), direction, element index, next mode) of every exit of the current modes."""
        events = []
        for index, (element, mode) in enumerate(zip(self.pieces, modes, strict=True)):
            for switch in element.table[mode].exits:
                row, constant = element.row(switch.surface)
                events.append((_strict(_affine(row, constant), switch.direction), switch.direction, index,
                               switch.next_mode))
        return events


def _affine(row: np.ndarray, constant: float) -> EventFunction:
    nonzero = np.flatnonzero(row)
    weights = row[nonzero]

    def event(t_s: float, y: np.ndarray) -> float:
        return float(weights @ y[nonzero]) + constant
    return event


def _strict(function: EventFunction, direction: int) -> EventFunction:
    """Terminal event that counts an exact zero as not yet crossed.

    SciPy fires an event when g goes from 0 to 0; at a start from rest (all states exactly zero)
    g = x_bit - x_n stays exactly 0 over the first steps and would switch modes endlessly.
    """
    not_crossed = -direction * np.finfo(float).tiny

    def event(t_s: float, y: np.ndarray) -> float:
        value = function(t_s, y)
        return value if value != 0.0 else not_crossed

    event.terminal, event.direction = True, direction
    return event


def _system(simulation: Simulation) -> _System:
    chain = simulation.dynamic_chain
    n = chain.size
    size = 2 * n + len(simulation.rock.state_names)
    torsion = simulation.torsion
    linear = chain.first_order_matrix()
    pieces = elements(chain, simulation.rock, size + (2 if torsion is not None else 0))
    return _System(
        simulation=simulation,
        linear_states=np.ascontiguousarray(linear[:, :-1]),
        linear_constant=linear[:, -1].copy(),
        torsion=None if torsion is None else torsion_first_order_matrix(torsion),
        pieces=pieces,
        n=n,
        bit=chain.bit_body,
        impact=chain.impact_body,
        masses_kg=np.array([b.mass_kg for b in chain.bodies]),
        chain=chain,
        rock_states=slice(2 * n, size),
        nonlinear_links=chain.nonlinear_links() if len(pieces) > 1 else (),
        rates_by_mode=_rock_rates(pieces[0]),
    )


def _rock_rates(rock: Element) -> dict[str, list[tuple[int, np.ndarray, float]]]:
    """Per mode of the rock element, (index in y, row over y, constant) of each of its states' rates:
    dy_i = row . y + constant."""
    return {mode: [(rock.states[state], *rock.row(affine)) for state, affine in rock.table[mode].rates.items()]
            for mode in rock.table}


class _SegmentPulse:
    """F_d on the open interval between two pulse switches, continued to its ends.

    The local time s since the blow's start is clipped into the segment, so that F_d at a segment
    end takes the value of the segment's own side of the switch (matters for the rectangular
    pulse). Between pulses F_d = 0 is a constant, evaluated once.
    """

    def __init__(self, impact: Impact, start_s: float, end_s: float) -> None:
        self.impact = impact
        middle = 0.5 * (start_s + end_s)
        self.blow_start_s = np.floor(middle / impact.period_s) * impact.period_s
        self.low_s = max(start_s - self.blow_start_s, 0.0)
        self.high_s = float(np.nextafter(end_s - self.blow_start_s, -np.inf))
        between = impact.piston is not None or middle - self.blow_start_s >= impact.duration_s
        self.constant_n = impact_force(impact, middle - self.blow_start_s, NUMERIC) if between else None

    def __call__(self, t_s: float) -> float:
        if self.constant_n is not None:
            return self.constant_n
        return impact_force(self.impact, min(max(t_s - self.blow_start_s, self.low_s), self.high_s), SCALAR)

    def samples(self, t_s: np.ndarray) -> np.ndarray:
        local = np.clip(t_s - self.blow_start_s, self.low_s, self.high_s)
        return np.asarray(impact_force(self.impact, local, NUMERIC)) + np.zeros_like(local)


@dataclass
class _Record:
    """Samples of all pieces (restart points not duplicated) and solver counts."""

    time_s: list[np.ndarray]
    states: list[np.ndarray]
    impact_n: list[np.ndarray]
    switches: dict[str, int]
    pieces: int = 0
    solver_steps: int = 0
    rhs_evaluations: int = 0

    def add(self, t: np.ndarray, y: np.ndarray, pulse_n: _SegmentPulse) -> None:
        skip = 1 if self.time_s else 0  # the piece starts where the previous one ended
        self.time_s.append(t[skip:])
        self.states.append(y[:, skip:])
        self.impact_n.append(pulse_n.samples(t[skip:]))


def _refined(steps_s: np.ndarray, interval_s: float) -> np.ndarray:
    """The solver's step times plus equally spaced times inside every step longer than ``interval_s``."""
    h = np.diff(steps_s)
    parts = np.maximum(np.ceil(h / interval_s), 1).astype(int)
    step = np.repeat(np.arange(len(h)), parts)
    j = np.arange(parts.sum()) - np.repeat(np.cumsum(parts) - parts, parts)
    return np.append(steps_s[step] + h[step] * j / parts[step], steps_s[-1])


def _fail(simulation: Simulation, t_s: float, why: str) -> SimulationFailed:
    return SimulationFailed(
        f"scene '{simulation.name}': ODE solver {simulation.settings.method} {why} at t = {t_s:.6g} s; "
        f"try another method (Radau for stiff chains) or a looser relative_tolerance"
    )


class _Piston:
    """The piston's strikes in the ODE, and the bookkeeping of its catches (module doc)."""

    def __init__(self, system: _System, setup: PistonSetup) -> None:
        self.setup, self.n, self.jumps = setup, system.n, PistonJumps(setup)
        self.contact = next(i for i, element in enumerate(system.pieces) if element.name == CONTACT)

    def strike(self, t_s: float, y: np.ndarray, modes: Modes) -> tuple[np.ndarray, Modes]:
        """The strike; the contact closing (closed when the piston is faster than the impact body)."""
        y = y.copy()
        self.jumps.strike(t_s, y[:self.n], y[self.n:2 * self.n])
        closing = y[self.n + self.setup.front] > y[self.n + self.setup.impact_body]
        return y, modes[:self.contact] + (CLOSED if closing else OPEN,) + modes[self.contact + 1:]

    def switched(self, t_s: float, y: np.ndarray, mode: str) -> str:
        """The contact's next mode: caught at once when it opens with the piston moving back already (an
        event function that starts on its crossed side would not fire); a catch noted before its entry."""
        if mode == OPEN and self.setup.mean_velocity_m_per_s(y[self.n:2 * self.n]) < 0.0:
            mode = CAUGHT
        if mode == CAUGHT:
            self.jumps.noted_catch(t_s, y[:self.n], y[self.n:2 * self.n])
        return mode


def _integrate_segment(system: _System, record: _Record, y: np.ndarray, modes: Modes, span: tuple[float, float],
                       pulse_n: _SegmentPulse, piston: _Piston | None = None) -> tuple[np.ndarray, Modes]:
    """Integrate one pulse segment piece by piece across mode switches; (end state, end modes)."""
    settings = system.simulation.settings
    t, end = span
    repeats = 0
    while t < end:
        events = system.transitions(modes)

        def rhs(t_s: float, y_: np.ndarray, modes: Modes = modes) -> np.ndarray:
            return system.rhs(t_s, y_, pulse_n, modes)

        sol = solve_ivp(rhs, (t, end), y, method=settings.method, rtol=settings.relative_tolerance,
                        atol=settings.absolute_tolerance, events=[e[0] for e in events], dense_output=True)
        record.pieces += 1
        record.solver_steps += len(sol.t) - 1
        record.rhs_evaluations += sol.nfev
        if sol.status == -1:
            raise _fail(system.simulation, float(sol.t[-1]), f"failed ({sol.message})")
        samples = _refined(sol.t, settings.sample_interval_s)
        record.add(samples, sol.sol(samples), pulse_n)
        if sol.status == 0:
            return sol.y[:, -1], modes
        fired = next(i for i, te in enumerate(sol.t_events) if len(te))
        t_next, y = float(sol.t_events[fired][0]), sol.y_events[fired][0]
        repeats = repeats + 1 if t_next <= t else 0
        if repeats > MAX_SWITCHES_AT_ONE_TIME:
            raise _fail(system.simulation, t_next, "chattered between modes")
        _, _, index, next_mode = events[fired]
        element = system.pieces[index]
        if piston is not None and index == piston.contact:
            next_mode = piston.switched(t_next, y, next_mode)
        modes = modes[:index] + (next_mode,) + modes[index + 1:]
        into = next_mode if index == 0 else f"{element.name}:{next_mode}"
        record.switches[into] = record.switches.get(into, 0) + 1
        t, y = t_next, element.enter(next_mode, y)
        record.time_s[-1][-1], record.states[-1][:, -1] = t, y  # the switch point, in the new mode
    return y, modes


def unsupported(simulation: Simulation) -> str | None:
    """Why this formulation cannot run ``simulation``: its switching comes from the laws' declared modes, and
    it integrates bodies with mass only (a rod with model: waves has massless faces and delays: models.waves)."""
    waves = [rod.name for rod in simulation.dynamic_chain.waves]
    if waves:
        keys = ", ".join("impact.piston.model" if name == "piston" else f"drill_string.bodies.{name}.model"
                         for name in waves)
        return (f"{keys} is waves: the ode formulation integrates lumped bodies only (a wave rod's faces are "
                "massless and its waves arrive after a delay); use the exact or exudyn formulation, or model: lumped")
    return undeclared(simulation.chain, simulation.rock)


def _start_blow(system: _System, blows: BlowStarts, record: _Record, y: np.ndarray,
                modes: Modes) -> tuple[_System, np.ndarray, Modes]:
    """The blow starting now: its rock law (a new rock element when its rows change), the rock state
    it meets and the rock's mode found again; the last sample is the blow start in its new state."""
    y = y.copy()
    angle = y[-2] if system.torsion is not None else 0.0
    law, y[system.rock_states] = blows(y[system.bit], tuple(y[system.rock_states]), angle)
    if law != system.pieces[0].law:
        rock = rock_element(system.chain, law, system.state_size)
        system = replace(system, pieces=(rock, *system.pieces[1:]), rates_by_mode=_rock_rates(rock))
    if record.time_s:
        record.states[-1][:, -1] = y
    return system, y, (system.pieces[0].initial_mode(y), *modes[1:])

def simulate(run: Scene | Simulation, progress: Callable[[float], None] | None = None) -> SimulationResult:
    """Integrate Eq. 4 from the simulation's start (rest or preloaded; the rock state consistent with
    it) to its end time, with the scene's ODE settings (models.evaluation.solver_settings: ``method``, a SciPy
    ``solve_ivp`` method, ``relative_tolerance``/``absolute_tolerance`` in the state's SI units). Every
    accepted step is stored, and the solver's dense output fills steps longer than
    ``sample_interval_s``, so that the trapezoidal energy account (models.evaluation.energy) balances."""
    simulation = as_simulation(run)
    why = unsupported(simulation)
    if why:
        raise ValueError(f"scene '{simulation.name}': the ODE formulation cannot run it: {why}")
    system = _system(simulation)
    y = np.zeros(system.state_size)
    setup = simulation.piston
    y[:system.n] = simulation.initial_positions_m if setup is None else setup.parked(simulation.initial_positions_m)
    y[system.n:system.n + simulation.chain.size] = simulation.initial_velocities
    y[system.rock_states] = simulation.initial_rock_state
    if system.torsion is not None:
        y[-2] = simulation.initial_torsion_angle_rad
        y[-1] = simulation.initial_torsion_rate_rad_per_s
    modes = tuple(element.initial_mode(y) for element in system.pieces)
    record = _Record([], [], [], {})
    start = time.process_time()
    impact, blows = simulation.impact, simulation.blow_starts()
    blow_starts = set(blow_start_times(impact, simulation.settings.end_time_s)) if blows or setup else set()
    piston = None if setup is None else _Piston(system, setup)
    for span in itertools.pairwise(switch_times(impact, simulation.settings.end_time_s)):
        if span[0] in blow_starts and blows:
            system, y, modes = _start_blow(system, blows, record, y, modes)
        if span[0] in blow_starts and piston:
            y, modes = piston.strike(span[0], y, modes)
            if record.time_s:
                record.states[-1][:, -1] = y
        y, modes = _integrate_segment(system, record, y, modes, span, _SegmentPulse(impact, *span), piston)
        if progress is not None:
            progress(span[1])
    cpu = time.process_time() - start

    time_s = np.concatenate(record.time_s)
    states = np.concatenate(record.states, axis=1).T
    n = system.n
    bad = diverged_index(states[:, :n], states[:, n:2 * n])
    if bad is not None:
        raise _fail(simulation, float(time_s[bad]), "diverged")
    torsion = system.torsion is not None
    settings = simulation.settings
    history = None
    if piston is not None:
        history = piston_history(setup, piston.jumps, time_s, states[:, :n], states[:, n:2 * n],
                                 np.ones(len(time_s), dtype=bool))
        n = simulation.chain.size  # the drill string's bodies
    return SimulationResult(
        simulation=simulation,
        formulation="ode",
        time_s=time_s,
        position_m=states[:, :n],
        velocity_m_per_s=states[:, system.n:system.n + n],
        bottom_m=states[:, system.rock_states][:, simulation.rock.bottom_index],
        rock_force_n=system.rock_force_n(states.T),
        rock_state_m=states[:, system.rock_states],
        impact_force_n=np.concatenate(record.impact_n) if history is None else history.contact_force_n,
        torsion_angle_rad=states[:, -2] if torsion else None,
        torsion_rate_rad_per_s=states[:, -1] if torsion else None,
        cpu_time_s=cpu,
        solver=OdeSolverRecord(
            samples=len(time_s), sample_interval_s=settings.sample_interval_s,
            mode_switches=sum(record.switches.values()), switches_into=dict(record.switches),
            fresh_fractions=tuple(blows.fresh_fractions) if blows else (),
            method=settings.method, relative_tolerance=settings.relative_tolerance,
            absolute_tolerance=settings.absolute_tolerance, solver_steps=record.solver_steps, pieces=record.pieces,
            rhs_evaluations=record.rhs_evaluations),
        piston=history,
    )
