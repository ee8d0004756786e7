"""The n-blow map of the exact formulation and its exact Jacobian.

The model is linear between switches (models.solvers.exact_model): w' = A_k w on every piece k of a run.
A run of n blow periods from the section state y0 (models.steady.section) by the exact solver gives the
end state Y(y0) and the pieces: the key k (modes, pulse phase) and length of each, and every switch
between them. Its Jacobian (the monodromy matrix) is the ordered product

    dY/dy0 = ... S_j expm(A_k dt_k) ... S_1 expm(A_1 dt_1)

of the pieces' matrix exponentials and, at each switch j where the exit function g = c . w crosses zero,
the saltation matrix (the first-order effect of the switch time moving with the state)

    S = M + (f+ - M f-) c^T / (c . f-),    f- = A_old w-,  f+ = A_new M w-,

M the switch's entry reset (the identity with the reset rows of the states the new mode sets; the
never-decreasing bottom keeps its row unless the reset raises it). A pulse phase boundary is at a fixed
time and keeps the state: no saltation. Blow-start resets (an indexed rock, a piston's strike) are
functions of the state the kernel applies outside the pieces: a map with them has no exact Jacobian here
(``has_exact_jacobian`` False) and the caller differentiates it by finite differences.
"""

from __future__ import annotations

import numpy as np

from ..drill.piston import PistonJumps
from ..drill.pulse import PHASES
from ..evaluation.results import SimulationResult
from ..solvers.exact_model import ANCHORS, PER_ANCHOR, ExactSolver, solver_result
from ..solvers.exact_system import Modes
from ..solvers.simulation import Simulation
from .map_runs import MapRun, Switch, started_at
from .section import Section, physical_state, section_of


def augmented(simulation: Simulation, y: np.ndarray, size: int) -> np.ndarray:
    """The exact solver's augmented state w (models.solvers.exact_system.Layout) from a section state y:
    a piston's bodies parked (its strike at the blow start sets them), the constant 1, the pulse states
    (the kernel sets them at each phase start)."""
    n, dynamic = simulation.chain.size, simulation.dynamic_chain.size
    w = np.zeros(size)
    x = y[:n]
    w[:dynamic] = x if simulation.piston is None else simulation.piston.parked(x)
    w[dynamic:dynamic + n] = y[n:2 * n]
    tail = len(y) - 2 * n
    w[2 * dynamic:2 * dynamic + tail] = y[2 * n:]
    w[size - 3] = 1.0
    return w


class ExactPeriodMap:
    """Y(y0) over ``periods`` blows of ``simulation`` by the exact solver, with dY/dy0 (module doc). Its
    products are small: call it with a single-threaded BLAS (models.solvers.exact_model.BLAS)."""

    def __init__(self, simulation: Simulation, periods: int, shared: ExactPeriodMap | None = None) -> None:
        self.simulation, self.periods = simulation, periods
        self.period_s = simulation.impact.period_s
        self.section: Section = section_of(simulation)
        if shared is not None:  # one solver, its operators and the matrices for maps of any length
            self.solver = shared.solver if shared.simulation is simulation else \
                shared.solver.with_frequency(simulation, periods * self.period_s)
            self._matrices, self._modes, self._series, self._switches, self._blocks = (
                shared._matrices, shared._modes, shared._series, shared._switches, shared._blocks)
        else:
            self.solver = ExactSolver(simulation)
            self._matrices: dict[int, np.ndarray] = {}
            self._modes: dict[int, tuple[Modes, str]] = {}
            self._series: dict[int, np.ndarray] = {}
            self._blocks: dict[int, np.ndarray] = {}
            self._switches: dict[tuple[Modes, Modes], tuple[np.ndarray, list[np.ndarray], list]] = {}
        self.has_exact_jacobian = not (self.solver.blows or self.solver.piston)
        self._columns: np.ndarray | None = None

    def of_periods(self, periods: int) -> ExactPeriodMap:
        """The map of ``periods`` blows on the same solver."""
        return ExactPeriodMap(self.simulation, periods, shared=self)

    def result(self, y0: np.ndarray, blows: int, cpu_start: float,
               jacobian: bool = True) -> tuple[SimulationResult, MapRun]:
        """The scene's result of a run of ``blows`` periods from y0 (models.steady.map_runs.started_at: the
        metrics' window those blows), by this map's solver, and that run as a map run (its end state, and with
        ``jacobian`` dY/dy0 where exact)."""
        ran = self._run(y0, blows)
        monodromy = self._monodromy(*ran[:2]) if jacobian and self.has_exact_jacobian else None
        end = physical_state(self.simulation, ran[1][-1, :self.solver.layout.size])
        result = solver_result(self.solver, started_at(self.simulation, y0, blows), cpu_start, ran=ran)
        return result, MapRun(end, monodromy, ())

    def _run_setup(self, blows: int) -> None:
        """The solver set for a run of ``blows`` periods (fresh blow-start trackers: it starts at a blow)."""
        solver, simulation = self.solver, self.simulation
        solver.blows = simulation.blow_starts()
        if solver.piston is not None:
            solver.piston = PistonJumps(simulation.piston)
        if solver.end_time_s != blows * self.period_s:
            solver.retime(blows * self.period_s)

    def _run(self, y0: np.ndarray, blows: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[Modes]]:
        """The solver's run of ``blows`` periods from y0."""
        self._run_setup(blows)
        return self.solver.run(augmented(self.simulation, y0, self.solver.layout.size))

    def __call__(self, y0: np.ndarray, jacobian: bool = True) -> MapRun:
        """Y(y0) and, with ``jacobian`` where it is exact, dY/dy0; SimulationFailed where the run fails."""
        time_s, rows, switch_times, entered = self._run(y0, self.periods)
        monodromy = self._monodromy(time_s, rows) if jacobian and self.has_exact_jacobian else None
        switches = tuple(Switch(float(t), modes) for t, modes in zip(switch_times, entered, strict=True))
        return MapRun(physical_state(self.simulation, rows[-1, :self.solver.layout.size]), monodromy, switches)

    def blow_states(self, y0: np.ndarray, blows: int) -> list[np.ndarray]:
        """y at every blow start of one run of ``blows`` periods from y0 (before that blow's resets; the
        last one the run's end)."""
        time_s, rows, _, _ = self._run(y0, blows)
        starts = np.arange(1, blows) * self.period_s
        first = np.minimum(np.searchsorted(time_s, starts * (1 - 1e-12)), len(time_s) - 1)
        size = self.solver.layout.size
        return [physical_state(self.simulation, rows[i, :size]) for i in [*first.tolist(), len(time_s) - 1]]

    def matrix(self, key: int) -> np.ndarray:
        """A of an operator key of the solver."""
        if key not in self._matrices:
            modes, phase = self.key_modes(key)
            self._matrices[key] = self.solver.model.matrix(modes, phase)
        return self._matrices[key]

    def propagator(self, key: int, length_s: float) -> np.ndarray:
        """expm(A t) of a key from the solver's cached operators (models.solvers.exact_model): with E =
        expm(A h) and t = (q A B + j) h + s, s < h, it is sum_k s^k A^k / k! E^j (E^(A B))^q, E^j from the
        anchors E^(a B) and powers E^b (b < B), the series from the Taylor matrices, (E^(A B))^q by
        squaring."""
        ops, size = self.solver.operators, self.solver.layout.size
        h, width = ops.step_s, ops.width
        steps = int(length_s // h)
        rest = length_s - steps * h
        if rest < 0.0:
            steps, rest = steps - 1, rest + h
        if key not in self._series:  # A^k / k! flattened, one row per k
            terms = ops.taylor[key].reshape(size, -1, width)[:, :, :size]  # (A^k / k!)^T as [c, k, r]
            self._series[key] = np.ascontiguousarray(terms.transpose(1, 2, 0).reshape(-1, size * size))
        series = self._series[key]
        result = (rest ** np.arange(len(series)) @ series).reshape(size, size)  # sum_k s^k A^k / k!
        whole, part = divmod(steps, ANCHORS * PER_ANCHOR)
        anchor, power = divmod(part, PER_ANCHOR)
        if anchor:
            result = result @ ops.anchors[key][:, anchor * size:(anchor + 1) * size].T
        if power:
            result = result @ ops.readout[key][:, power * width:power * width + size].T
        if whole:
            if key not in self._blocks:  # E^(A B) = E^((A - 1) B) E^B
                anchors = ops.anchors[key]
                self._blocks[key] = anchors[:, (ANCHORS - 1) * size:ANCHORS * size].T @ anchors[:, size:2 * size].T
            block = self._blocks[key]
            while whole:
                if whole & 1:
                    result = result @ block
                whole >>= 1
                if whole:
                    block = block @ block
        return result

    def key_modes(self, key: int) -> tuple[Modes, str]:
        """(modes, phase) of an operator key."""
        if key not in self._modes:
            ops = self.solver.operators
            mode_id, phase_id = np.argwhere(ops.key_of == key)[0]
            self._modes[key] = ops.modes[mode_id], PHASES[phase_id]
        return self._modes[key]

    def _saltated(self, product: np.ndarray, key_before: int, key_after: int, w_before: np.ndarray,
                  w_after: np.ndarray) -> np.ndarray:
        """S product for the switch from key_before's modes into key_after's (module doc), without forming S:
        M product + (f+ - M f-) (c . product) / (c . f-)."""
        modes = self.key_modes(key_before)[0], self.key_modes(key_after)[0]
        if modes not in self._switches:  # the exit row and the reset matrices (the bottom's row reset or kept)
            model = self.solver.model
            exits = [exit_ for exit_ in model.exits(modes[0]) if exit_[2] == modes[1]]
            if not exits:
                raise ValueError(f"no exit from {modes[0]} into {modes[1]}")
            row, resets = exits[0][0], exits[0][3]
            monotone = model.pieces[0].monotone
            both = []
            for keep_bottom in (False, True):
                reset = np.eye(len(w_before))
                for target, reset_row in resets:
                    if not (keep_bottom and target == monotone):
                        reset[target] = reset_row
                both.append(reset)
            raised = [(target, reset_row) for target, reset_row in resets if target == monotone]
            self._switches[modes] = row, both, raised
        row, (resetting, keeping), raised = self._switches[modes]
        reset = keeping if raised and raised[0][1] @ w_before < w_before[raised[0][0]] else resetting
        before = self.matrix(key_before) @ w_before
        jump = self.matrix(key_after) @ w_after - reset @ before
        return reset @ product + np.outer(jump / (row @ before), row @ product)

    def _monodromy(self, time_s: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """dY/dy0 as the product over the run's pieces and switches (module doc)."""
        solver, simulation = self.solver, self.simulation
        keys, size = solver.row_keys, solver.layout.size
        if self._columns is None:  # dw/dy0: the section's entries placed in w
            n, dynamic, d = simulation.chain.size, simulation.dynamic_chain.size, self.section.size
            columns = np.zeros((size, d))
            columns[:n, :n] = columns[dynamic:dynamic + n, n:2 * n] = np.eye(n)
            columns[2 * dynamic:2 * dynamic + d - 2 * n, 2 * n:] = np.eye(d - 2 * n)
            self._columns = columns
        product = self._columns
        # the zero-length intervals (a switch: both sides recorded; a phase boundary) cut the run into pieces
        # of one key each
        jumps = np.flatnonzero(np.diff(time_s) <= 0.0)
        start = 0
        for i in (*jumps.tolist(), len(time_s) - 1):
            if i > start:
                product = self.propagator(keys[start], time_s[i] - time_s[start]) @ product
            if i < len(time_s) - 1 and self.key_modes(keys[i])[0] != self.key_modes(keys[i + 1])[0]:  # a switch
                product = self._saltated(product, keys[i], keys[i + 1], rows[i, :size], rows[i + 1, :size])
            start = i + 1
        return physical_state(simulation, product)


_LAST: list[tuple[tuple, ExactPeriodMap]] = []  # the last map made in this process, by what its operators depend on


def _operators_key(simulation: Simulation) -> tuple:
    """What the exact solver's matrices, sub-step and operators depend on: all but the impact frequency, the
    end time and the start (the chain with a piston's bodies, the rock law as built, the torsion line, the
    pulse's amplitude, shape and duration, the settings, the data recorded, the piston, the indexing)."""
    impact, settings = simulation.impact, simulation.settings
    return (simulation.dynamic_chain, simulation.rock, simulation.torsion,
            (impact.amplitude_n, impact.shape, impact.duration_s, impact.piston),
            tuple(value for name, value in vars(settings).items() if name != "end_time_s"), simulation.outputs,
            simulation.piston, simulation.indexing)


def exact_period_map(simulation: Simulation, periods: int = 1) -> ExactPeriodMap:
    """The exact n-blow map of ``simulation``; on the solver of the last map made in this process when the
    two differ in the impact frequency only (ExactSolver.with_frequency: the next point of a frequency scan
    reuses the operators)."""
    key = _operators_key(simulation)
    if _LAST and _LAST[0][0] == key:
        made = ExactPeriodMap(simulation, periods, shared=_LAST[0][1])
    else:
        made = ExactPeriodMap(simulation, periods)
    _LAST[:] = [(key, made)]
    return made
