"""The method of characteristics at a stated step h, with the rest of the drill integrated exactly.

Step k covers [t_k, t_k + h]: the waves arriving at every rod end are set from the waves that left
the other end N steps before (models.waves.history), and the system of models.waves.system is
propagated exactly, w(t + s) = expm(A s) w(t), piece by piece: a piece ends at a pulse phase change or
at the first switch of a piecewise element, located to round-off (Brent's method on the exit function
of the exact solution, a crossing and its return within a piece found from the slopes). At the step's
end every port's outgoing wave is stored (its end value and the value that keeps the step's mean).

What is exact and what is not: between two grid times every node, face, body and element follows
the exact solution of the arriving waves as straight lines; the waves are carried without dispersion
or delay error beyond the rounding of each transit time to whole steps (stated: history.transit_errors).
The only approximation is the outgoing wave as a straight line over each step (second order in h where
it is smooth; a front keeps its area).

Blow starts fall on the grid (h divides the blow period): the indexing model's rock state and the
piston's strike are applied there, as in the exact formulation. A rigid or lumped piston is caught by
its contact's mode table; a wave piston when its contact is open and its momentum (in its waves) is
negative at a step's end: at most a step late, its energy kept (models.drill.piston).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..definition.links import CLOSED, OPEN
from ..drill.piston import CAUGHT, CONTACT, PARK_M, PistonJumps
from ..drill.pulse import generator_states, phase_pieces, phase_row
from ..drill.wave_rod import SIGMA, TOP
from ..evaluation.stability import POSITION_LIMIT_M, SimulationFailed
from .fast_path import SWITCH, run_fast
from .history import WaveLines
from .kernels import CATCH
from .levels import key_levels
from .outgoing import Segment, StepWaves, outgoing, readings
from .recording import BlowPeaks, Recorder, Samples, Snapshot
from .statics import initial_outgoing
from .system import Key, Modes, WaveSystem

MAX_SWITCHES_PER_STEP = 64
SWITCH_AT_START = 1e-9  # a switch this soon (a fraction of the step) after a jump is at the jump


@dataclass
class BlowStatistics:
    """Per blow and per port (2 per rod: top, bottom): the largest compression and tension (N, tension as a
    positive number), and the energy through the section int P v dt along +x (into the rock); per blow the
    work the rock took, int F_r v_bit dt."""

    compression_n: list[np.ndarray] = field(default_factory=list)
    tension_n: list[np.ndarray] = field(default_factory=list)
    energy_j: list[np.ndarray] = field(default_factory=list)
    arriving_j: list[np.ndarray] = field(default_factory=list)  # the energy the arriving wave brings, Z int w_in^2
    # per blow and string rod: (stations' positions from its top, largest compression there, its time, largest
    # tension, its time) (Stepper.read_envelopes)
    envelopes: list[dict[str, tuple[np.ndarray, ...]]] = field(default_factory=list)
    # per blow and gauge: (every step's start time, the down-going wave at its start and end, the up-going's)
    gauges: list[dict[str, tuple[np.ndarray, ...]]] = field(default_factory=list)
    rock_work_j: list[float] = field(default_factory=list)

    def open_blow(self, ports: int) -> None:
        self.compression_n.append(np.zeros(ports))
        self.tension_n.append(np.zeros(ports))
        self.energy_j.append(np.zeros(ports))
        self.arriving_j.append(np.zeros(ports))
        self.rock_work_j.append(0.0)

    def arrays(self, ports: int) -> dict[str, np.ndarray]:
        shape = (len(self.energy_j), ports)
        return {"compression_n": np.array(self.compression_n).reshape(shape),
                "tension_n": np.array(self.tension_n).reshape(shape),
                "energy_j": np.array(self.energy_j).reshape(shape),
                "arriving_j": np.array(self.arriving_j).reshape(shape), "rock_work_j": np.array(self.rock_work_j)}


class Stepper(Recorder):
    """One run on the grid of the characteristics (module doc). ``kinematic`` nodes move at their
    velocity over each step (the Exudyn formulation's bodies, set before each step)."""

    def __init__(self, simulation, step_s: float, sample_interval_s: float, kinematic: tuple[int, ...] = (),
                 record_steps: bool = True) -> None:
        self.simulation, self.step_s = simulation, step_s
        chain = self.chain = simulation.dynamic_chain
        self.string_size = simulation.chain.size
        self.setup = simulation.piston
        self.piston_rod = next((r for r, rod in enumerate(chain.waves) if self.setup is not None
                                and rod.top >= self.string_size), None)
        self.system = WaveSystem(chain, simulation.rock, simulation.torsion, simulation.impact, kinematic,
                                 catch_by_row=self.piston_rod is None)
        self.layout = self.system.layout
        end = simulation.settings.end_time_s
        self.steps = max(1, round(end / step_s))
        self.period_steps = round(simulation.impact.period_s / step_s)
        self.lines = WaveLines(chain.waves, step_s, initial_outgoing(simulation, chain), self.period_steps + 1)
        times, phases = phase_pieces(simulation.impact, end)
        self.phase_changes, self.phases = times[:, 0], phases
        self.blows = simulation.blow_starts()
        self.jumps = PistonJumps(self.setup) if self.setup is not None else None
        self.contact = next((i for i, piece in enumerate(self.system.pieces) if piece.name == CONTACT), None)
        if self.piston_rod is not None:  # the strike fills the rod as run: N h long
            rod = chain.waves[self.piston_rod]
            self.jumps.blow_energy_j = 0.5 * rod.impedance_n_s_per_m * self.lines.delays[self.piston_rod] * step_s \
                * self.setup.strike_velocity_m_per_s**2
        self.ports = self.system.ports
        impact = simulation.impact  # the wave scale: the strike velocity, or the pulse over the smallest impedance
        self.wave_scale_m_per_s = self.setup.strike_velocity_m_per_s if self.setup is not None else \
            impact.amplitude_n / min((rod.impedance_n_s_per_m for rod in chain.waves), default=1.0)
        self.port_nodes = np.array([port.node for port in self.ports], dtype=int)
        self.port_impedances = np.array([port.impedance_n_s_per_m for port in self.ports])
        self.port_signs = np.array([SIGMA[port.end] for port in self.ports]) * self.port_impedances
        self.port_down = np.array([1.0 if port.end == TOP else -1.0 for port in self.ports])  # flux along +x
        self.own_ports = np.arange(len(self.ports))  # the Exudyn model closes the others (its bodies' ports)
        self.kernel_constants = None  # the compiled kernel's fixed arguments (models.waves.fast_path.run_constants)
        self.pulse_outside = False  # the Exudyn model integrates the pulse on a body with mass, and counts its work
        self.string_ports = [p for p, port in enumerate(self.ports) if port.node < self.string_size]
        self.rigid_names = [link.name for link in self.system.rigid_links]
        self.sample_every = max(1, round(sample_interval_s / step_s))
        self.w = self._initial_state()
        self.modes = self.system.initial_modes(self.w)
        self.phase_index = 0
        self.samples, self.statistics, self.peaks = Samples(), BlowStatistics(), BlowPeaks()
        self.step_start: Callable[[], Snapshot] | None = None  # the state at the start of the step in progress (a peak's sample)
        weights = np.zeros((2, len(self.ports)))  # the string's and a wave piston's waves' energy: Z h square sums
        for p, port in enumerate(self.ports):
            weights[int(port.rod == self.piston_rod), p] = port.impedance_n_s_per_m * step_s
        self.energy_weights = weights
        self.peak_states = np.zeros((len(self.ports), 2, self.layout.size))
        self.peak_extras = np.zeros((len(self.ports), 2, 5))
        self.peak_sides = np.zeros((len(self.ports), 2), dtype=np.int64)
        self.works = np.zeros(2)
        self.switch_times: list[float] = []
        self.switch_modes: list[Modes] = []
        self.step_index = 0
        self.kinematic = tuple(sorted(kinematic))
        self.record_steps = record_steps  # False: the Exudyn model records at its step starts
        self.caught_at_end = False  # the last step ended with a wave piston's catch
        self._set_inputs(0)  # the waves arriving at the start (a preload's), for the first sample
        # energy into the string's rods, into a wave piston and through the Exudyn bodies' ports since the step's start
        self._step_flux = np.zeros(3)
        self.body_loads = np.zeros((2, len(self.kinematic)))  # (start, end) of the force on each over the step

    # -- state ----------------------------------------------------------------------------------------

    def _initial_state(self) -> np.ndarray:
        layout, simulation = self.layout, self.simulation
        w = np.zeros(layout.size)
        positions = simulation.initial_positions_m
        w[:layout.n] = positions if self.setup is None else self.setup.parked(positions)
        w[layout.rock:layout.rock + layout.rock_states] = simulation.initial_rock_state
        if layout.torsion:
            w[layout.angle] = simulation.initial_torsion_angle_rad
        w[layout.one] = 1.0
        w[layout.one + 1:layout.one + 3] = generator_states(simulation.impact, np.zeros(1))[0]
        return w

    def key(self) -> Key:
        return self.system.key(self.modes, self.phases[self.phase_index])

    def _add_works(self, key: Key, works: np.ndarray, moved: np.ndarray | None) -> None:
        """A piece's works (one per power form, models.waves.levels) and the kinematic bodies' impulse added."""
        self.works += works[:2]
        self.statistics.rock_work_j[-1] += works[2]
        self._step_flux[:len(works) - 3] += works[3:]  # into the rods since the step's start (not in their waves in flight yet)
        if moved is not None:
            self._step_impulse += key.body_forces @ moved

    # -- one step -------------------------------------------------------------------------------------

    def advance(self) -> None:
        """Step ``step_index`` (module doc): in the compiled kernel when nothing happens in it (no blow
        start, pulse phase change or switch), else here."""
        if self._quiet(self.step_index):
            status, _ = run_fast(self, self.step_index + 1)
            if status != SWITCH:
                self._after(status == CATCH)
                return
        self._step()

    def _quiet(self, k: int) -> bool:
        """Whether step k has no blow start and no pulse phase change (the kernel's steps; it returns itself
        before a step into which a wave arrives with a break)."""
        if k % self.period_steps == 0:
            return False
        t0, t1 = k * self.step_s, (k + 1) * self.step_s
        later = self.phase_changes[self.phase_index + 1:self.phase_index + 2]
        return not (len(later) and later[0] <= t1 + 1e-12 * self.step_s and later[0] > t0 - 1e-12 * self.step_s)

    def _after(self, caught: bool) -> None:
        """Once a step is done: the sample at its end when one is due (or a catch there)."""
        self.caught_at_end = caught
        k = self.step_index
        if self.record_steps and (caught or k % self.sample_every == 0 or k == self.steps):
            self._record(k * self.step_s, self.w, self.key(), after=caught, kept=caught)

    def _step(self) -> None:
        """Step ``step_index`` here (module doc): pieces between the switches, the pulse's phase changes and the
        breaks of the arriving waves (models.waves.history), each integrated exactly; the step's outgoing waves
        from its segments (models.waves.outgoing)."""
        k, h, layout = self.step_index, self.step_s, self.layout
        t0 = k * h
        w = self.w
        strike = k % self.period_steps == 0 and self.setup is not None
        if k % self.period_steps == 0:
            self._start_blow(k, t0)
        self._set_inputs(k)
        arrivals = self.lines.arriving_breaks(k)
        t, t1, switches = t0, t0 + h, 0
        ignored: tuple[Key, int] | None = None  # a grazing exit, ignored for the rest of the step (below)
        jumped = strike  # a jump just now whose other side is still to be sampled (the strike's, a front's)
        self._step_impulse = np.zeros(len(self.kinematic))
        segments: list[Segment] = []
        begin = (t0, w.copy(), self.key(), -1)
        self.step_start = self.snapshot_if_wanted(t0, w, self.key(), after=True)  # a peak there: after the step's jumps
        while t < t1 - 1e-12 * h:
            later = np.flatnonzero(self.phase_changes > t + 1e-12 * h)
            phase = self.phase_changes[later[0]] if len(later) else np.inf
            arrival = t0 + arrivals[0][0] * h if arrivals else np.inf
            boundary = min(t1, phase, arrival)
            if boundary >= t1 - 1e-9 * h:  # a phase change a round-off before the step's end: at its end
                boundary = t1
            key = self.key()
            span = boundary - t
            w1, works, moved = key_levels(self, key).advance(w, span)  # the whole piece, kept where nothing switches
            hit = self._first_switch(key, w, w1, span, ignored[1] if ignored and ignored[0] is key else None)
            at_jump = hit is not None and hit[0] <= SWITCH_AT_START * h and (jumped or t == t0)
            if jumped and not at_jump:  # the jump's other side (a switch at the jump: the state after it)
                begin = (*begin[:3], self._record(t, w, key, after=True))
            if hit is None:
                self._add_works(key, works, moved)
                w, t = w1, boundary
                jumped = False
                if boundary >= t1 - 1e-9 * h:  # the step's end (a phase change there: the next step's start)
                    if phase <= boundary + 1e-9 * h:
                        self.phase_index = int(later[0])
                        self._start_phase(w, t)
                    break
                segments.append(self._segment(begin, t, w, key, self._record(t, w, key)))  # a front: both sides
                if phase <= boundary + 1e-12 * h:
                    self.phase_index = int(later[0])
                    self._start_phase(w, t)
                while arrivals and t0 + arrivals[0][0] * h <= boundary + 1e-12 * h:
                    _, port, value, slope = arrivals.pop(0)
                    w[self.ports[port].input], w[self.ports[port].input + 1] = value, slope / h
                begin, jumped = (t, w.copy(), self.key(), -1), True
                continue
            s, exit_ = hit
            if self._grazing(t + s, key, exit_):  # back into the modes just left, at the same instant
                ignored = (key, exit_)
                continue
            w_s, works, moved = key_levels(self, key).advance(w, s)
            self._add_works(key, works, moved)
            t += s
            before = -1 if at_jump else self._record(t, w_s, key)  # a switch at a jump is at the jump: no sample between
            segments.append(self._segment(begin, t, w_s, key, before))
            w = self._switch(t, w_s, key, exit_)
            begin, jumped = (t, w.copy(), self.key(), self._record(t, w, self.key(), after=True)), False
            switches += 1
            if switches > MAX_SWITCHES_PER_STEP:
                raise SimulationFailed(f"scene '{self.simulation.name}': more than {MAX_SWITCHES_PER_STEP} switches "
                                       f"within one wave step at t = {t:.6g} s (a chattering contact)")
        if t1 - begin[0] > 1e-12 * h or not segments:
            segments.append(self._segment(begin, t1, w, key))
        self.w = w
        if not np.isfinite(w).all() or np.abs(w[:layout.n]).max() > POSITION_LIMIT_M:
            raise SimulationFailed(f"scene '{self.simulation.name}': the wave solution diverged at t = {t1:.6g} s")
        caught = self._close_step(k, segments, key)
        if self.kinematic:  # the loads on the Exudyn bodies over the step: its end value and its mean
            end = key.body_forces @ w
            self.body_loads = np.array([2.0 * self._step_impulse / h - end, end])
        self.step_index += 1
        self._after(caught)

    def _segment(self, begin: tuple[float, np.ndarray, Key, int], t: float, w: np.ndarray, key: Key,
                 sample: int = -1) -> Segment:
        """The segment from ``begin`` (time, state, key, its sample or -1) to the state ``w`` at ``t`` (its sample
        ``sample``) (models.waves.outgoing)."""
        t_begin, w_begin, key_begin, first = begin
        t0, h, nodes, inputs = self.step_index * self.step_s, self.step_s, self.port_nodes, self.layout.inputs
        if "accelerations" not in key.cache:  # the ports' nodes' accelerations: d/dt (V w) = V A w
            key.cache["accelerations"] = key.velocity[nodes] @ key.matrix
        if "accelerations" not in key_begin.cache:
            key_begin.cache["accelerations"] = key_begin.velocity[nodes] @ key_begin.matrix
        return Segment((t_begin - t0) / h, (t - t0) / h, w_begin[nodes], w[nodes], key_begin.velocity[nodes] @ w_begin,
                       key.velocity[nodes] @ w, w_begin[inputs::2].copy(), w[inputs::2].copy(),
                       key_begin.cache["accelerations"] @ w_begin - w_begin[inputs + 1::2],
                       key.cache["accelerations"] @ w - w[inputs + 1::2], True, (first, sample))

    def _start_phase(self, w: np.ndarray, t: float) -> None:
        """The pulse generator's states (u1, u2) at the start of the phase piece beginning at ``t``."""
        period = self.simulation.impact.period_s
        local = t - np.floor(t / period + 1e-9) * period
        one = self.layout.one
        w[one + 1:one + 3] = generator_states(self.simulation.impact, np.array([max(local, 0.0)]))[0]

    def _set_inputs(self, k: int) -> None:
        """The arriving waves of step k as (a, b) of every port (the first piece of a wave with breaks)."""
        if not self.ports:
            return
        value, slope = self.lines.first_pieces(k)
        inputs = self.layout.inputs
        self.w[inputs::2], self.w[inputs + 1::2] = value, slope / self.step_s

    def run(self) -> None:
        """Every step, runs of quiet steps in the kernel up to the next blow start, phase change or sample; the
        last blow's peaks recorded at the end."""
        self._record(0.0, self.w, self.key(), kept=False)
        while self.step_index < self.steps:
            k = self.step_index
            if not self._quiet(k):
                self.advance()
                continue
            stop = min(self.steps, (k // self.period_steps + 1) * self.period_steps,
                       (k // self.sample_every + 1) * self.sample_every, self._phase_step(k))
            status, _ = run_fast(self, stop)
            if status == SWITCH:
                self._step()
            elif self.step_index == stop or status == CATCH:
                self._after(status == CATCH)
        self.record_peaks()
        self.read_envelopes(self.step_index)

    def _phase_step(self, k: int) -> int:
        """The first step from k on that holds the next pulse phase change (the kernel stops before it)."""
        later = self.phase_changes[self.phase_index + 1:self.phase_index + 2]
        if not len(later):
            return self.steps
        return max(k + 1, int(np.floor(later[0] / self.step_s - 1e-9)))

    def _close_step(self, k: int, segments: list[Segment], key: Key) -> bool:
        """The outgoing waves of step k from its segments (``key`` that of its last piece), the blow's section
        figures, a wave piston's catch (True then)."""
        self._step_flux[:] = 0.0  # in the waves in flight from now on
        if self.ports:
            self.last_segments = segments
            self.last_inputs = (segments[0].a0, segments[-1].a1)
            self.close_ports(k, self.own_ports, segments, provisional=True)
        if self.piston_rod is not None and (k + 1) % self.period_steps and self._wave_piston_done(key):
            # (a catch at a blow start: the strike there resets the piston, its energy counted as rebound)
            self.catch_wave_piston(k + 1)
            return True
        return False

    def close_ports(self, k: int, ports: np.ndarray, segments: list[Segment], again: bool = False,
                    provisional: bool = False, ends: tuple[Snapshot | Callable[[], Snapshot] | None, ...] | None = None) -> None:
        """Store the outgoing waves over step k from its segments (models.waves.outgoing) and add the step to
        the blow's section figures of ``ports``; ``provisional``: store every port (the others are stored
        ``again`` later, from the Exudyn bodies)."""
        stored = np.arange(len(self.ports)) if provisional else ports
        waves = outgoing(segments, self.step_s, stored, self.wave_scale_m_per_s)
        size = len(self.ports)
        left, right, start = np.zeros(size), np.zeros(size), np.zeros(size)
        left[stored], right[stored], start[stored] = waves.left, waves.right, waves.start
        self.lines.store(k, left, right, start, stored, again)
        for j, rows in waves.pieces.items():
            self.lines.store_pieces(k, int(stored[j]), rows, again=True)
        if not provisional:
            read = readings(segments, waves, self.step_s, ports, self.port_signs, self.port_impedances, self.port_down)
        else:  # every port stored (``stored`` is every index): the readings of ``ports``
            position = {int(port): i for i, port in enumerate(ports)} if waves.pieces else {}
            mine = StepWaves(waves.left[ports], waves.right[ports], waves.start[ports],
                             {position[j]: rows for j, rows in waves.pieces.items() if j in position})
            read = readings(segments, mine, self.step_s, ports, self.port_signs, self.port_impedances, self.port_down)
        stats = self.statistics
        raised = (read.compression_n > stats.compression_n[-1][ports], read.tension_n > stats.tension_n[-1][ports])
        if np.logical_or(*raised).any():
            if ends is None:  # the step just done by the stepper: its start, and its end now
                ends = (self.step_start, self._snapshot((k + 1) * self.step_s, self.w, self.key(), after=False))
            self.offer_peaks(read, raised, ports, ends)
        stats.compression_n[-1][ports] = np.maximum(stats.compression_n[-1][ports], read.compression_n)
        stats.tension_n[-1][ports] = np.maximum(stats.tension_n[-1][ports], read.tension_n)
        stats.energy_j[-1][ports] += read.energy_j
        stats.arriving_j[-1][ports] += read.arriving_j

    def _wave_piston_done(self, key: Key) -> bool:
        """A wave piston is caught when its contact is open and its momentum not forward, or when it rests
        against the struck face without pushing (its momentum and the contact force both nil to 1e-9)."""
        mode, setup = self.modes[self.contact], self.setup
        momentum = self.lines.momentum_n_s(self.piston_rod)
        if mode == OPEN:
            return momentum <= 0.0
        if mode != CLOSED:
            return False
        rod = self.chain.waves[self.piston_rod]
        scale = setup.strike_velocity_m_per_s
        return abs(momentum) <= 1e-9 * setup.momentum_n_s and \
            abs(self.impact_force(key, self.w)) <= 1e-9 * rod.impedance_n_s_per_m * scale

    def impact_force(self, key: Key, w: np.ndarray) -> float:
        """F_d on the impact body along +x: the pulse, or the piston's contact (-F of the link)."""
        return float(self.impact_row(key) @ w)

    def impact_row(self, key: Key) -> np.ndarray:
        if self.contact is None:
            row = np.zeros(self.layout.size)
            row[self.layout.one:self.layout.one + 3] = phase_row(self.simulation.impact, key.phase)
            return row
        row = key.element_forces[self.contact]
        return -(key.constraints[CONTACT] if row is None else row)

    # -- switches -------------------------------------------------------------------------------------

    def _grazing(self, t: float, key: Key, exit_: int) -> bool:
        """Whether the exit at ``t`` would return into the modes the last switch left at the same instant: a
        contact at rest without force, its gap and its force both nil, where each mode's exit is crossed by
        round-off and both modes give the same motion (a rod piston of the struck rod's impedance resting on a
        fed face switched open and closed at one instant without end). The exit is then ignored for the rest of
        the step: the contact stays as it is, and the next step looks again."""
        if len(self.switch_times) < 2 or t - self.switch_times[-1] > SWITCH_AT_START * self.step_s:
            return False
        return key.exits[exit_][2] == self.switch_modes[-2]

    def _first_switch(self, key: Key, w0: np.ndarray, w1: np.ndarray, span_s: float,
                      ignored: int | None = None) -> tuple[float, int] | None:
        """(time into the piece, exit) of the first switch in the piece, None without one: an exit function
        on its crossed side at the piece's end, or one whose slopes show a maximum inside, located on the
        key's levels (models.waves.levels); the exit ``ignored`` left out."""
        if "exit_rows" not in key.cache:
            rows = np.array([direction * row for row, direction, *_ in key.exits]).reshape(len(key.exits), len(w0))
            key.cache["exit_rows"], key.cache["exit_slopes"] = rows, rows @ key.matrix
        rows, slopes = key.cache["exit_rows"], key.cache["exit_slopes"]
        start, end = rows @ w0, rows @ w1
        returning = (start < 0.0) & (end <= 0.0) & (slopes @ w0 > 0.0) & (slopes @ w1 < 0.0)
        candidates = (end > 0.0) | returning
        if ignored is not None:
            candidates[ignored] = False
        if not candidates.any():
            return None
        return key_levels(self, key).first_switch(rows, slopes, w0, span_s, candidates)

    def _switch(self, t: float, w: np.ndarray, key: Key, exit_: int) -> np.ndarray:
        """Enter the exit's modes: its entry resets (the borehole bottom never decreases)."""
        _, _, following, resets, element = key.exits[exit_]
        if self.contact is not None and element == self.contact and following[self.contact] == CAUGHT \
                and self.jumps is not None:  # the piston's energy before the reset
            self.jumps.noted_catch(t, *self._piston_state(key, w))
        w = w.copy()
        monotone = self.system.pieces[0].monotone
        values = {target: float(row @ w) for target, row in resets}
        for target, value in values.items():
            w[target] = max(w[target], value) if target == monotone else value
        self.modes = following
        self.switch_times.append(t)
        self.switch_modes.append(following)
        return w

    def _piston_state(self, key: Key, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return w[:self.layout.n], key.velocity @ w

    # -- blows ----------------------------------------------------------------------------------------

    def _start_blow(self, k: int, t: float) -> None:
        """The rock state the blow meets (indexing) and the piston's strike; the last blow's peaks recorded and its
        stresses along the rods read."""
        self.record_peaks()
        self.read_envelopes(k)
        self.statistics.open_blow(len(self.ports))
        layout, w = self.layout, self.w
        if self.blows:
            states = slice(layout.rock, layout.rock + layout.rock_states)
            angle = w[layout.angle] if layout.torsion else 0.0
            _, w[states] = self.blows(w[self.chain.bit_body], tuple(w[states]), angle)
            self.modes = (self.system.pieces[0].initial_mode(self._z(w)), *self.modes[1:])
        if self.setup is None:
            return
        setup, velocity_index = self.setup, layout.velocity
        if self.piston_rod is None:
            velocities = self.key().velocity @ w
            self.jumps.strike(t, w[:layout.n], velocities)
            for node in range(setup.first, setup.front + 1):
                w[node] = w[setup.impact_body]
                if node in velocity_index:
                    w[velocity_index[node]] = setup.strike_velocity_m_per_s
        else:
            rod = self.chain.waves[self.piston_rod]
            self.jumps.note(t, "strike", self.lines.energy_j(self.piston_rod),
                            self.lines.momentum_n_s(self.piston_rod) / rod.mass_kg)
            w[rod.top] = w[rod.bottom] = w[setup.impact_body]
            self.lines.fill(self.piston_rod, k, 0.5 * setup.strike_velocity_m_per_s)
        self.modes = self.modes[:self.contact] + (CLOSED,) + self.modes[self.contact + 1:]

    def catch_wave_piston(self, k: int) -> None:
        rod = self.chain.waves[self.piston_rod]
        t = k * self.step_s
        self.jumps.note(t, "catch", self.lines.energy_j(self.piston_rod),
                        self.lines.momentum_n_s(self.piston_rod) / rod.mass_kg)
        self.lines.fill(self.piston_rod, k, 0.0)
        self.w[rod.top] = self.w[rod.bottom] = self.w[self.setup.impact_body] - PARK_M
        self.modes = self.modes[:self.contact] + (CAUGHT,) + self.modes[self.contact + 1:]
        self.switch_times.append(t)
        self.switch_modes.append(self.modes)

    def _z(self, w: np.ndarray) -> np.ndarray:
        return np.concatenate([w, self.key().velocity @ w])

    # -- records --------------------------------------------------------------------------------------
