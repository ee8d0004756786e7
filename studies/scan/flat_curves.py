"""Why a scanned curve has no optimum: every point failed, or the metric is zero at every point.

A metric that only crushing moves (it needs the rock's plasticity: the penetration rate, the advance
per blow, the crushing work, ...) is zero exactly when the rock force never reaches F_th: the bottom
x_n moves only on the crushing branch of Eq. 1, 2. Plots, printed summaries and ``optima.csv`` give
this reason instead of a silent flat line.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from ...models.definition.outputs import METRICS

NO_RESULT = "no result: every point failed"
NO_CRUSHING = "no crushing: the peak rock force stays below F_th at every point"
ZERO = "zero at every point"


def moved_only_by_crushing(metric: str) -> bool:
    """Whether ``metric`` needs the rock's plasticity (models.definition.outputs: zero without crushing)."""
    need = METRICS.get(metric)
    return need is not None and "rock_plasticity" in need.effects


def why_no_optimum(metric: str, values: Sequence[float]) -> str | None:
    """The reason a curve of ``metric`` has no optimum (module doc), None when it may have one."""
    finite = [v for v in values if math.isfinite(v)]
    if not finite:
        return NO_RESULT
    if all(v == 0.0 for v in finite):
        return NO_CRUSHING if moved_only_by_crushing(metric) else ZERO
    return None
