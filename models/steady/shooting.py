"""Shooting: a periodic orbit of n blows as a fixed point of the n-blow map, found by Newton's method,
with its Floquet multipliers.

On the section (models.steady.section) the orbit is z = P_n(z). Newton solves F(z) = P_n(z) - z = 0:

    (I - J) dz = F(z),   z <- z + lambda dz,

J = dP_n/dz from the map's exact Jacobian (models.steady.exact_map), from a Jacobian given by the caller
(``jacobian_of``: the exact model's at the same state, for a formulation that has none), or by forward
differences (one map run per coordinate); the exact map's own Jacobian is formed at every step (with the
compiled product, models.steady.monodromy_kernel, it costs a third of the map's run, and Newton stays
quadratic), any other after the first is updated by Broyden's rule, J += (dP - J dz) dz^T / dz^T dz. A step
that raises the scaled residual max_i |F_i| / s_i is halved (at most ``HALVINGS`` times): the map is only
piecewise smooth, and a full step from a poor guess can cross into another sequence of contacts;
``STALLED_ITERATIONS`` shortened steps in a row, or ``MAX_ITERATIONS`` steps, end the search (NoConvergence).
The last step is the first whose scaled size max_i |dz_i| / s_i is below sqrt(tolerance) / 10 with the exact
Jacobian (Newton's convergence is quadratic: the error after it is of the order of its square), below
``tolerance`` with another (a chord method converges linearly); it is taken and not checked by another map run
(the caller's run of the orbit checks it). A residual that no step lowers and that is below ``NOISE_FACTOR``
tolerances is the map's own error (a time-stepping formulation's): converged as far as it resolves. The scales
s_i are the larger of |z_i| and a floor of the coordinate's kind (:func:`scales`).

The Floquet multipliers are the eigenvalues of J at the orbit: it is stable when all lie inside the unit
circle (the drift direction, the one multiplier 1 of the full state, is not in the section). A real
multiplier through -1 is a period doubling, through +1 a fold, a complex pair through the unit circle a
torus (Neimark-Sacker) bifurcation.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from ..evaluation.stability import SimulationFailed
from ..solvers.simulation import Simulation
from .map_runs import MapRun, Switch
from .section import Section

HALVINGS = 3
TOLERANCE = 1e-10  # scaled Newton step at convergence
MAX_ITERATIONS = 12
MAX_DIFFERENCED_ITERATIONS = 6  # with forward-difference Jacobians
STALLED_ITERATIONS = 2  # Newton steps in a row that had to be shortened: given up (not in the basin)
# a residual no step lowers is the map's own error (a time-stepping formulation's) when below this many tolerances
NOISE_FACTOR = 100.0
DIFFERENCE_STEP = 1e-6  # forward-difference step, relative to each coordinate's scale


class PeriodMap(Protocol):
    """An n-blow map (models.steady.exact_map.ExactPeriodMap, models.steady.formulation_map.FormulationMap)."""

    periods: int
    period_s: float
    section: Section
    has_exact_jacobian: bool

    def __call__(self, y0: np.ndarray, jacobian: bool = True) -> MapRun: ...


class NoConvergence(Exception):
    """Newton found no orbit from the guess (the message says how far it got)."""


@dataclass(frozen=True)
class Orbit:
    """A periodic orbit of ``periods`` blows: its section state ``state`` (y with the bottom at 0), the
    bottom's ``advance_m`` over the orbit, the Floquet ``multipliers``, the ``switches`` of one orbit
    (its event sequence), how Newton got there, and the Jacobian's source."""

    periods: int
    period_s: float
    state: np.ndarray
    advance_m: float
    multipliers: np.ndarray
    switches: tuple[Switch, ...]
    iterations: int
    map_runs: int
    jacobian: str  # "exact", "finite differences", or "exact model" (another formulation's Newton matrix)

    @property
    def floquet_max_abs(self) -> float:
        """max |mu|: stable below 1."""
        return float(np.max(np.abs(self.multipliers))) if len(self.multipliers) else 0.0

    @property
    def stable(self) -> bool:
        return self.floquet_max_abs < 1.0

    @property
    def advance_per_blow_m(self) -> float:
        return self.advance_m / self.periods

    @property
    def penetration_rate_m_per_s(self) -> float:
        """The advance per n blows x f / n (exact to the orbit's round-off)."""
        return self.advance_m / (self.periods * self.period_s)

    @property
    def event_sequence(self) -> tuple[str, ...]:
        """The modes entered in order over one orbit, each as its elements' modes joined by '+'."""
        return tuple("+".join(switch.modes) for switch in self.switches)


def scales(simulation: Simulation, section: Section, z: np.ndarray) -> np.ndarray:
    """s_i = max(|z_i|, floor_i) (:func:`floors`)."""
    return np.maximum(np.abs(z), floors(simulation, section))


def floors(simulation: Simulation, section: Section) -> np.ndarray:
    """The floor of each section coordinate's scale: lengths the rock's crushing penetration (F_th / k_n;
    else 1e-4 m), velocities that length x 2 pi f, other rock states (forces) the threshold, the torsion
    angle 1e-3 rad and its rate 1e-3 rad x 2 pi f, an extension's coordinates and rates as the bodies'."""
    rock = simulation.rock
    length = rock.crushing_penetration_m if 0.0 < rock.crushing_penetration_m < math.inf else 1e-4
    omega = 2.0 * math.pi * simulation.impact.frequency_hz
    threshold = rock.threshold_n if math.isfinite(rock.threshold_n) else 1e5
    n = section.bodies
    values = [length] * n + [length * omega] * n
    values += [length if shift else threshold for shift in section.shift[2 * n:2 * n + section.rock_states]]
    values += [1e-3, 1e-3 * omega] if section.torsion else []
    values += [length] * section.extension + [length * omega] * section.extension  # as the bodies'
    return np.array(values)[section.kept]


def _eigenvalues(jacobian: np.ndarray) -> np.ndarray:
    values = np.linalg.eigvals(jacobian)
    return values[np.argsort(-np.abs(values))]


class Shooter:
    """Newton on one n-blow map (module doc); ``jacobian_of(y0)`` an approximate dY/dy0 for a map
    without an exact one (else forward differences)."""

    def __init__(self, period_map: PeriodMap, simulation: Simulation,
                 jacobian_of: Callable[[np.ndarray], np.ndarray] | None = None) -> None:
        self.map, self.simulation, self.jacobian_of = period_map, simulation, jacobian_of
        self.section = period_map.section
        self.floor = floors(simulation, self.section)
        self.runs = 0

    @property
    def jacobian_source(self) -> str:
        if self.map.has_exact_jacobian:
            return "exact"
        return "exact model" if self.jacobian_of is not None else "finite differences"

    def evaluate(self, z: np.ndarray, jacobian: bool) -> tuple[np.ndarray, float, MapRun]:
        """(P(z), the advance, the run)."""
        self.runs += 1
        run = self.map(self.section.embed(z), jacobian=jacobian)
        following, advance = self.section.reduce(run.end_state)
        if not np.all(np.isfinite(following)):
            raise SimulationFailed("the map's end state is not finite")
        return following, advance, run

    def jacobian(self, z: np.ndarray, image: np.ndarray, run: MapRun, scale: np.ndarray) -> np.ndarray:
        """dP/dz at z (``image`` = P(z), ``run`` its run)."""
        if run.monodromy is not None:
            return self.section.jacobian(run.monodromy)
        if self.jacobian_of is not None:
            return self.section.jacobian(self.jacobian_of(self.section.embed(z)))
        columns = []
        for i, step in enumerate(DIFFERENCE_STEP * scale):
            moved = z.copy()
            moved[i] += step
            columns.append((self.evaluate(moved, jacobian=False)[0] - image) / step)
        return np.column_stack(columns)

    def solve(self, guess_y: np.ndarray, tolerance: float = TOLERANCE, max_iterations: int = MAX_ITERATIONS,
              halvings: int = HALVINGS, stalled: int = STALLED_ITERATIONS) -> Orbit:
        """The orbit from the section state ``guess_y`` (module doc); NoConvergence when Newton does not
        converge within ``max_iterations`` steps, or ``stalled`` steps in a row had to be halved (at most
        ``halvings`` times each)."""
        give_up = stalled
        section, start_runs = self.section, self.runs
        exact = self.map.has_exact_jacobian
        if not exact and self.jacobian_of is None:  # a Jacobian costs a run per coordinate: fewer tries
            max_iterations = min(max_iterations, MAX_DIFFERENCED_ITERATIONS)
        final_step = 0.1 * math.sqrt(tolerance) if exact else tolerance
        z = section.reduce(guess_y)[0]
        try:
            image, advance, run = self.evaluate(z, jacobian=True)
        except SimulationFailed as err:
            raise NoConvergence(f"the guess does not run: {err}") from None
        jacobian, before, bottom_row, source, stalled = None, None, None, self.jacobian_source, 0
        for iteration in range(1, max_iterations + 1):
            scale = np.maximum(np.abs(z), self.floor)
            residual = image - z
            if run.monodromy is not None or jacobian is None or before is None:
                jacobian = self.jacobian(z, image, run, scale)
                source = self.jacobian_source
            else:  # Broyden's update along the last step: J += (dP - J dz) dz^T / dz^T dz
                moved, changed = z - before[0], image - before[1]
                jacobian = jacobian + np.outer(changed - jacobian @ moved, moved) / (moved @ moved)
                source = f"{self.jacobian_source}, updated (Broyden)"
            if run.monodromy is not None:
                bottom_row = run.monodromy[section.bottom][section.kept]
            try:
                step = np.linalg.solve(np.eye(len(z)) - jacobian, residual)
            except np.linalg.LinAlgError:
                raise NoConvergence(f"I - J is singular at iteration {iteration} (a multiplier at 1: a fold)") from None
            size = np.max(np.abs(step) / scale)
            if size < final_step:  # the step taken is the last: accepted unchecked
                if bottom_row is not None:  # the advance moved along: d(Y_bottom) = (dY_bottom / dz) dz
                    advance += float(bottom_row @ step)
                return Orbit(self.map.periods, self.map.period_s, section.embed(z + step), advance,
                             _eigenvalues(jacobian), run.switches, iteration, self.runs - start_runs, source)
            residual_size = np.max(np.abs(residual) / scale)
            halved = 0
            for _ in range(halvings + 1):
                trial = z + step
                try:
                    trial_image, trial_advance, trial_run = self.evaluate(trial, jacobian=exact)
                except SimulationFailed:
                    step = step / 2
                    halved += 1
                    continue
                if np.max(np.abs(trial_image - trial) / np.maximum(np.abs(trial), self.floor)) <= residual_size:
                    break
                step = step / 2
                halved += 1
            else:
                if residual_size < NOISE_FACTOR * tolerance:  # the map's own error: as close as it resolves
                    return Orbit(self.map.periods, self.map.period_s, section.embed(z), advance,
                                 _eigenvalues(jacobian), run.switches, iteration, self.runs - start_runs, source)
                raise NoConvergence(f"no step lowered the residual at iteration {iteration} "
                                    f"(scaled residual {residual_size:.3g})")
            stalled = stalled + 1 if halved else 0
            if stalled == give_up:
                raise NoConvergence(f"{stalled} Newton steps in a row were cut short: not in the orbit's basin "
                                    f"(scaled residual {residual_size:.3g})")
            before = (z, image)
            z, image, advance, run = trial, trial_image, trial_advance, trial_run
        raise NoConvergence(f"no convergence in {max_iterations} Newton steps "
                            f"(scaled residual {np.max(np.abs(image - z) / scales(self.simulation, section, z)):.3g})")
