"""The steady regime of a scene: a stable periodic orbit of 1 or n blows, or none found.

1. From a guess (a neighbour's orbit in a continuation, else the state after the scene's
   ``metrics.transient_blows`` blows from its start), Newton on the map of the guess's blows (one without a
   neighbour; models.steady.shooting). A stable orbit is the regime (``period-1``, ``period-n``). Where
   Newton fails from a neighbour's orbit, the drill is run on from that orbit for ``RUN_ON_BLOWS`` blows
   (by the map, no Jacobian) and read as in step 2, Newton from its last blow start: the neighbour's orbit
   lies nearer the attractor than the drill at rest, and a short run from it costs a fraction of the time
   run that step 2 needs.
2. Otherwise (no convergence, or an unstable orbit, which a drill never shows: its rate is not reported)
   the scene's own time run (what ``steady_state: time`` runs) says, from the section states of its last
   blows, which period n <= ``MAX_PERIOD_BLOWS`` repeats best (:func:`repeating_period`), Newton on the
   one-blow map, then on the n-blow map, from its last blow start where that repeats within ``NEWTON_TRY``; where none repeats within
   ``REPEAT_TOLERANCE`` the drill is run on as many blows again from its end (by the exact map) and read
   again, Newton from its last blow start. A stable orbit is ``period-n``. A periodic run costs at most
   about two time runs more than a time run.
3. Otherwise ``no periodic orbit found``: the result is that time run (models.runs.scene_run), and the
   unstable orbits found are kept for the report.

A guess from a neighbour follows the branch it is on: where two stable orbits coexist (hysteresis), a
continuation stays on its branch while the time run from the scene's start may settle on the other
(models.steady.continuation follows a scan from both ends); :meth:`RegimeFinder.check_start` says where the
start goes (models.steady.start_check).

The exact formulation has the exact Jacobian. The ODE and Exudyn formulations shoot with their own time
runs (models.steady.formulation_map); where the exact formulation can run the scene, its regime comes first
and its orbit is their guess, its Jacobian their first Newton matrix (an approximation of the other
formulation's by the same model, then updated by Broyden's rule), else their Jacobian is taken by forward
differences.
"""

from __future__ import annotations

import math
import time
from dataclasses import replace

import numpy as np

from ..evaluation.results import SimulationResult
from ..evaluation.stability import SimulationFailed
from ..solvers.simulation import Simulation, prepare, unsupported
from ..solvers.time_run import time_run
from .exact_map import ExactPeriodMap, exact_period_map
from .extension_section import with_extension_coordinates
from .formulation_map import FormulationMap
from .map_runs import end_state, started_at, states_at
from .section import drift_problem, section_of
from .shooting import TOLERANCE, NoConvergence, Orbit, PeriodMap, Shooter, scales
from .start_check import check_start
from .steady_state import NONE_FOUND, SteadyState, SteadyStateUnavailable, regime_name

MAX_PERIOD_BLOWS = 6  # the longest orbit looked for, in blows
REPEAT_TOLERANCE = 0.05  # scaled distance of section states n blows apart under which Newton is tried
NEWTON_TRY = 1.0  # ... and tried before running on, from the time run's own last blow
EXUDYN_TOLERANCE = 1e-8
REPEATS_WITHIN = 1e-6  # scaled distance under which an n-blow orbit's state repeats after fewer blows
RUN_ON_BLOWS = 2 * MAX_PERIOD_BLOWS + 1  # blows run on from a neighbour's orbit where Newton failed from it: the
# fewest that show every period up to MAX_PERIOD_BLOWS twice (repeating_period)


def newton_tolerance(simulation: Simulation) -> float:
    """The scaled Newton step at convergence: round-off level for the exact map (shooting.TOLERANCE); a
    time-stepping formulation's map carries its own error: ten times its relative tolerance (ode), 1e-8
    (exudyn: a fixed step, deterministic, its time-discrete contact only piecewise smooth in the state)."""
    settings = simulation.settings
    if settings.formulation == "exact":
        return TOLERANCE
    if settings.formulation == "ode":
        return max(TOLERANCE, 10.0 * settings.relative_tolerance)
    return EXUDYN_TOLERANCE


def exact_available(simulation: Simulation) -> bool:
    """Whether the exact formulation runs this scene (its matrices and exits declared, no extension that
    changes the motion: the exact model of a scene with a clamp of one's own would be another drill)."""
    return unsupported("exact", simulation) is None


def as_exact(simulation: Simulation) -> Simulation:
    """The simulation prepared for the exact formulation (the same scene and start)."""
    exact = prepare(simulation.scene.with_solver("exact"))
    return replace(exact, initial_positions_m=simulation.initial_positions_m,
                   initial_velocities_m_per_s=simulation.initial_velocities_m_per_s,
                   initial_rock_state=simulation.initial_rock_state,
                   initial_torsion_angle_rad=simulation.initial_torsion_angle_rad,
                   initial_torsion_rate_rad_per_s=simulation.initial_torsion_rate_rad_per_s)


def make_map(simulation: Simulation, periods: int) -> PeriodMap:
    """The n-blow map of the simulation's formulation."""
    if simulation.settings.formulation == "exact":
        return exact_period_map(simulation, periods)
    return FormulationMap(simulation, periods)


def start_state(simulation: Simulation) -> np.ndarray:
    """y at the simulation's start (rest or preloaded)."""
    section = section_of(simulation)
    n = section.bodies
    torsion = [simulation.initial_torsion_angle_rad, simulation.initial_torsion_rate_rad_per_s] if section.torsion else []
    followed = simulation.extension_coordinates
    extension = [] if followed is None else followed.start
    return np.concatenate([simulation.initial_positions_m[:n], simulation.initial_velocities[:n],
                           simulation.initial_rock_state, torsion, extension])


def repeating_period(simulation: Simulation, states: list[np.ndarray], longest: int = MAX_PERIOD_BLOWS
                     ) -> tuple[int, float]:
    """(n, distance): the n <= ``longest`` whose section states n blows apart are closest over the last
    ``longest`` blows (at least 2 ``longest`` + 1 states; scaled: models.steady.shooting.scales), the
    smallest n within twice the best distance."""
    section = section_of(simulation)
    relative = [section.reduce(y)[0] for y in states]
    scale = scales(simulation, section, np.max(np.abs(relative[-2 * longest:]), axis=0))
    distances = []
    for n in range(1, longest + 1):
        pairs = range(len(relative) - longest, len(relative))
        distances.append(max(np.max(np.abs(relative[k] - relative[k - n]) / scale) for k in pairs))
    best = min(distances)
    n = next(i for i, d in enumerate(distances, start=1) if d <= 2 * best)
    return n, distances[n - 1]


class RegimeFinder:
    """Finds the regime of one simulation (module doc)."""

    def __init__(self, simulation: Simulation) -> None:
        if simulation.dynamic_chain.waves:
            raise SteadyStateUnavailable(
                f"scene '{simulation.name}': its wave rods carry their state in the waves in flight (a history "
                "over each transit time), not in a state vector a period map could shoot on; the time run")
        problem = drift_problem(simulation)
        if problem:
            raise SteadyStateUnavailable(problem)
        simulation = with_extension_coordinates(simulation)  # an Exudyn scene's extensions' coordinates
        self.simulation, self.section = simulation, section_of(simulation)
        self.exact = simulation.settings.formulation == "exact"
        # the exact model guides where it runs the scene and the section is its own (not where an extension
        # said to change no motion still adds coordinates: the exact model does not hold them)
        self.guide = None if self.exact or not exact_available(simulation) or simulation.extension_coordinates \
            else RegimeFinder(as_exact(simulation))
        self.maps: dict[int, PeriodMap] = {}
        self.runs = 0
        self.unstable: list[Orbit] = []

    def map(self, periods: int) -> PeriodMap:
        if periods not in self.maps:
            first = self.maps.get(1)
            self.maps[periods] = first.of_periods(periods) if isinstance(first, ExactPeriodMap) else \
                make_map(self.simulation, periods)
        return self.maps[periods]

    def shoot(self, periods: int, guess: np.ndarray, patient: bool = False) -> Orbit | None:
        """The orbit of ``periods`` blows from ``guess`` (unstable ones kept aside), None if Newton fails;
        ``patient``: from a settled state, more steps and more halvings (models.steady.shooting)."""
        jacobian_of = None
        if self.guide is not None:
            guide_map = self.guide.map(periods)
            jacobian_of = lambda y: guide_map(y).monodromy  # the exact model's Jacobian at y
        shooter = Shooter(self.map(periods), self.simulation, jacobian_of)
        try:
            orbit = shooter.solve(guess, newton_tolerance(self.simulation),
                                  **({"max_iterations": 20, "halvings": 6, "stalled": 4} if patient else {}))
        except NoConvergence:
            return None
        finally:
            self.runs += shooter.runs
        shorter = self._minimal_period(orbit)
        if shorter is not None:  # a fixed point of the n-blow map that repeats after d blows: a d-blow orbit
            return self.shoot(shorter, orbit.state)
        if not orbit.stable:
            self.unstable.append(orbit)
            return None
        return orbit

    def _minimal_period(self, orbit: Orbit) -> int | None:
        """The smallest d < n (a divisor) after which the n-blow orbit's section state repeats (scaled within
        REPEATS_WITHIN), None if none: the orbit's own period is n."""
        n = orbit.periods
        divisors = [d for d in range(1, n) if n % d == 0]
        if not divisors:
            return None
        self.runs += 1
        states = self.map(1).blow_states(orbit.state, max(divisors))
        start = self.section.reduce(orbit.state)[0]
        scale = scales(self.simulation, self.section, start)
        return next((d for d in divisors
                     if np.max(np.abs(self.section.reduce(states[d - 1])[0] - start) / scale) < REPEATS_WITHIN), None)

    def warm_state(self) -> np.ndarray:
        """y after the scene's transient blows from its start (at least one)."""
        blows = max(1, self.simulation.scene.metrics.transient_blows)
        self.runs += 1
        return self.map(1).blow_states(start_state(self.simulation), blows)[-1]

    def find(self, guess: np.ndarray | None = None, periods: int = 1) -> SteadyState:
        """Step 1 (module doc): Newton from ``guess`` (a section state of an orbit of ``periods`` blows), or
        from the state after the transient blows; the exact guide first for another formulation."""
        start = time.process_time()
        guide = None
        if self.guide is not None:
            guide = self.guide.find(guess, periods)
            if guide.orbit is None:  # the same model, nearly: its time run settles it (step 2)
                return SteadyState(NONE_FOUND, None, guide.unstable, "", self.runs, time.process_time() - start)
            guess, periods = guide.orbit.state, guide.orbit.periods
        try:
            orbit = self.shoot(periods, self.warm_state() if guess is None else guess)
            if orbit is None and guess is not None:  # run on from the neighbour's orbit (module doc, step 1)
                self.runs += 1
                orbit = self._from_blows(self.map(1).blow_states(guess, RUN_ON_BLOWS * periods), NEWTON_TRY)
        except SimulationFailed:
            orbit = None
        return self._state(orbit, start, guide)

    def _from_blows(self, states: list[np.ndarray], within: float) -> Orbit | None:
        """Newton from the last of ``states`` (y at successive blow starts) on one blow, then on the period
        n that repeats best over them, where it repeats within ``within`` (scaled; the distance kept for the
        note); None if neither converges to a stable orbit."""
        n, self.distance = repeating_period(self.simulation, states, min(MAX_PERIOD_BLOWS, (len(states) - 1) // 2))
        if self.distance > within:
            return None
        for periods in dict.fromkeys((1, n)):  # first (a transient's ringing can look like another period)
            orbit = self.shoot(periods, states[-1])
            if orbit is not None:
                return orbit
        return None

    def settled(self, time_run: SimulationResult, found: SteadyState) -> SteadyState:
        """Step 2 (module doc): the period that repeats best over the last blows of ``time_run`` (the scene's
        time run), Newton on its map from the last blow start."""
        start = time.process_time()
        period_s = self.simulation.impact.period_s
        blows = math.floor(time_run.time_s[-1] / period_s + 1e-9)
        longest = min(MAX_PERIOD_BLOWS, blows // 2 - 1)
        if longest < 1:
            return found
        states = states_at(time_run, np.arange(blows - 2 * longest, blows + 1) * period_s)
        n, self.distance = repeating_period(self.simulation, states, longest)
        if REPEAT_TOLERANCE < self.distance <= NEWTON_TRY:  # near enough for Newton's basin, perhaps: one blow
            for periods in dict.fromkeys((1, n)):  # first (a transient's ringing can look like another period)
                try:
                    orbit = self.shoot(periods, states[-1], patient=True)
                except SimulationFailed:
                    orbit = None
                if orbit is not None:
                    return self._state(orbit, start, None)
        if self.distance > REPEAT_TOLERANCE:  # run on from its end (the exact guide's map for another formulation)
            settle = (self.guide or self).map(1)
            self.runs += 1
            more = max(blows, 2 * MAX_PERIOD_BLOWS + 1)
            try:
                states = settle.blow_states(states[-1], more)
            except SimulationFailed:
                return found
            n, self.distance = repeating_period(self.simulation, states, MAX_PERIOD_BLOWS)
            self.settled_blows = more
        orbit = None
        if self.distance <= REPEAT_TOLERANCE:
            try:
                orbit = self.shoot(n, states[-1], patient=True)
            except SimulationFailed:
                pass
        state = self._state(orbit, start, None)
        return replace(state, cpu_time_s=state.cpu_time_s + found.cpu_time_s)

    def _state(self, orbit: Orbit | None, start: float, guide: SteadyState | None) -> SteadyState:
        regime = NONE_FOUND if orbit is None else regime_name(orbit.periods)
        note = "" if orbit is not None else self._why_none()
        return SteadyState(regime, orbit, tuple(self.unstable), note, self.runs, time.process_time() - start,
                           None if guide is None else guide.orbit)

    def result(self, orbit: Orbit, cpu_start: float) -> tuple[SimulationResult, np.ndarray]:
        """The scene's run over the orbit (models.steady.map_runs.started_at), by the map's own solver where
        it is the exact formulation's, and the run's end state y."""
        periodic = self.map(orbit.periods)
        if isinstance(periodic, ExactPeriodMap):
            return periodic.result(orbit.state, orbit.periods, cpu_start)
        result = time_run(started_at(self.simulation, orbit.state, orbit.periods))
        return result, end_state(result)

    def check_start(self, state: SteadyState) -> SteadyState:
        """``state`` with where the drill goes from the scene's start beside its orbit (models.steady.start_check),
        by the exact model (the scene's, or the one guiding another formulation, against its orbit); unchanged
        without an orbit or where the exact model does not run the scene."""
        finder = self if self.exact else self.guide
        orbit = state.orbit if self.exact else state.exact_guide or state.orbit
        if finder is None or orbit is None:
            return state
        self.runs += 1
        try:
            checked = check_start(finder.map(1), finder.simulation, finder.section, start_state(finder.simulation),
                                  orbit, lambda states: repeating_period(finder.simulation, states, MAX_PERIOD_BLOWS),
                                  finder.shoot)
        except SimulationFailed:
            return state
        return replace(state, start=checked)

    def _why_none(self) -> str:
        distance = getattr(self, "distance", None)
        more = getattr(self, "settled_blows", 0)
        settled = "" if distance is None else (
            f"over the time run's last blows{f' and {more} blows more' if more else ''} no period up to "
            f"{MAX_PERIOD_BLOWS} blows repeats within {REPEAT_TOLERANCE:g} (closest {distance:.2g})")
        unstable = "; ".join(f"an unstable period-{o.periods} orbit (|mu|max {o.floquet_max_abs:.4g}, advance per "
                             f"blow {o.advance_per_blow_m:.4g} m: not the drill's rate)" for o in self.unstable)
        return "; ".join(part for part in (settled, unstable) if part) or "Newton did not converge"


def steady_state(simulation: Simulation, guess: np.ndarray | None = None, periods: int = 1) -> SteadyState:
    """The steady regime of ``simulation`` (module doc: step 1, and step 2 on the scene's time run where
    step 1 finds no stable orbit); ``guess``: a section state of an orbit of ``periods`` blows (a
    neighbour's, in a continuation). SteadyStateUnavailable for a scene with no orbit relative to the
    bottom."""
    finder = RegimeFinder(simulation)
    found = finder.find(guess, periods)
    return found if found.orbit is not None else finder.settled(time_run(simulation), found)
