"""The operating point that maximises a metric within bounds (``rpdrill advise``).

The point lies in the operating parameters of :data:`PARAMETERS` (data: a scene path each, shown
through studies.display.catalogue; adding one, e.g. a rotation speed, is one entry): the impact frequency
and the feed force, and optionally the impact amplitude. The metric is the penetration rate, or
the penetration per joule of impact energy, or the penetration per joule of blow energy (a piston
scene: the penetration rate per unit hammer power; models.evaluation.metrics).

* **Fixed hammer power** (``power_w``, a piston scene): at every point the blow energy follows from
  the frequency, E_blow = P / f (``impact.piston.energy_j``; the strike speed follows from it), so the
  search trades frequency against blow energy at the hammer's rated power P = E_blow f. A top
  hammer's rate is jagged along the frequency there (each blow meets the string's ringing from the
  last at another phase).

* **The best is the best point run**: the points of the curves and the map are candidates too (a search on
  a small budget may stop short of a point its own curves pass through): where one beats the search's best
  it becomes the optimum (``Advice.search_best_value`` keeps the search's own), and the curves (and the map,
  when a parameter beside feed and frequency moved) are run again through it, until none beats it.

* **Runs**: the exact formulation where it can run the scene (models.definition.formulations.unsupported),
  the Exudyn model otherwise; the scene's end time, raised where needed so that the metrics'
  transient and block blows fit at the lowest frequency. A run that fails counts as 0.
* **Static limit**: a point whose mean thrust, feed plus blow frequency x impulse per blow
  (models.solvers.simulation.Simulation.mean_thrust_n), reaches the rock's threshold F_th (or
  ``max_thrust_ratio`` x F_th) is not run: there a Jenkins rock yields under the mean load and the
  bit sinks at a rate set only by the rock damper (runaway crushing, outside what the model
  describes). The search treats it as a constraint: such a point is worse than any point below the
  limit, the more the further beyond. So is a point whose rods exceed a stress bound; where no point run
  meets the bound there is no advice: :class:`NoAllowedPoint` (``rpdrill advise`` exits 1), never the
  search's penalty as a rate.
* **AdviceSearch**: SciPy's differential evolution over the box of the bounds (best1bin, a population
  of ``popsize`` x parameters, at most ``max_generations`` generations, seeded; no gradient
  polish: the metric has steps where crushing starts). Each generation's population is one batch
  on the runner (studies.runtime.pools), every run a one-point curve (studies.scan.curves: the point is the
  scene with the operating parameters, ``Scene.with_``).
* **Around the optimum**: the metric along each parameter across its bounds with the others at
  the optimum (``SLICE_POINTS`` points and the optimum itself) and the interval where it stays at
  or above 80 % of the optimum (studies.scan.curve_optima.band).
* **Feed x frequency map**: the metric on a ``MAP_POINTS`` x ``MAP_POINTS`` grid of feed force and
  impact frequency (others at the optimum). Percussive drilling has an optimum feed force in
  experiments (the rate rises, then falls, as the feed grows); :func:`feed_response` reads from the
  map, frequency by frequency, whether the model has one.
* **Resumable**: with an :class:`~rpdrill.studies.runtime.evaluation_log.EvaluationLog`, every point
  run is recorded as its run returns; a rerun of the same advice into the same folder replays the
  recorded points (the seeded search retraces its path) and runs only the rest.
"""

from __future__ import annotations

import dataclasses
import hashlib
import itertools
import json
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from pydantic import BaseModel, ConfigDict
from scipy import optimize

from ...models.definition.scene import Scene
from ...models.definition.validation import InputError
from ...models.solvers.simulation import SceneError, Simulation, prepare, unsupported
from ...rocklaw.catalog import TABLE_1
from ..display.catalogue import describe_scene, parameter
from ..runtime.evaluation_log import EvaluationLog
from ..runtime.pools import Runner
from ..scan.curve_optima import band
from ..scan.curves import Curve, run_curve
from .advice_records import Advice, AdviceSearch, Bounds, Point

FREQUENCY, FEED = "impact.frequency_hz", "feed.force_n"
STRESS = "rod_stress_max_pa"  # the rods' largest stress (models.evaluation.rod_outputs), a --max-rod-stress-mpa bound's
METRICS = ("penetration_rate_m_per_s", "penetration_per_impact_energy_m_per_j", "penetration_per_blow_energy_m_per_j")
SLICE_POINTS = 15
MAP_POINTS = 12
MAX_PROMOTIONS = 5  # rounds of curves through a better point (module doc: the best is the best point run)
IMPLAUSIBLE = 10  # a feed bound this many times every rock's threshold force is a unit mistake (N for kN)


@dataclass(frozen=True)
class AdviseParameter:
    """An operating parameter: its short ``name`` (the command-line option is ``--NAME-UNIT`` in the
    catalogue's display unit), its scene path, and whether every search needs its bounds."""

    name: str
    path: str
    required: bool

    @property
    def option(self) -> str:
        """'--frequency-hz', '--feed-kn'."""
        return f"--{self.name}-{parameter(self.path).unit.lower().replace('/', '-per-').replace(' ', '-')}"

    def si_bounds(self, given: tuple[float, float]) -> tuple[float, float]:
        """Bounds given in display units as SI values; InputError unless low < high."""
        low, high = given
        shown = f"{self.option} {low:g} {high:g}"
        if not (math.isfinite(low) and math.isfinite(high)):
            raise InputError(f"{shown}: the bounds must be finite numbers")
        if not low < high:
            raise InputError(f"{shown}: the lower bound must be below the upper bound")
        if low < 0 or (low == 0 and self.path != FEED):
            allowed = "zero or above" if self.path == FEED else "above zero"
            raise InputError(f"{shown}: the lower bound must be {allowed}")
        scale = parameter(self.path).scale
        if self.path == FEED and low / scale > IMPLAUSIBLE * max(r.threshold_n for r in TABLE_1.values()):
            raise InputError(f"{shown}: beyond the threshold force of every rock ({_rocks_kn()}) by an order of "
                             f"magnitude or more; the bounds are in {parameter(self.path).unit} (e.g. {self.option} 5 20)")
        return low / scale, high / scale


def _rocks_kn() -> str:
    return ", ".join(f"{name} {rock.threshold_n / 1e3:g} kN" for name, rock in TABLE_1.items())


PARAMETERS = (AdviseParameter("frequency", FREQUENCY, True), AdviseParameter("feed", FEED, True),
              AdviseParameter("amplitude", "impact.amplitude_n", False))


@dataclass(frozen=True)
class Request:
    """What to maximise, over which bounds, below which thrust ratio, with which search budget."""

    metric: str
    bounds: Bounds
    max_thrust_ratio: float = 1.0
    search: AdviceSearch = field(default_factory=AdviceSearch)
    power_w: float | None = None  # a fixed hammer power: E_blow = P / f at every point (module doc)
    max_rod_stress_pa: float | None = None  # a bound on the rods' stress (rod_stress_max_pa, module doc)

    @property
    def metrics(self) -> list[str]:
        """What each run computes: the metric, and the rods' largest stress under a stress bound."""
        return [self.metric] + ([STRESS] if self.max_rod_stress_pa is not None else [])


class NoAllowedPoint(RuntimeError):
    """No point run meets the rods' stress bound (``max_rod_stress_pa``): there is no advice (module doc)."""


def at_point(scene: Scene, point: Point, power_w: float | None = None, source: str = "advise") -> Scene:
    """The scene with the operating parameters of ``point`` (``Scene.with_``), and at a fixed hammer power
    ``power_w`` the piston's blow energy P / f (in place of its strike speed); InputError naming ``source``
    when that is no valid scene."""
    changes: dict[str, Any] = {path: float(value) for path, value in point.items()}
    if power_w is not None:
        frequency_hz = changes.get(FREQUENCY, scene.impact.frequency_hz)
        changes.update({"impact.piston.velocity_m_per_s": None, "impact.piston.energy_j": power_w / frequency_hz})
    return scene.with_(changes, source)


def runnable_scene(scene: Scene, rock: str | None, request: Request, source: str) -> Scene:
    """The scene as advise runs it: the Table 1 ``rock`` in place of its rock (None: its own), the exact
    formulation if it can run it, else Exudyn, the end time raised to fit the metrics' blows at the
    lowest frequency, only the metric computed. InputError (naming ``source`` and the options) when a
    corner of the bounds gives a scene that cannot run, or a fixed power is asked of a scene without a
    piston."""
    if request.power_w is not None and scene.impact.piston is None:
        raise InputError(f"{source}: --power-kw needs a piston (impact.piston): the blow energy at a fixed power "
                         "is the piston's")
    if request.max_rod_stress_pa is not None and not any(body.is_rod for body in scene.drill_string.bodies.values()):
        raise InputError(f"{source}: --max-rod-stress-mpa needs rods (bodies with length_m and diameter_m): the bound "
                         "is on the stress at the rods' ends")
    checked = scene.with_({**({"rock": {"name": rock}} if rock else {}), "outputs": {"metrics": request.metrics}},
                          source)
    formulation = "exact" if unsupported("exact", prepare(checked.with_solver("exact"))) is None else "exudyn"
    blows = checked.metrics.transient_blows + checked.metrics.block_blows
    data = checked.with_solver(formulation).with_(
        {"solver.end_time_s": max(checked.solver.end_time_s, blows / request.bounds[FREQUENCY][0])}, source)
    options = {path: path for path in request.bounds} | {p.path: p.option for p in PARAMETERS}
    for corner in itertools.product(*request.bounds.values()):
        point = dict(zip(request.bounds, corner, strict=True))
        try:
            prepare(at_point(data, point, request.power_w, source))
        except (InputError, SceneError) as error:
            where = " ".join(f"{options[path]} {parameter(path).show(value)}" for path, value in point.items())
            problem = str(error) if isinstance(error, InputError) else f"{source}: {'.'.join(error.location)}: {error}"
            raise InputError(f"{source}: the scene cannot run at the corner {where} of the bounds:\n{problem}") from None
    lowest = {path: low for path, (low, _) in request.bounds.items()}
    ratio = thrust_ratio(at_point(data, lowest))
    if not ratio < request.max_thrust_ratio:
        where = " ".join(f"{options[path]} {parameter(path).show(value)}" for path, value in lowest.items())
        raise InputError(f"{source}: every point of the bounds is beyond the static limit: at their lowest corner "
                         f"({where}{f', rock {rock}' if rock else ''}) the mean thrust is {ratio:.3g} x the rock's "
                         f"threshold force (--max-thrust-ratio {request.max_thrust_ratio:g}); lower the bounds")
    return data


def thrust_ratio(scene: Scene) -> float:
    """Mean thrust / the rock's threshold F_th (module doc: the static limit is 1)."""
    simulation: Simulation = prepare(scene)
    return simulation.mean_thrust_n / simulation.rock.threshold_n


def limit_feed_n(scene: Scene, frequency_hz: float, ratio: float, power_w: float | None = None) -> float:
    """The feed force at which the mean thrust reaches ``ratio`` x F_th at ``frequency_hz`` (inf for a
    rock without a threshold, negative when the blows alone exceed it)."""
    simulation = prepare(at_point(scene, {FREQUENCY: frequency_hz}, power_w))
    share = simulation.feed_total_n / simulation.scene.feed.force_n  # 1, or the bodies the feed acts on
    return (ratio * simulation.rock.threshold_n - (simulation.mean_thrust_n - simulation.feed_total_n)) / share


@dataclass(frozen=True)
class Evaluation:
    """The metric at a batch of points (NaN where not run or failed), their thrust ratios and the
    largest ratio run."""

    values: np.ndarray
    thrust_ratios: np.ndarray
    max_thrust_ratio: float
    stress_excess: np.ndarray | None = None  # rods' stress / bound - 1 where a run exceeded the bound, else 0

    def objective(self) -> np.ndarray:
        """What the search minimises: -metric below the thrust limit (a failed run counts as 0), the
        excess thrust ratio beyond it (worse than any point below); a point whose rods' stress exceeds the
        bound counts as its relative excess (worse than any point within it)."""
        excess = self.thrust_ratios - self.max_thrust_ratio
        objective = np.where(excess < 0, -np.nan_to_num(self.values, nan=0.0), excess)
        if self.stress_excess is not None:
            objective = np.where((excess < 0) & (self.stress_excess > 0), self.stress_excess, objective)
        return objective


def advice_hash(scenes: list[Scene], request: Request) -> str:
    """SHA-256 of what determines an advice's points and their values: the scene of each rock and the
    request (its checkpoint's hash, studies.runtime.evaluation_log)."""
    content = json.dumps({"scenes": [scene.model_dump(by_alias=True, exclude_none=True) for scene in scenes],
                          "request": dataclasses.asdict(request)}, sort_keys=True)
    return hashlib.sha256(content.encode()).hexdigest()


def _point_key(rock: str | None, point: Point) -> tuple[Any, ...]:
    """The memo key of a point of one rock's search: its exact coordinates."""
    return (rock or "", *sorted((path, float(value)) for path, value in point.items()))


class AdviceEvaluation(BaseModel):
    """One point run by a search (a line of ``evaluations.jsonl``): the ``rock`` (a Table 1 name, or '' for the
    scene's own), the ``point`` (key path -> value), the metric's ``value`` there (None where it is not a
    number), the runs that failed and the first error, and under a rod-stress bound the largest rod stress."""

    model_config = ConfigDict(extra="forbid", frozen=True)
    rock: str
    point: dict[str, float]
    value: float | None
    failed_runs: int
    error: str
    rod_stress_max_pa: float | None = None


class AdviceEvaluator:
    """The metric at batches of points, the runs of a batch on the runner at once (points that ``log``
    recorded replayed, new ones recorded as they return); counts runs, replays, failures and points
    beyond the thrust limit."""

    def __init__(self, scene: Scene, request: Request, runner: Runner,
                 progress: Callable[[int], None] | None = None, rock: str | None = None,
                 log: EvaluationLog | None = None) -> None:
        self.scene, self.request, self.runner, self.progress = scene, request, runner, progress
        self.rock, self.log = rock, log
        self.recorded = {_point_key(r.rock, r.point): r for r in (log.records if log else [])}
        self.earlier = set(self.recorded)  # recorded by an earlier session (the rest: this one's repeats)
        self.runs = self.replayed = self.failed = self.beyond_limit = self.beyond_stress = 0
        self.stress = np.empty(0)
        self.stress_at: dict[tuple[Any, ...], float] = {}  # every point run under a stress bound -> its stress
        self.first_error = ""
        self.best_point: Point = {}
        self.best_value = -math.inf

    def _take(self, values: np.ndarray, index: int, record: AdviceEvaluation) -> None:
        values[index] = math.nan if record.value is None else record.value
        self.failed += record.failed_runs
        self.first_error = self.first_error or record.error
        bound, stress = self.request.max_rod_stress_pa, record.rod_stress_max_pa
        if bound is not None:
            self.stress[index] = math.nan if stress is None else stress
            self.stress_at[_point_key(record.rock or None, record.point)] = self.stress[index]
            if stress is not None and stress > bound:  # not allowed: no value on the curves and the map
                values[index] = math.nan
                self.beyond_stress += 1

    def __call__(self, points: list[Point]) -> Evaluation:
        scenes = [at_point(self.scene, p, self.request.power_w) for p in points]
        ratios = np.array([thrust_ratio(scene) for scene in scenes])
        run = [i for i in range(len(points)) if ratios[i] < self.request.max_thrust_ratio]
        values = np.full(len(points), np.nan)
        self.stress = np.full(len(points), np.nan)
        replays = {i: self.recorded[key] for i in run if (key := _point_key(self.rock, points[i])) in self.recorded}
        for i, record in replays.items():
            self._take(values, i, record)
        curves = [Curve(i, scenes[i], {}, (scenes[i].impact.frequency_hz,), tuple(self.request.metrics))
                  for i in run if i not in replays]
        for point_run in (r for batch in self.runner(run_curve, curves) for r in batch) if curves else ():
            value = float(point_run.values(self.request.metric)[0])
            stress = math.nan
            if self.request.max_rod_stress_pa is not None:
                stress = float(point_run.values(STRESS)[0])
            record = AdviceEvaluation(rock=self.rock or "",
                                      point={k: float(v) for k, v in points[point_run.key].items()},
                                      value=None if math.isnan(value) else value, failed_runs=point_run.failed_runs,
                                      error=point_run.error, rod_stress_max_pa=None if math.isnan(stress) else stress)
            self._take(values, point_run.key, record)
            if self.log is not None:
                self.log.append(record)
                self.recorded[_point_key(self.rock, record.point)] = record
        self.runs += len(run)
        self.replayed += sum(_point_key(self.rock, points[i]) in self.earlier for i in replays)
        self.beyond_limit += len(points) - len(run)
        if self.progress:
            self.progress(len(points))
        below = np.where(ratios < self.request.max_thrust_ratio, np.nan_to_num(values, nan=-math.inf), -math.inf)
        if len(points) and below.max() > self.best_value:
            self.best_value, self.best_point = float(below.max()), dict(points[int(np.argmax(below))])
        excess = None
        if self.request.max_rod_stress_pa is not None:
            excess = np.maximum(np.nan_to_num(self.stress / self.request.max_rod_stress_pa - 1.0, nan=0.0), 0.0)
        return Evaluation(values, ratios, self.request.max_thrust_ratio, excess)


def planned_evaluations(request: Request) -> int:
    """Points of a search at most, with the curves and the map."""
    count, search = len(request.bounds), request.search
    return search.popsize * count * (search.max_generations + 1) + count * (SLICE_POINTS + 1) + MAP_POINTS**2


def search_best(evaluate: AdviceEvaluator, request: Request) -> tuple[Point, float, int, bool]:
    """Differential evolution (module doc): (best point, its value, generations, converged)."""
    names, search = list(request.bounds), request.search

    def objective(population: np.ndarray) -> np.ndarray:  # (parameters, members)
        return evaluate([dict(zip(names, member, strict=True)) for member in population.T]).objective()

    found = optimize.differential_evolution(
        objective, list(request.bounds.values()), popsize=search.popsize, maxiter=search.max_generations,
        tol=search.tolerance, rng=search.seed, polish=False, updating="deferred", vectorized=True)
    return dict(zip(names, map(float, found.x), strict=True)), float(-found.fun), int(found.nit), bool(found.success)


def slices(evaluate: AdviceEvaluator, bounds: Bounds, best: Point, best_value: float) -> dict[str, dict[str, Any]]:
    """The metric along each parameter through the optimum (module doc), all in one batch."""
    axes = {path: sorted({*map(float, np.linspace(*bounds[path], SLICE_POINTS)), best[path]}) for path in bounds}
    results = iter(evaluate([{**best, path: value} for path, values in axes.items() for value in values]).values)
    curves = {}
    for path, values in axes.items():
        metric = [float(next(results)) for _ in values]
        at = values.index(best[path])
        metric[at] = best_value  # the same point as the search's best
        band_80 = band(np.array(values), np.nan_to_num(metric, nan=0.0), at, 0.8 * best_value)
        curves[path] = {"values": values, "metric": metric, "band_80": list(band_80)}
    return curves


def feed_map(evaluate: AdviceEvaluator, request: Request, best: Point, scene: Scene) -> dict[str, Any]:
    """The metric on the feed x frequency grid, the other parameters at the optimum (NaN: not run or
    failed), and the feed force of the thrust limit at each frequency."""
    frequencies = [float(f) for f in np.linspace(*request.bounds[FREQUENCY], MAP_POINTS)]
    feeds = [float(f) for f in np.linspace(*request.bounds[FEED], MAP_POINTS)]
    values = evaluate([{**best, FREQUENCY: f, FEED: feed} for feed in feeds for f in frequencies]).values
    at_best = at_point(scene, best, request.power_w)
    return {FREQUENCY: frequencies, FEED: feeds, "metric": values.reshape(len(feeds), len(frequencies)).tolist(),
            "limit_feed_n": [limit_feed_n(at_best, f, request.max_thrust_ratio, request.power_w) for f in frequencies]}


def peak_position(values: list[float]) -> str:
    """Where a curve along the feed is highest: 'interior' (it rises, then falls), 'lowest feed',
    'highest feed' (the highest feed run: the bound or the last below the thrust limit), or 'none'
    (nowhere positive). NaN: not run."""
    column = np.array(values, dtype=float)
    run = np.flatnonzero(np.isfinite(column))
    if not np.any(column[run] > 0):
        return "none"
    best = int(np.nanargmax(column))
    return "lowest feed" if best == run[0] else "highest feed" if best == run[-1] else "interior"


def feed_response(feed_map_: dict[str, Any]) -> dict[str, Any]:
    """Per map frequency, where the metric is highest along the feed (:func:`peak_position`), and the
    frequencies of each kind."""
    kinds = [peak_position(column) for column in np.array(feed_map_["metric"], dtype=float).T]
    by_kind = {kind: [f for f, k in zip(feed_map_[FREQUENCY], kinds, strict=True) if k == kind]
               for kind in ("interior", "highest feed", "lowest feed", "none")}
    return {"best_feed_at": kinds, "frequencies_by_kind": by_kind}


def search_advice(data: Scene, rock: str | None, request: Request, runner: Runner,
                  progress: Callable[[int], None] | None = None, log: EvaluationLog | None = None) -> Advice:
    """The best operating point (module doc) of the scene ``data`` (:func:`runnable_scene`, on ``rock``),
    with the curves around it and the feed x frequency map; ``progress(points)`` after each batch;
    ``log``: the points recorded and replayed (module doc)."""
    start = time.perf_counter()
    evaluate = AdviceEvaluator(data, request, runner, progress, rock, log)
    advice = Advice(scene=data.name, description=describe_scene(data, request.bounds),
                    scene_description=describe_scene(data, [*request.bounds, "rock.name"]), rock=rock,
                    metric=request.metric, formulation=data.solver.formulation, end_time_s=data.solver.end_time_s,
                    bounds=request.bounds, max_thrust_ratio=request.max_thrust_ratio, power_w=request.power_w)
    advice.best, advice.best_value, advice.generations, advice.converged = search_best(evaluate, request)
    if request.max_rod_stress_pa is not None and evaluate.beyond_stress and not math.isfinite(evaluate.best_value):
        raise NoAllowedPoint(_no_allowed_point(evaluate, request, rock or data.name))
    advice.best_thrust_ratio = thrust_ratio(at_point(data, advice.best, request.power_w))
    advice.slices = slices(evaluate, request.bounds, advice.best, advice.best_value)
    advice.feed_map = feed_map(evaluate, request, advice.best, data)
    searched = advice.best_value
    for _ in range(MAX_PROMOTIONS):  # a point of the curves or the map beats the search's best (module doc)
        if not evaluate.best_value > advice.best_value:
            break
        moved = [path for path in request.bounds if path not in (FREQUENCY, FEED)
                 and evaluate.best_point[path] != advice.best[path]]
        advice.best, advice.best_value = evaluate.best_point, evaluate.best_value
        advice.best_thrust_ratio = thrust_ratio(at_point(data, advice.best, request.power_w))
        advice.slices = slices(evaluate, request.bounds, advice.best, advice.best_value)
        if moved:  # the map is at the other parameters of the best
            advice.feed_map = feed_map(evaluate, request, advice.best, data)
    if advice.best_value > searched:
        advice.search_best_value = searched
    advice.feed_map["response"] = feed_response(advice.feed_map)
    advice.runs, advice.failed_runs, advice.beyond_limit = evaluate.runs, evaluate.failed, evaluate.beyond_limit
    advice.max_rod_stress_pa, advice.beyond_stress = request.max_rod_stress_pa, evaluate.beyond_stress
    advice.best_rod_stress_pa = evaluate.stress_at.get(_point_key(rock, advice.best), math.nan)
    advice.replayed = evaluate.replayed
    advice.first_error = evaluate.first_error
    advice.wall_time_s = time.perf_counter() - start
    return advice


def _no_allowed_point(evaluate: AdviceEvaluator, request: Request, name: str) -> str:
    """Why there is no advice under the stress bound: the least stress of the points run, and where."""
    stresses = {key: value for key, value in evaluate.stress_at.items() if math.isfinite(value)}
    bound = f"{request.max_rod_stress_pa / 1e6:g} MPa"
    if not stresses:
        return f"{name}: no point run gave the rods' stress to hold against the bound {bound}"
    key = min(stresses, key=stresses.get)
    where = ", ".join(f"{parameter(path).name} {parameter(path).show_with_unit(value)}" for path, value in key[1:])
    return (f"{name}: no point run keeps the rods below the stress bound {bound} (max_rod_stress_pa; "
            f"{evaluate.beyond_stress} of {evaluate.runs} points run exceed it): the least stress run is "
            f"{stresses[key] / 1e6:.4g} MPa, at {where}; raise the bound above it or change the bounds")
