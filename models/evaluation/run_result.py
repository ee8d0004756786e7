"""One run of a scene as a user holds it (``rpdrill.Result``): its metrics, its time series as a
pandas table, the formulation's raw result, its steady state and where the run came from."""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING, Any

from ..definition.extensions import CodeRecords
from ..definition.scene import Scene
from .metrics import summary_metrics
from .results import SimulationResult
from .run_record import ExudynModelRecord, SolverRecord, SteadyStateRecord

if TYPE_CHECKING:
    import pandas as pd


@dataclass(frozen=True)
class Result:
    """One run: ``metrics`` (the scene's outputs' metrics, SI units in the names), ``timeseries`` (a
    DataFrame every ``solver.output_interval_s``, columns with units in their names, as
    ``timeseries.csv``), ``raw`` (the formulation's result: every sample, the chain), ``steady_state`` (the
    regime: a time run, or the periodic orbit with its Floquet multipliers), ``solver`` (what the
    formulation's solver did), ``exudyn_model`` (the items of one's own an Exudyn model ran with, or None),
    ``source`` (the scene's file, or how it was made), ``code`` (the code of one's own the run imported:
    every extension and a rock law of one's own, by import path, package, version and file) and
    ``warnings`` (what the run warned of). The raw result's histories read through (``result.time_s``,
    ``result.position_m``)."""

    scene: Scene
    raw: SimulationResult
    source: str = ""
    code: CodeRecords = field(default_factory=CodeRecords)
    warnings: tuple[str, ...] = ()

    @cached_property
    def metrics(self) -> dict[str, float]:
        return summary_metrics(self.raw)

    @property
    def steady_state(self) -> SteadyStateRecord:
        return self.raw.steady_state

    @property
    def solver(self) -> SolverRecord:
        return self.raw.solver

    @property
    def exudyn_model(self) -> ExudynModelRecord | None:
        return self.raw.exudyn_model

    @property
    def provenance(self) -> dict[str, Any]:
        """Where the run came from, as ``summary.json`` records it: the source and the code records."""
        return {"source": self.source, **self.code.as_dict()}

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
