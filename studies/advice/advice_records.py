"""The typed records of an advice (``rpdrill advise``, studies.advice.advice_search): the budget of its search
(:class:`AdviceSearch`) and what it found for one rock (:class:`Advice`), SI units by scene key path."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from ..inputs.arguments import check, count_problem, positive_problem, seed_problem

Bounds = dict[str, tuple[float, float]]  # scene path -> (low, high), SI
Point = dict[str, float]  # scene path -> SI value


@dataclass(frozen=True)
class AdviceSearch:
    """Differential evolution's budget for :func:`advise` (SciPy's ``differential_evolution``).

    Parameters
    ----------
    popsize : int, default 10
        The population: ``popsize`` x the number of parameters.
    max_generations : int, default 30
        Generations after the first population.
    tolerance : float, default 0.01
        Convergence at this relative spread of the population (SciPy's ``tol``).
    seed : int, default 1
        The random seed: the same seed, the same search.

    Raises
    ------
    InputError
        For a count below 1, a tolerance that is not positive, a seed that is not a whole number.

    Examples
    --------
    >>> import rpdrill
    >>> rpdrill.AdviceSearch(popsize=6, max_generations=10)
    AdviceSearch(popsize=6, max_generations=10, tolerance=0.01, seed=1)
    """

    popsize: int = 10
    max_generations: int = 30
    tolerance: float = 0.01
    seed: int = 1

    def __post_init__(self) -> None:
        for name, problem in (("popsize", count_problem), ("max_generations", count_problem),
                              ("tolerance", positive_problem), ("seed", seed_problem)):
            check("rpdrill.AdviceSearch", name, getattr(self, name), problem)



@dataclass
class Advice:
    """The advice for one scene and rock (:func:`advise`): the best point, its value, how it was found. SI units.

    Parameters
    ----------
    scene, description, scene_description : str
        The scene's name; the scene, rock and impact in one line; the same without the rock.
    rock : str or None
        The Table 1 rock advised for (None: the scene's).
    metric, formulation : str
        What was maximised, by which formulation.
    end_time_s : float
        The simulated time of each run.
    bounds : dict of str to (float, float)
        The bounds searched, SI units by key path.
    max_thrust_ratio : float
        The thrust limit as a share of F_th.
    best : dict of str to float
        The best point found (key path to value).
    best_value : float
        The metric there.
    best_thrust_ratio : float
        The mean thrust over F_th there.
    runs, replayed, failed_runs, beyond_limit : int
        The points run, of them replayed from an earlier session, failed; the points not run (thrust limit).
    first_error : str
        The first failed run's error.
    generations : int
        Differential evolution's generations.
    converged : bool
        Whether it converged within its budget.
    slices : dict
        The metric along each parameter through the best point.
    feed_map : dict
        The feed x frequency map.
    wall_time_s : float
        The wall time of the search.
    power_w, max_rod_stress_pa : float or None
        The fixed hammer power and the rods' stress bound, where given.
    best_rod_stress_pa : float
        The rods' largest stress at the best point (with a bound).
    beyond_stress : int
        Points run whose rods' stress exceeded the bound.
    search_best_value : float
        The search's own best, where a point of its curves or map beat it.

    Examples
    --------
    >>> import rpdrill
    >>> scene = rpdrill.load_scene("paper_base").with_({"solver.formulation": "exact"})
    >>> advice = rpdrill.advise(scene, {"impact.frequency_hz": (45, 75), "feed.force_n": (10e3, 30e3)},
    ...                         search=rpdrill.AdviceSearch(popsize=3, max_generations=2))  # doctest: +SKIP
    >>> advice[0].best, advice[0].rock, advice[0].metric  # doctest: +SKIP
    ({'impact.frequency_hz': 75.0, 'feed.force_n': 30000.0}, None, 'penetration_rate_m_per_s')
    """

    scene: str
    description: str  # the scene, rock and impact in one line (studies.display.catalogue.describe_scene)
    scene_description: str  # the same without the rock
    rock: str | None
    metric: str
    formulation: str
    end_time_s: float
    bounds: Bounds
    max_thrust_ratio: float
    best: Point = field(default_factory=dict)
    best_value: float = math.nan
    best_thrust_ratio: float = math.nan  # mean thrust / F_th at the best point
    runs: int = 0
    replayed: int = 0  # of the runs, points recorded by an earlier session (module doc)
    failed_runs: int = 0
    beyond_limit: int = 0  # points not run: beyond the thrust limit
    first_error: str = ""
    generations: int = 0
    converged: bool = False
    slices: dict[str, dict[str, Any]] = field(default_factory=dict)
    feed_map: dict[str, Any] = field(default_factory=dict)
    wall_time_s: float = 0.0
    power_w: float | None = None  # the fixed hammer power (module doc), or None
    max_rod_stress_pa: float | None = None  # the rods' stress bound, or None
    best_rod_stress_pa: float = math.nan  # the rods' largest stress at the best point (with a bound)
    beyond_stress: int = 0  # points run whose rods' stress exceeded the bound
    search_best_value: float = math.nan  # the search's own best, where a point of its curves or map beat it
