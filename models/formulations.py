"""The three formulations of the same model, by name.

``exudyn``: the multibody model (default, any chain the builder makes). ``ode``: the paper's Eq. 4
as an event-located SciPy ODE (independent cross-check). ``exact``: the piecewise-linear model
propagated by matrix exponentials between located switches (the reference and the fast path for
large sweeps; only for laws linear between switches, as the paper's).
"""

from __future__ import annotations

from collections.abc import Callable

from rpdrill.models.exact_model import simulate_exact
from rpdrill.models.exact_scope import exact_unsupported
from rpdrill.models.exudyn_model import simulate_exudyn
from rpdrill.models.ode_model import simulate_ode
from rpdrill.models.results import SimulationResult
from rpdrill.models.scene import Scene

FORMULATIONS: dict[str, Callable[[Scene], SimulationResult]] = {
    "exudyn": simulate_exudyn,
    "exact": simulate_exact,
    "ode": simulate_ode,
}

# Why a formulation cannot run a scene (None: it can); formulations not listed run every scene.
LIMITS: dict[str, Callable[[Scene], str | None]] = {"exact": exact_unsupported}


def unsupported(formulation: str, scene: Scene) -> str | None:
    """Why ``formulation`` cannot run ``scene``, or None."""
    limit = LIMITS.get(formulation)
    return limit(scene) if limit else None
