"""The paper's Eq. 4 as a plain ODE with event-located rock-law switches (no Exudyn).

State y = [x (n bodies), v (n bodies), rock law states (, phi, omega)] of
:func:`models.chain.axial_chain` and the scene's rock law as built (``Scene.rock_law``, a
:class:`rocklaw.base.RockLaw`):

    M x'' + C x' + K x = F_feed + F_d(t) e_shank - F_rock e_bit          (Eq. 4, axial lines)
                         + sum over nonlinear links of F_link (e_a - e_b)   (couplings, models.links)
    state' = law.state_rate(mode, x_bit')                   (Jenkins: Eq. 2, x_n' = x_bit' while crushing)
    J phi'' + c_x phi' + k_x phi = M_x - M_c             (Eq. 4, torsion line, if its effect is on)

F_rock is the law's ``force`` at (x_bit, x_bit', state) (Jenkins: Eq. 1 at d = x_bit - x_n).
The law is piecewise; the integration never steps over a branch change. Each piece runs in one
rock mode of the law's mode table (rocklaw.jenkins, rocklaw.bilinear) and stops at the first
zero crossing of one of the mode's ``transitions``, then restarts in the next mode from the
law's ``enter`` state. The piston pulse's on/off times (:func:`models.pulse.pulse_switch_times`)
are breakpoints: the run is integrated segment by segment between them, and the pulse is
evaluated on the segment's own side of each switch.
"""

from __future__ import annotations

import itertools
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from rpdrill.models.chain import (
    AxialChain,
    axial_chain,
    initial_positions_m,
    initial_torsion_angle_rad,
    link_load_n,
)
from rpdrill.models.links import Link
from rpdrill.models.pulse import impact_force, pulse_switch_times
from rpdrill.models.results import SimulationResult
from rpdrill.models.scene import Impact, Scene
from rpdrill.models.stability import SimulationFailed, diverged_index
from rpdrill.rocklaw.backends import NUMERIC
from rpdrill.rocklaw.base import EventFunction as RockEvent
from rpdrill.rocklaw.base import RockLaw
from scipy.integrate import solve_ivp

ODE_METHODS = ("DOP853", "Radau", "LSODA")
# Mode switches at one instant beyond this mean the law chatters: report instead of looping.
MAX_SWITCHES_AT_ONE_TIME = 20
EventFunction = Callable[[float, np.ndarray], float]


@dataclass(frozen=True)
class _System:
    """Eq. 4 in first-order form, pre-multiplied by M^-1; ``n`` axial bodies, state layout in the module doc."""

    scene: Scene
    chain: AxialChain
    rock: RockLaw
    stiffness_per_mass: np.ndarray  # M^-1 K [1/s^2]
    damping_per_mass: np.ndarray  # M^-1 C [1/s]
    feed_per_mass: np.ndarray  # M^-1 F_feed [m/s^2]
    torsion: tuple[float, float, float] | None  # ((M_x - M_c)/J, k_x/J, c_x/J)
    n: int  # axial bodies; the state is [x (n), v (n), rock states (, phi, omega)]
    bit: int
    impact: int
    bit_mass_kg: float
    impact_mass_kg: float
    inverse_masses: np.ndarray  # 1 / m of every body [1/kg]
    nonlinear_links: tuple[Link, ...]  # not in K and C: their forces are evaluated in the rhs

    @property
    def rock_states(self) -> slice:
        """Where the rock law's states sit in y."""
        return slice(2 * self.n, 2 * self.n + len(self.rock.state_names))

    @property
    def kink_event_count(self) -> int:
        """Kink events at the end of every :meth:`transitions` list (two per kink)."""
        return 2 * sum(len(link.kinks()) for link in self.nonlinear_links)

    @property
    def state_size(self) -> int:
        return self.rock_states.stop + (2 if self.torsion else 0)

    def bit_position(self, y: np.ndarray) -> np.ndarray:
        return y[self.bit]

    def bit_velocity(self, y: np.ndarray) -> np.ndarray:
        return y[self.n + self.bit]

    def rock_force_n(self, y: np.ndarray) -> np.ndarray:
        return self.rock.force(self.bit_position(y), self.bit_velocity(y), y[self.rock_states], NUMERIC)

    def rhs(self, t_s: float, y: np.ndarray, pulse_n: _SegmentPulse, mode: str) -> np.ndarray:
        n = self.n
        x, v = y[:n], y[n:2 * n]
        dy = np.empty_like(y)
        dy[:n] = v
        acceleration = self.feed_per_mass - self.stiffness_per_mass @ x - self.damping_per_mass @ v
        acceleration[self.impact] += pulse_n(t_s) / self.impact_mass_kg
        acceleration[self.bit] -= self.rock_force_n(y) / self.bit_mass_kg
        if self.nonlinear_links:
            acceleration += link_load_n(self.chain, x, v, self.nonlinear_links) * self.inverse_masses
        dy[n:2 * n] = acceleration
        dy[self.rock_states] = self.rock.state_rate(mode, v[self.bit])
        if self.torsion:
            torque, stiffness, damping = self.torsion
            dy[-2] = y[-1]
            dy[-1] = torque - stiffness * y[-2] - damping * y[-1]
        return dy

    def transitions(self, mode: str) -> list[tuple[EventFunction, int, str]]:
        """(event function of (t, y), crossing direction, next mode) leaving ``mode`` (the law's table),
        and the kinks of the nonlinear links in both directions (the piece ends, the mode stays)."""
        rock = [(_strict(self._on_state(function), direction), direction, following)
                for function, direction, following in self.rock.transitions(mode)]
        kinks = [(_strict(_on_stretch(link, kink), direction), direction, mode)
                 for link in self.nonlinear_links for kink in link.kinks() for direction in (1, -1)]
        return rock + kinks

    def _on_state(self, function: RockEvent) -> EventFunction:
        def event(t_s: float, y: np.ndarray) -> float:
            return function(self.bit_position(y), self.bit_velocity(y), y[self.rock_states])
        return event

    def initial_mode(self, y: np.ndarray) -> str:
        return self.rock.initial_mode(self.bit_position(y), self.bit_velocity(y), y[self.rock_states])

    def enter(self, mode: str, y: np.ndarray) -> np.ndarray:
        """State at the start of a piece in ``mode``: the law's ``enter`` (Jenkins: crushing starts from
        the return map of Eq. 2, removing the event location's round-off in d)."""
        y = y.copy()
        y[self.rock_states] = self.rock.enter(mode, float(self.bit_position(y)), tuple(y[self.rock_states]))
        return y


def _on_stretch(link: Link, kink: Callable[[float], float]) -> EventFunction:
    def event(t_s: float, y: np.ndarray) -> float:
        return kink(link.stretch(y))
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


def _system(scene: Scene) -> _System:
    chain = axial_chain(scene)
    inverse_mass = np.linalg.inv(chain.mass_matrix())
    tor = scene.torsion
    torsion = None
    if scene.effects.torsion:
        torsion = ((tor.drive_torque_n_m - tor.resisting_torque_n_m) / tor.inertia_kg_m2,
                   tor.stiffness_n_m_per_rad / tor.inertia_kg_m2, tor.damping_n_m_s_per_rad / tor.inertia_kg_m2)
    return _System(
        scene=scene,
        chain=chain,
        rock=scene.rock_law(),
        stiffness_per_mass=inverse_mass @ chain.stiffness_matrix(linear_only=True),
        damping_per_mass=inverse_mass @ chain.damping_matrix(linear_only=True),
        feed_per_mass=inverse_mass @ chain.constant_forces(),
        torsion=torsion,
        n=chain.size,
        bit=chain.bit_body,
        impact=chain.impact_body,
        bit_mass_kg=chain.bodies[chain.bit_body].mass_kg,
        impact_mass_kg=chain.bodies[chain.impact_body].mass_kg,
        inverse_masses=np.diag(inverse_mass).copy(),
        nonlinear_links=chain.nonlinear_links(),
    )


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
        between = middle - self.blow_start_s >= impact.duration_s
        self.constant_n = impact_force(impact, middle - self.blow_start_s, NUMERIC) if between else None

    def __call__(self, t_s: float) -> float:
        if self.constant_n is not None:
            return self.constant_n
        return impact_force(self.impact, min(max(t_s - self.blow_start_s, self.low_s), self.high_s), NUMERIC)

    def samples(self, t_s: np.ndarray) -> np.ndarray:
        local = np.clip(t_s - self.blow_start_s, self.low_s, self.high_s)
        return np.asarray(impact_force(self.impact, local, NUMERIC)) + np.zeros_like(local)


def _breakpoints(scene: Scene) -> np.ndarray:
    end = scene.solver.end_time_s
    times = np.unique([0.0, *pulse_switch_times(scene.impact, end), end])
    return times[(times >= 0.0) & (times <= end)]


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


def _fail(scene: Scene, method: str, t_s: float, why: str) -> SimulationFailed:
    return SimulationFailed(
        f"scene '{scene.name}': ODE solver {method} {why} at t = {t_s:.6g} s; "
        f"try another method (Radau for stiff chains) or a looser rtol"
    )


def _integrate_segment(system: _System, record: _Record, y: np.ndarray, mode: str, span: tuple[float, float],
                       pulse_n: _SegmentPulse, method: str, rtol: float, atol: float,
                       sample_interval_s: float) -> tuple[np.ndarray, str]:
    """Integrate one pulse segment piece by piece across rock-mode switches; (end state, end mode)."""
    t, end = span
    repeats, skip = 0, None
    while t < end:
        events = system.transitions(mode)
        # a link kink that just fired starts the next piece on its old side by round-off: leave it out
        # once (it can only fire again after its opposite crossing, which ends that piece)
        active = [i for i in range(len(events)) if i != skip]
        functions = [events[i][0] for i in active]

        def rhs(t_s: float, y_: np.ndarray, mode: str = mode) -> np.ndarray:
            return system.rhs(t_s, y_, pulse_n, mode)

        sol = solve_ivp(rhs, (t, end), y, method=method, rtol=rtol, atol=atol, events=functions,
                        dense_output=True)
        record.pieces += 1
        record.solver_steps += len(sol.t) - 1
        record.rhs_evaluations += sol.nfev
        if sol.status == -1:
            raise _fail(system.scene, method, float(sol.t[-1]), f"failed ({sol.message})")
        samples = _refined(sol.t, sample_interval_s)
        record.add(samples, sol.sol(samples), pulse_n)
        if sol.status == 0:
            return sol.y[:, -1], mode
        fired = next(i for i, te in enumerate(sol.t_events) if len(te))
        t_next, y = float(sol.t_events[fired][0]), sol.y_events[fired][0]
        repeats = repeats + 1 if t_next <= t else 0
        if repeats > MAX_SWITCHES_AT_ONE_TIME:
            raise _fail(system.scene, method, t_next, "chattered between rock modes")
        fired = active[fired]
        kink = fired >= len(events) - system.kink_event_count
        t, mode, skip = t_next, events[fired][2], fired if kink else None
        into = "link_kink" if kink else mode
        record.switches[into] = record.switches.get(into, 0) + 1
        y = y if kink else system.enter(mode, y)
        record.time_s[-1][-1], record.states[-1][:, -1] = t, y  # the switch point, in the new mode
    return y, mode


def simulate_ode(scene: Scene, method: str = "DOP853", rtol: float = 1e-10, atol: float = 1e-13,
                 sample_interval_s: float = 2e-6) -> SimulationResult:
    """Integrate Eq. 4 of ``scene`` from its start (rest or preloaded; the rock state consistent
    with it, return_map(x_bit(0), initial_state())) to ``scene.solver.end_time_s``.

    ``method`` is a SciPy ``solve_ivp`` method (DOP853, Radau or LSODA); ``rtol``/``atol`` its
    tolerances (atol in the state's SI units: m, m/s, rad, rad/s). Every accepted step is stored,
    and the solver's dense output fills steps longer than ``sample_interval_s``, so that the
    trapezoidal energy account (models.energy) of the stored samples balances.
    """
    if method not in ODE_METHODS:
        raise ValueError(f"method {method!r} not one of {', '.join(ODE_METHODS)}")
    system = _system(scene)
    y = np.zeros(system.state_size)
    y[:system.n] = initial_positions_m(scene)
    y[system.rock_states] = system.rock.return_map(float(y[system.bit]), system.rock.initial_state())
    if system.torsion:
        y[-2] = initial_torsion_angle_rad(scene)
    mode = system.initial_mode(y)
    record = _Record([], [], [], {})
    breakpoints = _breakpoints(scene)
    start = time.process_time()
    for span in itertools.pairwise(breakpoints):
        y, mode = _integrate_segment(system, record, y, mode, span, _SegmentPulse(scene.impact, *span),
                                     method, rtol, atol, sample_interval_s)
    cpu = time.process_time() - start

    time_s = np.concatenate(record.time_s)
    states = np.concatenate(record.states, axis=1).T
    n = system.n
    bad = diverged_index(states[:, :n], states[:, n:2 * n])
    if bad is not None:
        raise _fail(scene, method, float(time_s[bad]), "diverged")
    torsion = system.torsion is not None
    return SimulationResult(
        scene=scene,
        chain=system.chain,
        formulation="ode",
        time_s=time_s,
        position_m=states[:, :n],
        velocity_m_per_s=states[:, n:2 * n],
        bottom_m=states[:, system.rock_states][:, system.rock.bottom_index],
        rock_force_n=system.rock_force_n(states.T),
        rock_state_m=states[:, system.rock_states],
        impact_force_n=np.concatenate(record.impact_n),
        torsion_angle_rad=states[:, -2] if torsion else None,
        torsion_rate_rad_per_s=states[:, -1] if torsion else None,
        cpu_time_s=cpu,
        info={
            "solver_success": True,
            "method": method,
            "rtol": rtol,
            "atol": atol,
            "solver_steps": record.solver_steps,
            "samples": len(time_s),
            "sample_interval_s": sample_interval_s,
            "pieces": record.pieces,
            "rhs_evaluations": record.rhs_evaluations,
            "mode_switches": sum(record.switches.values()),
            "switches_into": dict(record.switches),
        },
    )
