"""The operating point of one depth of a hole with ``operating: advise``: the advisor's search (differential
evolution of rpdrill advise, studies.advice.advice_search: the same scene as advise runs it, the same thrust and
rod-stress limits, at a fixed hammer power where asked) on the depth's scene as a time run of
``search_end_time_s``, without the curves and the feed x frequency map ``rpdrill advise`` adds around the best.
The hole's run at that depth is then the steady run at the point found (studies.hole.hole_runs)."""

from __future__ import annotations

from typing import Any

from ...models.definition.scene import Scene
from ...models.definition.validation import parse
from ..advice.advice_records import AdviceSearch
from ..advice.advice_search import (
    FREQUENCY,
    METRICS,
    AdviceEvaluator,
    NoAllowedPoint,
    Request,
    runnable_scene,
    search_best,
)
from ..runtime.pools import sequential


def advised_changes(data: dict[str, Any], source: str, advise: dict[str, Any]) -> dict[str, Any]:
    """The scene key paths to values of the best point for the scene ``data`` (``advise``: the hole file's
    ``operating.advise``); a fixed power's blow energy P / f among them. RuntimeError (NoAllowedPoint) where no point
    keeps the rods below the stress bound."""
    search_data = {**data, "solver": {**data["solver"], "steady_state": "time",
                                      "end_time_s": advise["search_end_time_s"]}}
    scene = parse(Scene, search_data, source)
    power_w = None if advise.get("power_kw") is None else 1e3 * advise["power_kw"]
    stress = None if advise.get("max_rod_stress_mpa") is None else 1e6 * advise["max_rod_stress_mpa"]
    request = Request(METRICS[0], {path: (float(low), float(high)) for path, (low, high) in advise["bounds"].items()},
                      search=AdviceSearch(advise["popsize"], advise["max_generations"], seed=advise["seed"]),
                      power_w=power_w, max_rod_stress_pa=stress)
    evaluate = AdviceEvaluator(runnable_scene(scene, None, request, source), request, sequential)
    best, value, _, _ = search_best(evaluate, request)
    if stress is not None and evaluate.beyond_stress and not value > float("-inf"):
        raise NoAllowedPoint(f"{source}: no point of the search keeps the rods below {advise['max_rod_stress_mpa']} MPa")
    changes: dict[str, Any] = {path: float(v) for path, v in best.items()}
    if power_w is not None:
        frequency_hz = changes.get(FREQUENCY, scene.impact.frequency_hz)
        changes.update({"impact.piston.velocity_m_per_s": None, "impact.piston.energy_j": power_w / frequency_hz})
    return changes
