"""Exact event-driven solution of the piecewise-linear model (paper Eq. 1, 2, 4), no Exudyn.

Between two switches the model is linear and autonomous in the augmented state
w = (x (n bodies), v (n bodies), x_n, [phi, phi'], 1, u1, u2) (phi, phi' with the torsion effect):

    w' = A_(mode, phase) w

The constant 1 carries the feed forces, F_th and the net torque; u1, u2 generate the piston pulse
(s = time since the blow's start, tau = pulse duration, I = amplitude):

=============  ================================  ===============================
pulse shape    generator                          F_d
=============  ================================  ===============================
half_sine      u1 = sin(pi s/tau), u2 = cos(..)   I u1
rectangular    (none)                             I 1
triangular     u1 = s (u1' = 1)                   (2I/tau) u1, then 2I - (2I/tau) u1
=============  ================================  ===============================

and F_d = 0 between pulses (phase ``off``); the triangular pulse has a ``rising`` and a
``falling`` phase. The axial rows are Eq. 4, M x'' + C x' + K x = F_feed + F_d e_shank - F_r e_bit,
with the rock force F_r linear in w in each rock mode (d = x_bit - x_n, v = x_bit'):

=========  ====================================  ===========================================
mode       F_r, x_n'                             left when (direction) -> next mode
=========  ====================================  ===========================================
free       0 (``always``: c_n v), 0              d rises through 0 -> contact
contact    k_n d + c_n v, 0                      d falls through 0 -> free;
                                                 k_n d - F_th rises through 0 -> crushing;
                                                 k_n d + c_n v falls through 0 -> clipped
                                                 (``contact`` damping with c_n > 0 only:
                                                 F_r = max(k_n d + c_n v, 0))
clipped    0, 0                                  k_n d + c_n v rises through 0 -> contact;
                                                 d falls through 0 -> free
crushing   F_th + c_n v, v                       v falls through 0 -> contact
                                                 (no crushing mode for an elastic rock, F_th = inf)
=========  ====================================  ===========================================

In crushing x_n' = x_bit', so k_n (x_bit - x_n) = F_th is kept exactly; on entering crushing x_n is
set by the law's return map max(x_n, x_bit - F_th / k_n), removing the root's round-off.

Propagation. A global sub-grid of step h (an integer fraction of the output interval, with
||A_bal|| h <= 1 for the balanced matrices of all modes, so h <= 1/(2 pi) of the shortest period)
carries the solution, w(t_j + b h) = expm(A b h) w(t_j), in batches of J = A B sub-grid points
from one state s0: anchors expm(A a B h) s0 (a < A), then every point a B + b from its anchor
(b < B). SciPy computes expm(A h) once per (mode, phase) (on the balanced matrix); its powers, the
readout rows R = (I, F_r row, F_d row, exit rows) and the Taylor matrices A^k / k! are cached, and
a batch is two matrix products. A piece shorter than h (to the first grid point after a switch, to
a pulse switch, to a located switch) uses the Taylor series sum_k (A s)^k / k! w truncated where its
remainder is below 1e-20 of the state (s <= h): the exact solution to round-off, without an expm
per switch. Each exit function g = c . w comes with every point; the first interval where g goes
from its side to the crossed side brackets the switch, which Brent's method (as
``scipy.optimize.brentq``) locates on the Taylor polynomial g(s) of the exact solution. The event
loop runs compiled (models.exact_kernels); the operators of a (mode, phase) are built when the run
first reaches it.

Zero-length modes: a mode lasts at least ``min_switch_interval_s``. Its start is taken as not
crossed for every exit function; if an exit function is on its crossed side already at
t_start + min_switch_interval_s, the switch is placed there. More than ``max_switches_per_blow``
rock switches per blow on average raise :class:`SimulationFailed`, and so does a diverged state
(models.stability's criterion, checked at every switch, pulse switch and batch end; the message
names the first diverged sample).

Torsion (decoupled, with the torsion effect): J phi'' + c_x phi' + k_x phi = M_x - M_c, two more
rows of A, propagated with the axial state.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from rpdrill.models.chain import AxialChain, axial_chain, initial_positions_m, initial_torsion_angle_rad
from rpdrill.models.exact_kernels import DIVERGED, MISSING_KEY, TOO_MANY_SWITCHES, assemble, run_events
from rpdrill.models.exact_scope import exact_unsupported
from rpdrill.models.results import SimulationResult
from rpdrill.models.scene import Impact, Scene, Torsion
from rpdrill.models.stability import POSITION_LIMIT_M, SimulationFailed, diverged_index
from rpdrill.rocklaw.jenkins import JenkinsRock
from scipy.linalg import expm
from scipy.linalg.lapack import dgebal

FREE, CONTACT, CLIPPED, CRUSHING = MODES = "free", "contact", "clipped", "crushing"
OFF, ON, RISING, FALLING = PHASES = "off", "on", "rising", "falling"
# Sample interval when energies are asked for: the trapezoidal energy integrals then close the
# balance to ~1e-4 of the impact work (1e-4 s samples: ~1e-2).
ENERGY_SAMPLE_S = 1e-5
ANCHORS, PER_ANCHOR = 16, 16  # A, B: a batch is J = A B sub-grid points from one state (module doc)
MAX_EXITS = 3
TAYLOR_REMAINDER = 1e-20  # relative truncation of the Taylor series on pieces shorter than h
Key = tuple[str, str]  # (rock mode, pulse phase)


@dataclass(frozen=True)
class Exit:
    """Exit function g = row . w of a mode, its crossing direction (+1 rising) and the next mode."""

    row: np.ndarray
    direction: int
    next_mode: str


@dataclass
class Layout:
    """Indices into w = (x, v, x_n, [phi, phi'], 1, u1, u2) for ``n`` bodies."""

    n: int
    bit: int
    impact: int
    torsion: bool

    @property
    def bottom(self) -> int:
        return 2 * self.n

    @property
    def angle(self) -> int:
        """phi (phi' follows); only with torsion."""
        return 2 * self.n + 1

    @property
    def one(self) -> int:
        return self.size - 3

    @property
    def size(self) -> int:
        return 2 * self.n + 4 + 2 * self.torsion

    def unit(self, index: int) -> np.ndarray:
        row = np.zeros(self.size)
        row[index] = 1.0
        return row

    @cached_property
    def penetration_row(self) -> np.ndarray:
        """d = x_bit - x_n."""
        return self.unit(self.bit) - self.unit(self.bottom)

    @cached_property
    def bit_velocity_row(self) -> np.ndarray:
        return self.unit(self.n + self.bit)


def pulse_phases(impact: Impact, end_time_s: float) -> tuple[np.ndarray, list[str]]:
    """((start, end) rows, phase) of the pieces of F_d covering [0, end_time_s], split where F_d
    changes formula."""
    tau, period = impact.duration_s, impact.period_s
    inner = ((0.0, 0.5 * tau, RISING), (0.5 * tau, tau, FALLING)) if impact.shape == "triangular" else \
        ((0.0, tau, ON),)
    pieces = (*inner, (tau, period, OFF))
    starts = np.arange(math.ceil(end_time_s / period))[:, None] * period
    times = np.stack([starts + [low for low, _, _ in pieces], starts + [high for _, high, _ in pieces]], axis=-1)
    times = times.reshape(-1, 2)
    keep = times[:, 0] < end_time_s
    times[:, 1] = np.minimum(times[:, 1], end_time_s)
    return times[keep], [phase for phase, kept in zip([p[2] for p in pieces] * len(starts), keep) if kept]


def pulse_states(impact: Impact, local_s: np.ndarray) -> np.ndarray:
    """Exact (u1, u2) at times ``local_s`` after the blow's start: rows (sin, cos)(pi s / tau) for the
    half-sine, (s, 0) for the triangular pulse, zeros for the rectangular one."""
    states = np.zeros((len(local_s), 2))
    if impact.shape == "half_sine":
        states[:, 0], states[:, 1] = np.sin(np.pi * local_s / impact.duration_s), np.cos(np.pi * local_s / impact.duration_s)
    elif impact.shape == "triangular":
        states[:, 0] = local_s
    return states


def pulse_row(impact: Impact, phase: str) -> np.ndarray:
    """F_d = row . (1, u1, u2) in ``phase``."""
    amplitude, slope = impact.amplitude_n, 2.0 * impact.amplitude_n / impact.duration_s
    if phase == OFF:
        return np.zeros(3)
    if impact.shape == "half_sine":
        return np.array([0.0, amplitude, 0.0])
    if impact.shape == "rectangular":
        return np.array([amplitude, 0.0, 0.0])
    return np.array([0.0, slope, 0.0]) if phase == RISING else np.array([2.0 * amplitude, -slope, 0.0])


def pulse_generator(impact: Impact, phase: str) -> np.ndarray:
    """G with (1, u1, u2)' = G (1, u1, u2): the oscillator of the half-sine, the ramp s' = 1."""
    generator = np.zeros((3, 3))
    if phase == OFF:
        return generator
    if impact.shape == "half_sine":
        omega = math.pi / impact.duration_s
        generator[1, 2], generator[2, 1] = omega, -omega
    elif impact.shape == "triangular":
        generator[1, 0] = 1.0
    return generator


def rock_row(layout: Layout, rock: JenkinsRock, mode: str) -> np.ndarray:
    """F_r = row . w in rock ``mode`` (table in the module doc)."""
    k, c, damper = rock.stiffness_n_per_m, rock.damping_n_s_per_m, layout.bit_velocity_row
    if mode == CONTACT:
        return k * layout.penetration_row + c * damper
    if mode == CRUSHING:
        return rock.threshold_n * layout.unit(layout.one) + c * damper
    if mode == FREE and rock.damping_mode == "always":
        return c * damper
    return np.zeros(layout.size)


def exits(layout: Layout, rock: JenkinsRock, mode: str) -> list[Exit]:
    """Exit functions of ``mode`` (table in the module doc); no crushing exit for an elastic rock
    (F_th infinite) and no clipping without rock damping (k_n d + c_n v = 0 is then d = 0)."""
    k, c = rock.stiffness_n_per_m, rock.damping_n_s_per_m
    d = layout.penetration_row
    total = k * d + c * layout.bit_velocity_row
    crushing = [Exit(k * d - rock.threshold_n * layout.unit(layout.one), 1, CRUSHING)] if rock.crushes else []
    clipping = [Exit(total, -1, CLIPPED)] if rock.damping_mode == "contact" and c > 0 else []
    table = {
        FREE: [Exit(d, 1, CONTACT)],
        CONTACT: [Exit(d, -1, FREE), *crushing, *clipping],
        CLIPPED: [Exit(total, 1, CONTACT), Exit(d, -1, FREE)],
        CRUSHING: [Exit(layout.bit_velocity_row, -1, CONTACT)],
    }
    return table[mode]


def base_matrix(chain: AxialChain, layout: Layout, torsion: Torsion | None) -> np.ndarray:
    """A without rock force and pulse: x' = v, M v' = -K x - C v + F_feed 1, and with torsion
    phi'' = (-k_x phi - c_x phi' + M_x - M_c) / J."""
    n = layout.n
    forces = np.zeros((n, layout.size))
    forces[:, :n] = -chain.stiffness_matrix()
    forces[:, n:2 * n] = -chain.damping_matrix()
    forces[:, layout.one] = chain.constant_forces()
    matrix = np.zeros((layout.size, layout.size))
    matrix[:n, n:2 * n] = np.eye(n)
    matrix[n:2 * n] = np.linalg.solve(chain.mass_matrix(), forces)
    if layout.torsion:
        phi, inertia = layout.angle, torsion.inertia_kg_m2
        matrix[phi, phi + 1] = 1.0
        matrix[phi + 1, phi] = -torsion.stiffness_n_m_per_rad / inertia
        matrix[phi + 1, phi + 1] = -torsion.damping_n_m_s_per_rad / inertia
        matrix[phi + 1, layout.one] = (torsion.drive_torque_n_m - torsion.resisting_torque_n_m) / inertia
    return matrix


def mode_part(layout: Layout, rock: JenkinsRock, inverse_mass: np.ndarray, mode: str) -> np.ndarray:
    """What rock ``mode`` adds to A: the rows -M^-1 F_r e_bit, and in crushing x_n' = v_bit (Eq. 2)."""
    n = layout.n
    part = np.zeros((layout.size, layout.size))
    part[n:2 * n] = -np.outer(inverse_mass[:, layout.bit], rock_row(layout, rock, mode))
    if mode == CRUSHING:
        part[layout.bottom] = layout.bit_velocity_row
    return part


def phase_part(layout: Layout, impact: Impact, inverse_mass: np.ndarray, phase: str) -> np.ndarray:
    """What pulse ``phase`` adds to A: the rows M^-1 F_d e_impact and the pulse generator."""
    n = layout.n
    part = np.zeros((layout.size, layout.size))
    part[n:2 * n, layout.one:] = np.outer(inverse_mass[:, layout.impact], pulse_row(impact, phase))
    part[layout.one:, layout.one:] = pulse_generator(impact, phase)
    return part


def taylor_order(norm_times_step: float) -> int:
    """Smallest K with (||A|| h)^(K+1) / (K+1)! below TAYLOR_REMAINDER."""
    order, term = 0, 1.0
    while term > TAYLOR_REMAINDER:
        order += 1
        term *= norm_times_step / order
    return order


def balance(matrix: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(D^-1 A D, diagonal of D): LAPACK's diagonal balancing (``scipy.linalg.matrix_balance`` without
    permutation). Its 1-norm bounds the growth of the Taylor terms; it is the better conditioned
    argument of expm."""
    balanced, _, _, scale, info = dgebal(matrix, scale=1, permute=0)
    if info < 0:
        raise ValueError(f"dgebal: illegal argument {-info}")
    return balanced, scale


class Operators:
    """The per-key (rock mode, pulse phase) arrays of models.exact_kernels.run_events, stacked over the
    keys and filled when the kernel first reaches a key (``add``); key_of[mode id, phase id] -> key
    (-1: not built). R = (I, F_r row, F_d row, exit rows) gives a point's outputs."""

    def __init__(self, matrices: dict[Key, np.ndarray], step_s: float, order: int, layout: Layout,
                 rock: JenkinsRock, impact: Impact) -> None:
        self.matrices, self.step_s = matrices, step_s
        self.layout, self.rock, self.impact = layout, rock, impact
        keys, size, width = len(matrices), layout.size, layout.size + 2 + MAX_EXITS
        self.taylor = np.empty((keys, size, (order + 1) * width))  # [(R A^k / k!)^T]_k
        self.one_step = np.empty((keys, size, size))  # expm(A h)
        self.anchors = np.empty((keys, size, ANCHORS * size))  # [expm(A a B h)^T]_a
        self.readout = np.empty((keys, size, PER_ANCHOR * width))  # [(R expm(A b h))^T]_b
        self.exit_counts = np.zeros(keys, dtype=np.int64)
        self.directions = np.zeros((keys, MAX_EXITS))
        self.next_modes = np.zeros((keys, MAX_EXITS), dtype=np.int64)  # mode ids
        self.rock_rows = np.zeros((keys, size))  # F_r = row . w
        self.impact_rows = np.zeros((keys, 3))  # F_d = row . (1, u1, u2)
        self.key_of = np.full((len(MODES), len(PHASES)), -1, dtype=np.int64)
        self.built = 0

    def add(self, key: Key) -> None:
        """Build the arrays of ``key``: expm(A h) = D expm(D^-1 A D h) D^-1 (``scipy.linalg.expm`` on
        the balanced matrix), its powers, R, R A^k / k!."""
        (mode, phase), layout, i = key, self.layout, self.built
        matrix, size = self.matrices[key], layout.size
        balanced, scale = balance(matrix)
        self.one_step[i] = scale[:, None] * expm(balanced * self.step_s) / scale[None, :]
        mode_exits = exits(layout, self.rock, mode)
        count = len(mode_exits)
        readout = np.zeros((size + 2 + MAX_EXITS, size))
        readout[:size] = np.eye(size)
        readout[size] = self.rock_rows[i] = rock_row(layout, self.rock, mode)
        readout[size + 1, layout.one:] = self.impact_rows[i] = pulse_row(self.impact, phase)
        readout[size + 2:size + 2 + count] = [e.row for e in mode_exits]
        self.exit_counts[i] = count
        self.directions[i, :count] = [e.direction for e in mode_exits]
        self.next_modes[i, :count] = [MODES.index(e.next_mode) for e in mode_exits]
        assemble(self.one_step[i], matrix, readout, ANCHORS, PER_ANCHOR, self.readout[i], self.anchors[i],
                 self.taylor[i])
        self.key_of[MODES.index(mode), PHASES.index(phase)] = i
        self.built += 1


class ExactSolver:
    """The event-driven exact solution of one scene (module doc)."""

    def __init__(self, scene: Scene, sample_interval_s: float, min_switch_interval_s: float,
                 max_switches_per_blow: int) -> None:
        self.scene, self.impact, self.rock = scene, scene.impact, scene.rock_law()
        self.chain = axial_chain(scene)
        self.layout = Layout(self.chain.size, self.chain.bit_body, self.chain.impact_body, scene.effects.torsion)
        self.min_switch_interval_s = min_switch_interval_s
        self.max_switches = max_switches_per_blow * math.ceil(scene.solver.end_time_s * self.impact.frequency_hz)
        self.phase_times, self.phases = pulse_phases(self.impact, scene.solver.end_time_s)
        clips = self.rock.damping_mode == "contact" and self.rock.damping_n_s_per_m > 0
        modes = (FREE, CONTACT) + ((CLIPPED,) if clips else ()) + ((CRUSHING,) if self.rock.crushes else ())
        inverse_mass = np.linalg.inv(self.chain.mass_matrix())
        base = base_matrix(self.chain, self.layout, scene.torsion)
        mode_parts = {mode: base + mode_part(self.layout, self.rock, inverse_mass, mode) for mode in modes}
        phase_parts = {phase: phase_part(self.layout, self.impact, inverse_mass, phase)
                       for phase in dict.fromkeys(self.phases)}
        matrices = {(mode, phase): with_mode + phase_parts[phase]  # A = base + mode part + phase part
                    for mode, with_mode in mode_parts.items() for phase in phase_parts}
        norm = max(np.linalg.norm(balance(matrix)[0], 1) for matrix in matrices.values())
        self.per_sample = max(1, math.ceil(sample_interval_s * norm))
        self.step_s = sample_interval_s / self.per_sample
        self.operators = Operators(matrices, self.step_s, taylor_order(norm * self.step_s), self.layout, self.rock,
                                   self.impact)

    def run(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """From the scene's start (rest, off the bottom; or preloaded, in contact) through every pulse
        phase to the end time: (sample times; rows w, F_r, F_d; switch times; mode ids entered). The
        kernel returns when it reaches a key not built yet, and resumes once it is built."""
        layout, ops, period = self.layout, self.operators, self.impact.period_s
        w = np.zeros(layout.size)
        w[layout.one] = 1.0
        w[:layout.n] = initial_positions_m(self.scene)
        if layout.torsion:
            w[layout.angle] = initial_torsion_angle_rad(self.scene)
        starts = self.phase_times[:, 0]
        pulse = pulse_states(self.impact, starts - np.floor(starts / period + 1e-9) * period)
        phase_ids = np.array([PHASES.index(p) for p in self.phases])
        capacity = (math.floor(self.scene.solver.end_time_s / (self.step_s * self.per_sample)) + 4
                    + 2 * len(self.phases) + 2 * self.max_switches + ANCHORS * PER_ANCHOR)
        time_s, rows = np.empty(capacity), np.empty((capacity, layout.size + 2 + MAX_EXITS))
        switch_times = np.empty(self.max_switches + 1)
        switch_modes = np.empty(self.max_switches + 1, dtype=np.int64)
        progress = np.array([0, MODES.index(CONTACT if layout.penetration_row @ w > 0 else FREE), 0, 0, 0])
        clock = np.zeros(2)
        while True:
            status = run_events(
                ops.taylor, ops.one_step, ops.anchors, ops.readout, ops.exit_counts, ops.directions, ops.next_modes,
                ops.rock_rows, ops.impact_rows, ops.key_of, self.phase_times, phase_ids, pulse, self.step_s,
                PER_ANCHOR, self.per_sample, self.min_switch_interval_s, self.max_switches, layout.n, layout.bit,
                layout.bottom, MODES.index(CRUSHING), self.rock.crushing_penetration_m if self.rock.crushes else 0.0,
                POSITION_LIMIT_M, progress, clock, w, time_s, rows, switch_times, switch_modes)
            if status != MISSING_KEY:
                break
            ops.add((MODES[progress[1]], self.phases[progress[0]]))
        filled, switches = progress[2], progress[3]
        time_s, rows, switch_times = time_s[:filled], rows[:filled], switch_times[:switches]
        if status == TOO_MANY_SWITCHES:
            raise SimulationFailed(
                f"scene '{self.scene.name}': exact solver exceeded {self.max_switches} rock-law switches "
                f"at t = {switch_times[-1]:.6g} s (chattering contact); raise max_switches_per_blow or check the scene"
            )
        if status == DIVERGED:
            first = diverged_index(rows[:, :layout.n], rows[:, layout.n:2 * layout.n])
            raise SimulationFailed(f"scene '{self.scene.name}': exact solution diverged at "
                                   f"t = {time_s[-1 if first is None else first]:.6g} s (an unstable chain?)")
        return time_s, rows, switch_times, switch_modes[:switches]


def simulate_exact(scene: Scene, sample_interval_s: float | None = None, min_switch_interval_s: float = 1e-12,
                   max_switches_per_blow: int = 1000) -> SimulationResult:
    """Exact solution of ``scene`` from its start to ``scene.solver.end_time_s`` (formulation "exact").

    Samples: a uniform grid of ``sample_interval_s`` (default ``scene.solver.output_interval_s``, at most
    ENERGY_SAMPLE_S when energy outputs are asked for) plus both sides of every rock-law switch and pulse
    switch (repeated times, the rock and piston forces of each side). ``min_switch_interval_s`` and
    ``max_switches_per_blow``: module doc. ValueError for a scene outside its scope
    (models.exact_scope: another rock law than Jenkins, a nonlinear connector).
    """
    why = exact_unsupported(scene)
    if why:
        raise ValueError(f"scene '{scene.name}': the exact formulation cannot run {why}; use exudyn or ode")
    start = time.process_time()
    if sample_interval_s is None:  # energies are integrated by quadrature over the samples
        energy = "energy" in scene.needed_data()
        sample_interval_s = min(scene.solver.output_interval_s, ENERGY_SAMPLE_S) if energy else \
            scene.solver.output_interval_s
    solver = ExactSolver(scene, sample_interval_s, min_switch_interval_s, max_switches_per_blow)
    time_s, rows, switch_times, switch_modes = solver.run()
    layout = solver.layout
    n, angle = layout.n, layout.angle
    cpu = time.process_time() - start
    entered = np.bincount(switch_modes, minlength=len(MODES))
    return SimulationResult(
        scene=scene,
        chain=solver.chain,
        formulation="exact",
        time_s=time_s,
        position_m=rows[:, :n],
        velocity_m_per_s=rows[:, n:2 * n],
        bottom_m=rows[:, layout.bottom],
        rock_force_n=rows[:, layout.size],
        impact_force_n=rows[:, layout.size + 1],
        torsion_angle_rad=rows[:, angle] if layout.torsion else None,
        torsion_rate_rad_per_s=rows[:, angle + 1] if layout.torsion else None,
        cpu_time_s=cpu,
        info={
            "solver_success": True,
            "sub_step_s": solver.step_s,
            "sample_interval_s": solver.step_s * solver.per_sample,
            "samples": len(time_s),
            "mode_switches": len(switch_times),
            "switches_into": {mode: int(count) for mode, count in zip(MODES, entered) if count},
            "switch_times_s": switch_times,
            "switch_modes": [MODES[m] for m in switch_modes],  # the mode entered at each switch time
            "min_switch_interval_s": min_switch_interval_s,
        },
    )
