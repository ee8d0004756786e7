"""Whether a finished run's figures stand as they are: its status and, when they do not, why.

* ``unstable``: the stability check flags the run's fixed explicit step (models.evaluation.stability.step_warning:
  the step exceeds the limit of the stiffest mode, or the solver is unstable at any step on undamped
  modes); the run finished, but its figures may be the integrator's, not the drill's.
* ``unsettled``: the penetration rate has not settled over the averaging window: the block rates
  (models.evaluation.metrics) spread over more than UNSETTLED_SHARE of their mean (and more than
  SETTLED_SPREAD_M_PER_S); the rate depends on where the window ends.
* ``ok`` otherwise. A run that failed is ``failed`` (it has no figures).
"""

from __future__ import annotations

import numpy as np

from .metrics import block_rates_m_per_s
from .results import SimulationResult
from .stability import step_warning


class UnsettledWarning(UserWarning):
    """The penetration rate of a run has not settled (module doc)."""


UNSETTLED_SHARE = 0.25  # (max - min) / |mean| of the block rates beyond which a run has not settled
SETTLED_SPREAD_M_PER_S = 1e-6  # a spread below this (0.001 mm/s) is settled whatever the mean


def unsettled_warning(result: SimulationResult) -> str | None:
    """Why the penetration rate of ``result`` has not settled (module doc), None when it has or
    when the window has fewer than two blocks."""
    try:
        rates = block_rates_m_per_s(result)
    except ValueError:  # no whole block in the run
        return None
    if len(rates) < 2 or not np.all(np.isfinite(rates)):
        return None
    low, high, mean = float(rates.min()), float(rates.max()), float(rates.mean())
    spread = high - low
    if spread <= max(SETTLED_SPREAD_M_PER_S, UNSETTLED_SHARE * abs(mean)):
        return None
    share = f"{spread / abs(mean):.0%} of their mean" if mean else "their mean is 0"
    return (f"scene '{result.simulation.name}': the penetration rate has not settled: its {len(rates)} blocks "
            f"range from {low * 1e3:.3g} to {high * 1e3:.3g} mm/s ({share}; settled is within "
            f"{UNSETTLED_SHARE:.0%}); raise solver.end_time_s or metrics.transient_blows")


def run_status(result: SimulationResult) -> tuple[str, str]:
    """``(status, why)`` of a finished run (module doc); why is '' for ``ok``."""
    simulation = result.simulation
    unstable = step_warning(simulation) if result.formulation == "exudyn" else None
    if unstable:
        return "unstable", unstable
    unsettled = unsettled_warning(result)
    if unsettled:
        return "unsettled", unsettled
    return "ok", ""
