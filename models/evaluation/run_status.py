"""Whether a finished run's figures stand as they are: its status and, when they do not, why.

* ``unstable``: the stability check flags the run's fixed explicit step (models.evaluation.stability.step_warning:
  the step exceeds the limit of the stiffest mode, or the solver is unstable at any step on undamped
  modes); the run finished, but its figures may be the integrator's, not the drill's.
* ``unsettled``: the penetration rate has not settled over the averaging window: the block rates
  (models.evaluation.metrics) spread over more than UNSETTLED_SHARE of their mean (and more than
  SETTLED_SPREAD_M_PER_S); the rate depends on where the window ends.
* ``not_finite``: a metric of the run is not a finite number (NaN, infinite): the figures are not
  numbers (an energy transfer efficiency of a run whose impact did no work, 0 / 0); written as
  empty (null) values.
* ``unbalanced``: the run's energy balance (``energy_balance_relative_error``, when its outputs ask
  for it: models.evaluation.energy) is off by more than ENERGY_BALANCE_BOUND of the impact work:
  twice the largest energy-balance error a solver preset states (``fast``, 5e-2:
  models.evaluation.solver_settings.EXUDYN_PRESETS, measured by benchmarks/bench_presets.py on the
  paper scene and the hard scenes, docs/stability.md); the exact formulation closes it to
  round-off and the ODE to its tolerance. Beyond it the run does not hold the work put in (a step
  too coarse, or an impact too weak against the feed to balance it).
* ``ok`` otherwise. A run that failed is ``failed`` (it has no figures).

A study's point is usable when its status is ``ok`` or ``unsettled`` (:data:`USABLE`): its figures
stand (unsettled: they depend on where the averaging window ends).
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from .metrics import block_rates_m_per_s, summary_metrics
from .results import SimulationResult
from .solver_settings import EXUDYN_PRESETS
from .stability import step_warning


class UnsettledWarning(UserWarning):
    """A finished run whose figures do not stand as they are: its status is not ``ok`` (module doc); the message
    says why and what to change (a longer run, more transient blows). The command ``rpdrill simulate`` issues it;
    from Python the same status and message are ``Result.status`` and ``Result.status_why``.

    Parameters
    ----------
    *args
        The message.

    Examples
    --------
    >>> import rpdrill
    >>> issubclass(rpdrill.UnsettledWarning, UserWarning)
    True
    """


STATUSES = ("ok", "unstable", "unsettled", "not_finite", "unbalanced")  # of a finished run (and "failed")
USABLE = ("ok", "unsettled")
ENERGY_BALANCE_BOUND = 2 * max(preset.energy_balance_error for preset in EXUDYN_PRESETS.values())
ENERGY_BALANCE = "energy_balance_relative_error"


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


def not_finite(metrics: Mapping[str, float]) -> str | None:
    """Why some of ``metrics`` are not finite numbers (module doc), None when all are."""
    bad = {name: value for name, value in metrics.items() if not math.isfinite(value)}
    if not bad:
        return None
    shown = ", ".join(f"{name} {value}" for name, value in bad.items())
    return (f"{shown}: not a finite number; the run's figures are written as empty (null) values; raise "
            "impact.amplitude_n or the run's length if its impact did no work")


def unbalanced(metrics: Mapping[str, float], name: str) -> str | None:
    """Why the energy balance in ``metrics`` (of scene ``name``) is off beyond ENERGY_BALANCE_BOUND, None
    when it is within it or was not asked for."""
    error = metrics.get(ENERGY_BALANCE)
    if error is None or not error > ENERGY_BALANCE_BOUND:
        return None
    return (f"scene '{name}': the energy balance is off by {error:.3g} of the impact work (bound "
            f"{ENERGY_BALANCE_BOUND:g}: twice the largest error a solver preset states); the run does not hold the "
            "work put in: a smaller solver step, or an impact strong enough against the feed to balance")


def run_status(result: SimulationResult, metrics: Mapping[str, float] | None = None) -> tuple[str, str]:
    """``(status, why)`` of a finished run (module doc) with its ``metrics`` (default: computed here);
    why is '' for ``ok``."""
    if metrics is None:
        metrics = summary_metrics(result)
    why = not_finite(metrics)
    if why:
        return "not_finite", f"scene '{result.simulation.name}': {why}"
    why = unbalanced(metrics, result.simulation.name)
    if why:
        return "unbalanced", why
    simulation = result.simulation
    unstable = step_warning(simulation) if result.formulation == "exudyn" else None
    if unstable:
        return "unstable", unstable
    unsettled = unsettled_warning(result)
    if unsettled:
        return "unsettled", unsettled
    return "ok", ""
