"""Exact event-driven solution of the piecewise-linear model (paper Eq. 1, 2, 4), no Exudyn.

Between two switches the model is linear and autonomous in the augmented state
w = (x (n bodies), v (n bodies), rock states, [phi, phi'], 1, u1, u2) (phi, phi' with the torsion
effect; u1, u2 the pulse generator of models.drill.pulse, the constant 1 carrying the feed forces, the
laws' constants and the net torque):

    w' = A_(modes, phase) w

``modes`` holds the mode of every piecewise element (models.drill.piecewise: the rock law and each
nonlinear connector), ``phase`` the pulse phase. A is generated, never written by hand: the chain's
first-order matrix (models.drill.chain, the linear links and the feed), the torsion line, the pulse
phase's force row and generator (models.drill.pulse), and for each element its mode's force row acting
along the element's load and its state-rate rows (rocklaw.modes: the laws' own declarations).
The mode is left at the first zero crossing, in its direction, of one of the current modes' exit
rows; the next mode starts from the element's entry values (Jenkins: x_n = x_bit - F_th / k_n on
entering crushing, the return map on the switching surface; the bottom never decreases).

Propagation. A global sub-grid of step h (an integer fraction of the sample interval, with
||A_bal|| h <= 1 for the balanced matrices of the modes, so h <= 1/(2 pi) of the shortest period)
carries the solution, w(t_j + b h) = expm(A b h) w(t_j), in batches of J = A B sub-grid points
from one state s0: anchors expm(A a B h) s0 (a < A), then every point a B + b from its anchor
(b < B). SciPy computes expm(A h) once per (modes, phase) key (on the balanced matrix); its powers,
the readout rows R = (I, F_r row, F_d row, exit rows) and the Taylor matrices A^k / k! are cached,
and a batch is two matrix products. A piece shorter than h (to the first grid point after a switch,
to a pulse switch, to a located switch) uses the Taylor series sum_k (A s)^k / k! w truncated where
its remainder is below 1e-20 of the state (s <= h): the exact solution to round-off, without an
expm per switch. Each exit function g = c . w and its slope g' = c A w come with every point; the
first interval where g goes from its side to the crossed side, or where g' turns from towards it to
away from it and the maximum of g between the points is on the crossed side (a crossing and its
return within one sub-step), brackets the switch, which Brent's method (as ``scipy.optimize.brentq``)
locates on the Taylor polynomial g(s) of the exact solution. The event
loop runs compiled (models.solvers.exact_kernels); the operators of a key are built when the run first
reaches it.

Works (with the energy outputs): the impact work and the work the links, the rock and the torsion
line absorb are quadratic forms w^T Q w integrated exactly between the samples,
int_0^s w^T Q w = w^T G(s) w with G(s) = int_0^s expm(A^T u) Q expm(A u) du per key, a series in s
(models.solvers.exact_power_kernels.power_integrals and integrate_powers), so the samples stay at the output
interval.

Zero-length modes: a mode lasts at least ``min_switch_interval_s``. Its start is taken as not
crossed for every exit function; if an exit function is on its crossed side already at
t_start + min_switch_interval_s, the switch is placed there. More than ``max_switches_per_blow``
switches per blow on average raise :class:`SimulationFailed`, and so does a diverged state
(models.evaluation.stability's criterion, checked at every switch, pulse switch and batch end; the message
names the first diverged sample).

Blow starts. A law that resets at blow starts (the state the next blow meets: models.drill.indexing) is
linear between blows; the compiled loop stops at each blow start, the rock states are set here
(any function of the state, e.g. of the torsion angle turned since the last blow) and the rock's
mode found again, and the loop goes on.
"""

from __future__ import annotations

import bisect
import copy
import math
import time
from collections import Counter, OrderedDict
from collections.abc import Callable

import numpy as np
from scipy.linalg import expm
from threadpoolctl import ThreadpoolController

from ..definition.links import CLOSED, OPEN
from ..definition.scene import Scene
from ..drill.piston import CAUGHT, CONTACT, PistonJumps, piston_history
from ..drill.pulse import (
    PHASES,
    blow_start_times,
    generator_states,
    phase_pieces,
    phase_row,
)
from ..evaluation.results import SimulationResult
from ..evaluation.run_record import ExactSolverRecord
from ..evaluation.stability import POSITION_LIMIT_M, SimulationFailed, diverged_index
from .exact_kernels import (
    BLOW_START,
    DIVERGED,
    MISSING_KEY,
    TOO_MANY_SWITCHES,
    assemble,
    run_events,
)
from .exact_power_kernels import integrate_powers, power_integrals
from .exact_system import Model, Modes, balance, sub_step, unsupported
from .simulation import SceneError, Simulation, as_simulation

# A, B: a batch is J = A B sub-grid points from one state (module doc). Building a key costs about 2 B + A
# products of m x m matrices, a sub-grid point m (m + r + m / B) multiply-adds: 8 x 8 against 16 x 16 (python
# benchmarks/bench_size.py --segments 2,8,32,64 --times 0.2): exact CPU s 0.008 / 0.075 / 8.9 / 37.5 against
# 0.008 / 0.090 / 9.4 / 42.6 at 11 / 35 / 131 / 259 bodies, operator memory 28 % less; 4 x 4: 40.1 s at 259.
ANCHORS, PER_ANCHOR = 8, 8
TAYLOR_REMAINDER = 1e-20  # relative truncation of the Taylor series on pieces shorter than h
# The operators are small (m ~ 10-300): a multi-threaded BLAS spends more on its threads than on the
# products (a 13 x 13 expm took 8 ms with two threads on a loaded 2-core machine, 0.1 ms with one).
BLAS = ThreadpoolController()
CacheKey = tuple[bytes, bytes, bytes, float, int, int]  # A, R, power forms, h, sub-steps per sample, order


class OperatorCache:
    """The propagators of the keys built last in this process, by (A, R, power forms, h, sub-steps per
    sample, Taylor order): they depend on neither the impact frequency nor the end time, so the runs of
    a frequency scan build them once (a key costs 0.3-0.6 ms on the paper scene). Bounded in memory,
    the least recently used dropped first: a key's arrays take 0.2 MB on the paper scene and grow with
    m^2 (32 MB at 131 bodies)."""

    def __init__(self, max_bytes: int) -> None:
        self.max_bytes, self.bytes = max_bytes, 0
        self.entries: OrderedDict[CacheKey, tuple[np.ndarray, ...]] = OrderedDict()

    def get(self, key: CacheKey) -> tuple[np.ndarray, ...] | None:
        arrays = self.entries.get(key)
        if arrays is not None:
            self.entries.move_to_end(key)
        return arrays

    def holds(self, arrays: tuple[np.ndarray, ...]) -> bool:
        """Whether ``arrays`` fit in the cache at all: a key larger than the cache (0.24 GB a key for the rod piston
        of 32 segments on a 256-segment rod of tests/test_piston.py) is neither copied nor kept, where its copy was
        made only to be dropped at once."""
        return sum(array.nbytes for array in arrays) <= self.max_bytes

    def put(self, key: CacheKey, arrays: tuple[np.ndarray, ...]) -> None:
        self.entries[key] = arrays
        self.bytes += sum(a.nbytes for a in arrays)
        while self.bytes > self.max_bytes and self.entries:
            self.bytes -= sum(a.nbytes for a in self.entries.popitem(last=False)[1])

    def clear(self) -> None:
        self.entries.clear()
        self.bytes = 0


OPERATOR_CACHE = OperatorCache(64 << 20)
CACHED_ARRAYS = ("one_step", "readout", "anchors", "taylor", "step_powers", "step_grams", "series")


def taylor_order(norm_times_step: float) -> int:
    """Smallest K with (||A|| h)^(K+1) / (K+1)! below TAYLOR_REMAINDER."""
    order, term = 0, 1.0
    while term > TAYLOR_REMAINDER:
        order += 1
        term *= norm_times_step / order
    return order


class Operators:
    """The per-key (modes, phase) arrays of models.solvers.exact_kernels.run_events, stacked over the keys and
    filled when the kernel first reaches a key (``add``); mode combinations get ids as they are
    first named, key_of[mode id, phase id] -> key (-1: not built), arrays growing as needed.
    R = (I, F_r row, F_d row, exit rows c_e, their slopes c_e A) gives a point's outputs."""

    def __init__(self, model: Model, step_s: float, per_sample: int, order: int, capacity: int, powers: bool) -> None:
        self.model, self.step_s, self.per_sample, self.order = model, step_s, per_sample, order
        self.modes: list[Modes] = []
        self.mode_ids: dict[Modes, int] = {}
        size, exits = model.layout.size, model.max_exits
        self.width = size + 2 + 2 * exits
        self.taylor = np.empty((capacity, size, (order + 1) * self.width))  # [(R A^k / k!)^T]_k
        self.one_step = np.empty((capacity, size, size))  # expm(A h)
        self.anchors = np.empty((capacity, size, ANCHORS * size))  # [expm(A a B h)^T]_a
        self.readout = np.empty((capacity, size, PER_ANCHOR * self.width))  # [(R expm(A b h))^T]_b
        self.exit_counts = np.zeros(capacity, dtype=np.int64)
        self.directions = np.zeros((capacity, exits))
        self.next_modes = np.zeros((capacity, exits), dtype=np.int64)  # mode ids
        self.reset_counts = np.zeros((capacity, exits), dtype=np.int64)
        self.reset_targets = np.zeros((capacity, exits, model.max_resets), dtype=np.int64)
        self.reset_rows = np.zeros((capacity, exits, model.max_resets, size))
        self.rock_rows = np.zeros((capacity, size))  # F_r = row . w
        self.impact_rows = np.zeros((capacity, 3))  # F_d = row . (1, u1, u2)
        self.key_of = np.full((capacity, len(PHASES)), -1, dtype=np.int64)
        # with the energy outputs, the integrals of the power forms Q (Model.power_forms) over whole sub-steps
        # and as a series in the length (integrate_powers), [key, form]
        form_capacity = capacity if powers else 0
        self.step_powers = np.empty((form_capacity, per_sample + 1, size, size))  # expm(A h)^j
        self.step_grams = np.empty((form_capacity, 2, per_sample + 1, size, size))  # G(j h), j <= p
        self.series = np.empty((form_capacity, 2, order + 1, size, size))
        self.built = 0

    def mode_id(self, modes: Modes) -> int:
        """The id of a mode combination (assigned when first named)."""
        if modes not in self.mode_ids:
            self.mode_ids[modes] = len(self.modes)
            self.modes.append(modes)
            if len(self.modes) > self.key_of.shape[0]:
                self.key_of = np.concatenate([self.key_of, np.full_like(self.key_of, -1)])
        return self.mode_ids[modes]

    def _grow(self) -> None:
        """Double the capacity of the per-key arrays."""
        for name in ("taylor", "one_step", "anchors", "readout", "exit_counts", "directions", "next_modes",
                     "reset_counts", "reset_targets", "reset_rows", "rock_rows", "impact_rows", "step_powers",
                     "step_grams", "series"):
            array = getattr(self, name)
            if len(array):
                setattr(self, name, np.concatenate([array, np.zeros_like(array)]))

    def add(self, modes: Modes, phase: str) -> None:
        """Build the arrays of (modes, phase): expm(A h) = D expm(D^-1 A D h) D^-1 (``scipy.linalg.expm``
        on the balanced matrix), its powers, R, R A^k / k!, the exits and their resets; the propagators are
        taken from OPERATOR_CACHE when an earlier run built them from the same A, R and power forms."""
        model, i = self.model, self.built
        if i == self.one_step.shape[0]:
            self._grow()
        matrix, size = model.matrix(modes, phase), model.layout.size
        exits = model.exits(modes)
        readout = np.zeros((self.width, size))
        readout[:size] = np.eye(size)
        readout[size] = self.rock_rows[i] = model.rock_force_row(modes)
        readout[size + 1, model.layout.one:] = self.impact_rows[i] = phase_row(model.impact, phase)
        for e, (row, direction, following, resets) in enumerate(exits):
            readout[size + 2 + e] = row
            readout[size + 2 + model.max_exits + e] = row @ matrix
            self.directions[i, e] = direction
            self.next_modes[i, e] = self.mode_id(following)
            self.reset_counts[i, e] = len(resets)
            for j, (target, reset) in enumerate(resets):
                self.reset_targets[i, e, j], self.reset_rows[i, e, j] = target, reset
        self.exit_counts[i] = len(exits)
        forms = model.power_forms(modes, phase) if len(self.series) else np.empty(0)
        names = CACHED_ARRAYS if len(self.series) else CACHED_ARRAYS[:4]
        key = (matrix.tobytes(), readout.tobytes(), forms.tobytes(), self.step_s, self.per_sample, self.order)
        cached = OPERATOR_CACHE.get(key)
        if cached is None:
            self.build(i, matrix, readout, forms, modes)
            built = tuple(getattr(self, name)[i] for name in names)
            if OPERATOR_CACHE.holds(built):  # a key larger than the whole cache is not copied only to be dropped
                OPERATOR_CACHE.put(key, tuple(array.copy() for array in built))
        else:
            for name, array in zip(names, cached, strict=True):
                getattr(self, name)[i] = array
        self.key_of[self.mode_id(modes), PHASES.index(phase)] = i
        self.built += 1

    def build(self, i: int, matrix: np.ndarray, readout: np.ndarray, forms: np.ndarray, modes: Modes) -> None:
        """The propagators of key ``i`` from A, R and the power forms (:meth:`add`)."""
        balanced, scale = balance(matrix)
        if taylor_order(np.linalg.norm(balanced, 1) * self.step_s) > self.order:
            raise SimulationFailed(f"scene '{self.model.simulation.name}': exact solver: mode {modes} is stiffer "
                                   f"than the modes that chose its sub-step; please report this scene")
        self.one_step[i] = scale[:, None] * expm(balanced * self.step_s) / scale[None, :]
        assemble(self.one_step[i], matrix, readout, ANCHORS, PER_ANCHOR, self.readout[i], self.anchors[i],
                 self.taylor[i])
        if len(self.series):  # the integrals of the power forms (module doc)
            power_integrals(self.one_step[i], balanced, scale, forms, self.step_s, self.step_powers[i],
                            self.step_grams[i], self.series[i])


class ExactSolver:
    """The event-driven exact solution of one simulation (module doc)."""

    def __init__(self, simulation: Simulation) -> None:
        settings = simulation.settings
        self.simulation, self.impact = simulation, simulation.impact
        self.model = Model(simulation)
        self.layout = self.model.layout
        self.min_switch_interval_s = settings.min_switch_interval_s
        self.blows = simulation.blow_starts()
        self.piston = None if simulation.piston is None else PistonJumps(simulation.piston)
        self.contact = next((i for i, e in enumerate(self.model.pieces) if e.name == CONTACT), None)
        self.retime(settings.end_time_s)
        norm, self.per_sample, self.step_s = sub_step(simulation, self.phases, self.model)
        self.operators = Operators(self.model, self.step_s, self.per_sample, taylor_order(norm * self.step_s),
                                   len(self.model.pieces[0].table) * len(set(self.phases)),
                                   "energy" in simulation.needed_data)

    def with_frequency(self, simulation: Simulation, end_time_s: float | None = None) -> ExactSolver:
        """This solver for ``simulation``, whose scene differs from its own in the impact frequency only:
        the matrices, the sub-step and the operators built do not depend on it (the pulse's shape,
        amplitude and duration do), so a frequency scan builds them once (models.steady); it runs to
        ``end_time_s`` (default the simulation's end time)."""
        twin = copy.copy(self)
        twin.simulation, twin.impact = simulation, simulation.impact
        twin.blows = simulation.blow_starts()
        twin.piston = None if simulation.piston is None else PistonJumps(simulation.piston)
        twin.retime(simulation.settings.end_time_s if end_time_s is None else end_time_s)
        return twin

    def retime(self, end_time_s: float) -> None:
        """Run from 0 to ``end_time_s`` (the operators built so far stay: models.steady runs one solver over
        orbits of different lengths)."""
        self.end_time_s = end_time_s
        self.max_switches = self.simulation.settings.max_switches_per_blow * math.ceil(
            end_time_s * self.impact.frequency_hz)
        self.phase_times, self.phases = phase_pieces(self.impact, end_time_s)
        starts = self.blows or self.piston  # the kernel stops at every blow start for them
        blows = blow_start_times(self.impact, end_time_s) if starts else np.empty(0)
        self.blow_phases = np.isin(self.phase_times[:, 0], blows).astype(np.int64)

    def start_blow(self, w: np.ndarray, mode_id: int, time_s: float, row: int) -> int:
        """Set the rock states of w to those the blow starting now meets, and strike with the piston
        (models.drill.piston; ``row`` the first sample after it); the mode id with the rock's mode found again and
        the piston's contact closing."""
        layout, rock = self.layout, self.model.pieces[0]
        modes = self.operators.modes[mode_id]
        if self.blows:
            states = slice(2 * layout.n, 2 * layout.n + layout.rock_states)
            angle = w[layout.angle] if layout.torsion else 0.0
            # the law stays the one the matrices were built for: a law whose rows change per blow is unsupported()
            _, w[states] = self.blows(w[self.simulation.chain.bit_body], tuple(w[states]), angle)
            modes = (rock.initial_mode(w), *modes[1:])
        if self.piston is not None:
            n, setup = layout.n, self.piston.setup
            self.piston.strike(time_s, w[:n], w[n:2 * n], row)
            closing = w[n + setup.front] > w[n + setup.impact_body]
            modes = modes[:self.contact] + (CLOSED if closing else OPEN,) + modes[self.contact + 1:]
        return self.operators.mode_id(modes)

    def note_catches(self, time_s: np.ndarray, rows: np.ndarray, switch_times: np.ndarray,
                     entered: list[Modes]) -> None:
        """Note every catch (the first switch into the contact's ``caught`` mode after a strike, its entry
        reset applied by the kernel) from the row recorded before it (the kernel records both sides of a
        switch). The switches of the other links while the piston stays caught enter ``caught`` again and
        are not catches."""
        n = self.layout.n
        strikes = sorted(t for t, kind, _, _ in self.piston.log if kind == "strike")
        caught_s = -math.inf  # the last catch noted
        for t, modes in zip(switch_times, entered, strict=True):
            struck = bisect.bisect_right(strikes, t)
            if modes[self.contact] == CAUGHT and (struck and strikes[struck - 1] > caught_s):
                before = int(np.searchsorted(time_s, t))  # the first of the two rows at t
                self.piston.noted_catch(float(t), rows[before, :n], rows[before, n:2 * n], before + 1)
                caught_s = float(t)

    def works_j(self, time_s: np.ndarray, rows: np.ndarray) -> dict[str, np.ndarray]:
        """Cumulative impact work int F_d v_shank dt and internal work (what the links, the rock and the
        torsion line absorb) at every row, integrated exactly from the propagators: a whole sample interval
        as w^T G(sample interval) w, all of one key at once (BLAS), every other interval by
        integrate_powers."""
        ops, size = self.operators, self.layout.size
        interval = self.step_s * self.per_sample
        powers = np.zeros((len(time_s), 2))
        flat_series = ops.series.reshape(*ops.series.shape[:3], size * size)
        integrate_powers(time_s, rows, self.row_keys, ops.step_powers, ops.step_grams, flat_series, self.step_s,
                         interval, powers)
        whole = np.flatnonzero(np.abs(np.diff(time_s) - interval) <= 1e-9 * interval)
        keys = self.row_keys[whole]
        for key in np.unique(keys):
            start = whole[keys == key]
            states = rows[start, :size]
            for q in range(2):
                powers[start + 1, q] = np.einsum("ij,ij->i", states @ ops.step_grams[key, q, -1], states)
        impact, internal = np.cumsum(powers, axis=0).T
        return {"impact": impact, "internal": internal}

    def run(self, start: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[Modes]]:
        """From the simulation's start (rest, off the bottom; or preloaded, in contact; or the augmented
        state ``start``) through every pulse phase to the end time: (sample times; rows w, F_r, F_d; switch
        times; modes entered); the key propagating from each row in ``row_keys``. The kernel returns when
        it reaches a key not built yet, and resumes once it is built."""
        layout, ops, period, simulation = self.layout, self.operators, self.impact.period_s, self.simulation
        n = layout.n
        w = np.zeros(layout.size)
        w[layout.one] = 1.0
        setup = simulation.piston
        w[:n] = simulation.initial_positions_m if setup is None else setup.parked(simulation.initial_positions_m)
        w[n:n + simulation.chain.size] = simulation.initial_velocities
        w[2 * n:2 * n + layout.rock_states] = simulation.initial_rock_state
        if layout.torsion:
            w[layout.angle] = simulation.initial_torsion_angle_rad
            w[layout.angle + 1] = simulation.initial_torsion_rate_rad_per_s
        if start is not None:  # a given state (models.steady: the period map)
            w[:] = start
        starts = self.phase_times[:, 0]
        pulse = generator_states(self.impact, starts - np.floor(starts / period + 1e-9) * period)
        phase_ids = np.array([PHASES.index(p) for p in self.phases])
        capacity = (math.floor(self.end_time_s / (self.step_s * self.per_sample)) + 4
                    + 2 * len(self.phases) + 2 * self.max_switches + ANCHORS * PER_ANCHOR)
        time_s, rows, row_keys = np.empty(capacity), np.empty((capacity, ops.width)), np.empty(capacity, dtype=np.int64)
        switch_times = np.empty(self.max_switches + 1)
        switch_modes = np.empty(self.max_switches + 1, dtype=np.int64)
        initial = tuple(element.initial_mode(w) for element in self.model.pieces)
        progress = np.array([0, ops.mode_id(initial), 0, 0, 0])
        clock = np.zeros(2)
        while True:
            status = run_events(
                ops.taylor, ops.one_step, ops.anchors, ops.readout, ops.exit_counts, ops.directions, ops.next_modes,
                ops.rock_rows, ops.impact_rows, ops.key_of, self.phase_times, phase_ids, pulse, self.blow_phases,
                ops.reset_counts,
                ops.reset_targets, ops.reset_rows, self.model.pieces[0].monotone, self.step_s, PER_ANCHOR,
                self.per_sample, self.min_switch_interval_s, self.max_switches, n, POSITION_LIMIT_M, progress, clock,
                w, time_s, rows, row_keys, switch_times, switch_modes)
            if status == BLOW_START:
                progress[1] = self.start_blow(w, progress[1], float(clock[0]), int(progress[2]))
            elif status == MISSING_KEY:
                ops.add(ops.modes[progress[1]], self.phases[progress[0]])
            else:
                break
        filled, switches = progress[2], progress[3]
        time_s, rows, switch_times = time_s[:filled], rows[:filled], switch_times[:switches]
        self.row_keys = row_keys[:filled]
        if status == TOO_MANY_SWITCHES:
            raise SimulationFailed(
                f"scene '{simulation.name}': exact solver exceeded {self.max_switches} switches "
                f"at t = {switch_times[-1]:.6g} s (chattering contact); raise solver.max_switches_per_blow "
                f"or check the scene")
        if status == DIVERGED:
            first = diverged_index(rows[:, :n], rows[:, n:2 * n])
            raise SimulationFailed(f"scene '{simulation.name}': exact solution diverged at "
                                   f"t = {time_s[-1 if first is None else first]:.6g} s (an unstable chain?)")
        return time_s, rows, switch_times, [ops.modes[m] for m in switch_modes[:switches].tolist()]


def _switch_counts(model: Model, before: Modes, entered: list[Modes]) -> dict[str, int]:
    """How often each element mode was entered (``mode`` for the rock, ``link:mode`` for a link)."""
    counts: dict[str, int] = {}
    for (previous, modes), times in Counter(zip([before, *entered], entered)).items():  # each distinct switch once
        for index, (old, new) in enumerate(zip(previous, modes, strict=True)):
            if old != new:
                key = new if index == 0 else f"{model.pieces[index].name}:{new}"
                counts[key] = counts.get(key, 0) + times
    return counts


def simulate(run: Scene | Simulation, progress: Callable[[float], None] | None = None) -> SimulationResult:
    """Exact solution of the simulation from its start to its end time (formulation "exact").

    Samples: a uniform grid of the settings' ``sample_interval_s`` (models.evaluation.solver_settings) plus both
    sides of every switch and pulse switch (repeated times, the rock and piston forces of each side).
    ``min_switch_interval_s`` and ``max_switches_per_blow``: module doc. ``progress(t)`` is called once,
    at the end (a run takes milliseconds).
    """
    simulation = as_simulation(run)
    why = unsupported(simulation)
    if why:
        raise SceneError(("solver", "formulation"), "exact", why)
    if simulation.dynamic_chain.waves:  # rods carried as waves: the characteristics (models.waves)
        # its kernels: about 45 ms of imports, only where a scene has wave rods
        from ..waves import exact_waves

        return exact_waves.simulate(simulation, progress)
    start = time.process_time()
    with BLAS.limit(limits=1, user_api="blas"):
        solver = ExactSolver(simulation)
    return solver_result(solver, simulation, start, progress)


def solver_result(solver: ExactSolver, simulation: Simulation, cpu_start: float,
                  progress: Callable[[float], None] | None = None, start: np.ndarray | None = None,
                  ran: tuple[np.ndarray, np.ndarray, np.ndarray, list[Modes]] | None = None) -> SimulationResult:
    """Run ``solver`` from ``start`` (default the simulation's initial state) to its end time into the result
    of ``simulation`` (the solver's own, or one that differs from it in its start and end only); ``ran``:
    the solver's run just made (models.steady reads its rows first)."""
    with BLAS.limit(limits=1, user_api="blas"):
        time_s, rows, switch_times, entered = ran or solver.run(start)
        works = solver.works_j(time_s, rows) if "energy" in simulation.needed_data else None
    layout = solver.layout
    n, angle, states = layout.n, layout.angle, slice(2 * layout.n, 2 * layout.n + layout.rock_states)
    cpu = time.process_time() - cpu_start
    impact_force, piston = rows[:, layout.size + 1], None
    if solver.piston is not None:
        solver.note_catches(time_s, rows, switch_times, entered)
        piston = piston_history(simulation.piston, solver.piston, time_s, rows[:, :n], rows[:, n:2 * n], None)
        impact_force = piston.contact_force_n
    bodies = simulation.chain.size  # the drill string's (a piston's follow)
    if progress is not None:
        progress(simulation.settings.end_time_s)
    initial = tuple(element.initial_mode(rows[0, :layout.size]) for element in solver.model.pieces)
    return SimulationResult(
        simulation=simulation,
        formulation="exact",
        time_s=time_s,
        position_m=rows[:, :bodies],
        velocity_m_per_s=rows[:, n:n + bodies],
        bottom_m=rows[:, states][:, simulation.rock.bottom_index],
        rock_state_m=rows[:, states],
        rock_force_n=rows[:, layout.size],
        impact_force_n=impact_force,
        torsion_angle_rad=rows[:, angle] if layout.torsion else None,
        torsion_rate_rad_per_s=rows[:, angle + 1] if layout.torsion else None,
        cpu_time_s=cpu,
        works_j=works,
        solver=ExactSolverRecord(
            samples=len(time_s), sample_interval_s=solver.step_s * solver.per_sample, mode_switches=len(switch_times),
            switches_into=_switch_counts(solver.model, initial, entered), switch_times_s=switch_times,
            switch_modes=tuple(entered),  # the modes entered at each switch time
            fresh_fractions=tuple(solver.blows.fresh_fractions) if solver.blows else (),
            sub_step_s=solver.step_s, min_switch_interval_s=solver.min_switch_interval_s,
            operator_keys=solver.operators.built),
        piston=piston,
    )
