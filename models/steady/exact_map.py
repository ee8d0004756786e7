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
from ..evaluation.results import SimulationResult
from ..solvers.exact_model import ANCHORS, PER_ANCHOR, ExactSolver, solver_result
from ..solvers.exact_system import Modes
from ..solvers.simulation import Simulation
from .map_runs import MapRun, Switch, started_at
from .monodromy_kernel import NO_EXIT, monodromy
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
        if shared is not None:  # one solver and its operators for maps of any length
            self.solver = shared.solver if shared.simulation is simulation else \
                shared.solver.with_frequency(simulation, periods * self.period_s)
        else:
            self.solver = ExactSolver(simulation)
        self.has_exact_jacobian = not (self.solver.blows or self.solver.piston)
        self._columns: np.ndarray | None = None
        self._modes_of_keys: np.ndarray | None = None

    def of_periods(self, periods: int) -> ExactPeriodMap:
        """The map of ``periods`` blows on the same solver."""
        return ExactPeriodMap(self.simulation, periods, shared=self)

    def result(self, y0: np.ndarray, blows: int, cpu_start: float) -> tuple[SimulationResult, np.ndarray]:
        """The scene's result of a run of ``blows`` periods from y0 (models.steady.map_runs.started_at: the
        metrics' window those blows), by this map's solver, and that run's end state y."""
        ran = self._run(y0, blows)
        end = physical_state(self.simulation, ran[1][-1, :self.solver.layout.size])
        return solver_result(self.solver, started_at(self.simulation, y0, blows), cpu_start, ran=ran), end

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

    def _key_modes(self) -> np.ndarray:
        """The mode id of every key built so far (ops.key_of inverted)."""
        ops = self.solver.operators
        if self._modes_of_keys is None or len(self._modes_of_keys) != ops.built:
            modes = np.full(ops.built, -1, dtype=np.int64)
            mode_ids, phase_ids = np.nonzero(ops.key_of >= 0)
            modes[ops.key_of[mode_ids, phase_ids]] = mode_ids
            self._modes_of_keys = modes
        return self._modes_of_keys

    def _monodromy(self, time_s: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """dY/dy0 as the product over the run's pieces and switches (module doc;
        models.steady.monodromy_kernel)."""
        solver, simulation = self.solver, self.simulation
        ops, size = solver.operators, solver.layout.size
        if self._columns is None:  # dw/dy0: the section's entries placed in w
            n, dynamic, d = simulation.chain.size, simulation.dynamic_chain.size, self.section.size
            columns = np.zeros((size, d))
            columns[:n, :n] = columns[dynamic:dynamic + n, n:2 * n] = np.eye(n)
            columns[2 * dynamic:2 * dynamic + d - 2 * n, 2 * n:] = np.eye(d - 2 * n)
            self._columns = columns
        monotone = solver.model.pieces[0].monotone
        product = np.empty_like(self._columns)
        status = monodromy(self._columns, time_s, rows, solver.row_keys, self._key_modes(), ops.taylor, ops.anchors,
                           ops.readout, ops.exit_counts, ops.next_modes, ops.reset_counts, ops.reset_targets,
                           ops.reset_rows, -1 if monotone is None else monotone, ops.step_s, ANCHORS, PER_ANCHOR,
                           product)
        if status == NO_EXIT:
            raise ValueError(f"scene '{simulation.name}': a switch of the run between modes with no exit between them")
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
