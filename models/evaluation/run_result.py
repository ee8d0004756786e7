"""One run of a scene as a user holds it (``rpdrill.Result``): its metrics, its time series as a
pandas table, the formulation's raw result, its steady state and where the run came from."""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING, Any

from ..definition.extensions import CodeRecords
from ..definition.scene import Scene
from .energy import EnergyAccount, energy_account
from .metrics import summary_metrics
from .results import SimulationResult
from .run_record import ExudynModelRecord, SolverRecord, SteadyStateRecord
from .run_status import run_status

if TYPE_CHECKING:
    import pandas as pd


@dataclass(frozen=True)
class Result:
    """One run of a scene (:func:`simulate`): its metrics, its time series, its steady state and its records.

    The raw result's histories read through (``result.time_s``, ``result.position_m``).

    Parameters
    ----------
    scene : Scene
        The scene that ran.
    raw : SimulationResult
        The formulation's result: every sample, the chain (models.evaluation.results).
    source : str, default ""
        The scene's file, or how it was made.
    code : CodeRecords
        The code of one's own the run imported: every extension and a rock law of one's own, by import path,
        package, version and file.
    warnings : tuple of str, default ()
        What the run warned of.

    Attributes
    ----------
    metrics : dict of str to float
        The scene's metrics, SI units in the names (``penetration_rate_m_per_s``, ``bit_velocity_peak_m_per_s``).
    energy : EnergyAccount
        The run's energy account at every stored step: W_impact + W_feed = dE_kinetic + dE_elastic + D_damping
        + W_crushing, its ``residual_j`` and ``relative_residual()`` (the balance a reviewer checks).
    timeseries : pandas.DataFrame
        Every ``solver.output_interval_s``: ``time_s`` a column on a plain index, every body's position and
        velocity, every connector's force and compression, units in the column names (as ``timeseries.csv``).
    status, status_why : str
        Whether the figures stand as they are (``ok``, ``unstable``, ``unsettled``, ``not_finite``, ``unbalanced``)
        and, when not, why: the status ``summary.json`` and a study's rows hold.
    steady_state : SteadyStateRecord
        The ``regime`` (:class:`Regime`), the periodic ``orbit`` with its Floquet ``multipliers``, the ``note``.
    solver : SolverRecord
        What the formulation's solver did: samples, mode switches, its step.
    exudyn_model : ExudynModelRecord or None
        The items of one's own an Exudyn model ran with.
    provenance : dict
        The source and the code records, as ``summary.json`` holds them.

    Examples
    --------
    >>> import rpdrill
    >>> scene = rpdrill.load_scene("paper_base").with_({"solver.formulation": "exact",
    ...                                                  "solver.steady_state": "periodic"})
    >>> result = rpdrill.simulate(scene)
    >>> result.steady_state.regime, result.steady_state.orbit.period_blows
    (<Regime.PERIODIC: 'periodic'>, 1)
    >>> result.metrics["advance_per_blow_m"] > 0, result.timeseries.columns[0], result.status
    (True, 'time_s', 'ok')
    >>> result.energy.relative_residual() < 1e-6
    True
    """

    scene: Scene
    raw: SimulationResult
    source: str = ""
    code: CodeRecords = field(default_factory=CodeRecords)
    warnings: tuple[str, ...] = ()

    @cached_property
    def metrics(self) -> dict[str, float]:
        return summary_metrics(self.raw)

    @cached_property
    def energy(self) -> EnergyAccount:
        """The energy account (models.evaluation.energy): cumulative works and energies [J] at every stored
        step, W_impact + W_feed = dE_kinetic + dE_elastic + D_damping + W_crushing."""
        return energy_account(self.raw)

    @cached_property
    def _status(self) -> tuple[str, str]:
        return run_status(self.raw, self.metrics)

    @property
    def status(self) -> str:
        """Whether the figures stand as they are: ``ok``, ``unstable``, ``unsettled``, ``not_finite`` or
        ``unbalanced`` (models.evaluation.run_status; summary.json's and a study row's ``status``)."""
        return self._status[0]

    @property
    def status_why(self) -> str:
        """Why the status is not ``ok`` (the message ``rpdrill simulate`` warns with), '' when it is."""
        return self._status[1]

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
