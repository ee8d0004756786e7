"""One run of a scene as a user holds it (``rpdrill.Result``): its metrics, its time series as a
pandas table, the formulation's raw result and where the run came from."""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING, Any

from ..definition.scene import Scene
from .metrics import summary_metrics
from .results import SimulationResult

if TYPE_CHECKING:
    import pandas as pd


@dataclass(frozen=True)
class Result:
    """One run: ``metrics`` (the scene's outputs' metrics, SI units in the names), ``timeseries`` (a
    DataFrame every ``solver.output_interval_s``, columns with units in their names, as
    ``timeseries.csv``), ``raw`` (the formulation's result: every sample, the chain, the run info) and
    ``provenance``. The raw result's attributes read through (``result.time_s``, ``result.position_m``,
    ``result.info``)."""

    scene: Scene
    raw: SimulationResult
    provenance: dict[str, Any] = field(default_factory=dict)

    @cached_property
    def metrics(self) -> dict[str, float]:
        return summary_metrics(self.raw)

    @cached_property
    def timeseries(self) -> pd.DataFrame:
        """Time series every ``solver.output_interval_s`` (x_n held between its changes, the rest
        interpolated), columns with units in their names, the sensors of one's own of an Exudyn model by
        their names; ``time_s`` a column, the index a plain range (``pd.merge_asof(..., on="time_s")``)."""
        import pandas as pd  # 0.3 s to import: only where a table is asked for

        return pd.DataFrame(self.raw.resampled(self.scene.solver.output_interval_s))

    def __getattr__(self, name: str) -> Any:  # only for names the Result itself lacks
        if name.startswith("__"):
            raise AttributeError(name)
        return getattr(self.raw, name)
