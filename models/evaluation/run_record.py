"""What a run records besides its histories, as typed values: what the formulation's solver did
(:class:`SolverRecord` and one subclass per formulation), the steady state the scene asked for
(:class:`SteadyStateRecord`: the regime, the orbit with its Floquet multipliers as complex numbers, the
unstable and coexisting orbits met, why none was found or why the scene cannot have one), and the items of
one's own an Exudyn model ran with (:class:`ExudynModelRecord`)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from enum import Enum
from typing import Any, Literal

import numpy as np


@dataclass(frozen=True, kw_only=True)
class SolverRecord:
    """What the formulation's solver did: ``success``, the stored ``samples`` and their interval, the
    piecewise modes entered (``mode_switches`` in all, ``switches_into`` by mode, ``switch_times_s`` and
    ``switch_modes`` where the formulation locates them) and, under bit indexing, the share of fresh rock
    ``fresh_fractions`` of every blow."""

    success: bool = True
    samples: int
    sample_interval_s: float | None = None
    mode_switches: int | None = None
    switches_into: Mapping[str, int] = field(default_factory=dict)
    switch_times_s: np.ndarray | None = None
    switch_modes: tuple[Any, ...] = ()
    fresh_fractions: tuple[float, ...] = ()


@dataclass(frozen=True, kw_only=True)
class ExactSolverRecord(SolverRecord):
    """The exact propagator (models.solvers.exact_model): its sub-step, the shortest mode it allows and how
    many mode operators it built."""

    sub_step_s: float
    min_switch_interval_s: float
    operator_keys: int


@dataclass(frozen=True, kw_only=True)
class OdeSolverRecord(SolverRecord):
    """The paper's Eq. 4 as a SciPy ODE (models.solvers.ode_model): the method, its tolerances, its steps,
    the smooth pieces between events and the right-hand side's evaluations."""

    method: str
    relative_tolerance: float
    absolute_tolerance: float
    solver_steps: int
    pieces: int
    rhs_evaluations: int


@dataclass(frozen=True, kw_only=True)
class ExudynSolverRecord(SolverRecord):
    """Exudyn's time integration: the ODE2 coordinates of the system it solved."""

    coordinates: int


@dataclass(frozen=True, kw_only=True)
class WaveSolverRecord(SolverRecord):
    """A run with wave rods (models.waves): the characteristics' step, each rod's transit-time rounding to
    it, the linear systems (keys) met; ``coordinates`` Exudyn's (None: the exact formulation)."""

    wave_step_s: float
    transit_time_errors: Mapping[str, float]
    keys: int
    coordinates: int | None = None


class Regime(Enum):
    """What a run's steady state is (``Result.steady_state.regime``).

    Attributes
    ----------
    TIME_RUN
        The time run itself (``solver.steady_state: time``): averaged after the transient blows.
    PERIODIC
        A stable periodic orbit of ``period_blows`` blows (``solver.steady_state: periodic``).
    NOT_FOUND
        No periodic orbit found: the result is the time run, the reason in the note.
    REFUSED
        A scene that cannot have an orbit relative to the bottom: the time run, the reason in the note.
    SETTLED
        A drill with wave rods run blow by blow until its per-blow figures settled (models.steady.wave_settling):
        the metrics over the settled blows, the blows run and the last change in the record.

    Examples
    --------
    >>> import rpdrill
    >>> rpdrill.Regime("periodic") is rpdrill.Regime.PERIODIC
    True
    >>> [regime.value for regime in rpdrill.Regime]
    ['time run', 'periodic', 'no periodic orbit found', 'periodic orbit refused', 'settled']
    """

    TIME_RUN = "time run"
    PERIODIC = "periodic"
    NOT_FOUND = "no periodic orbit found"
    REFUSED = "periodic orbit refused"
    SETTLED = "settled"


@dataclass(frozen=True)
class OrbitRecord:
    """A periodic orbit of ``period_blows`` blows as a run reports it: its Floquet ``multipliers``, the modes
    entered over one orbit (``event_sequence``), its section ``state`` (a neighbour's Newton guess) with a
    label per entry, ``advance_per_blow_m``, and how it was found (Newton's iterations, the Jacobian's
    source); ``residual``: max |z(end) - z(start)| / s of the run over it."""

    period_blows: int
    multipliers: tuple[complex, ...]
    advance_per_blow_m: float
    event_sequence: tuple[str, ...] = ()
    state: np.ndarray | None = None
    state_labels: tuple[str, ...] = ()
    newton_iterations: int = 0
    jacobian: str = ""
    residual: float = float("nan")
    json_properties = ("floquet_max_abs",)  # written beside the fields

    @property
    def floquet_max_abs(self) -> float:
        """max |mu|: stable below 1."""
        return max((abs(mu) for mu in self.multipliers), default=0.0)

    @property
    def stable(self) -> bool:
        return self.floquet_max_abs < 1


@dataclass(frozen=True)
class StartRecord:
    """Where the drill goes from its scene's start beside the orbit found (models.steady.start_check): the
    ``regime`` it reaches (``period-n`` or ``irregular``), whether that is the orbit (``reaches_orbit``; False:
    coexisting attractors, and the start reaches the other one), after ``blows`` blows, and the other
    attractor's advance per blow (NaN: none)."""

    regime: str
    reaches_orbit: bool
    blows: int
    advance_per_blow_m: float = float("nan")


@dataclass(frozen=True)
class SteadyStateRecord:
    """The steady state of a run (module doc): ``requested`` the scene's ``solver.steady_state``, the
    ``regime``, the stable ``orbit`` (None unless the regime is periodic), the ``unstable`` orbits met on the
    way, where the drill goes from its scene's ``start`` (None: not checked; another attractor there: the orbit
    coexists with it), the ``note`` (coexisting regimes, why none was found, why the scene was refused) and what
    the search cost; a drill with wave rods run until it settled: the ``blows`` run and the ``last_change`` of
    its per-blow figures and the period they settled with (models.steady.wave_settling)."""

    requested: Literal["time", "periodic"] = "time"
    regime: Regime = Regime.TIME_RUN
    orbit: OrbitRecord | None = None
    unstable: tuple[OrbitRecord, ...] = ()
    start: StartRecord | None = None
    note: str = ""
    map_runs: int = 0
    cpu_time_s: float = 0.0
    blows: int = 0
    last_change: float = float("nan")
    settled_period_blows: int | None = None
    json_properties = ("regime_name", "period_blows", "floquet_max_abs")  # written beside the fields

    @property
    def period_blows(self) -> int | None:
        return self.settled_period_blows if self.orbit is None else self.orbit.period_blows

    @property
    def regime_name(self) -> str:
        """``period-n`` for an orbit of n blows, ``settled`` (``settled period-n`` where the blows alternate), else
        the regime's text (``time run``, ...)."""
        if self.regime is Regime.SETTLED and (self.settled_period_blows or 1) > 1:
            return f"settled period-{self.settled_period_blows}"
        return f"period-{self.orbit.period_blows}" if self.orbit is not None else self.regime.value

    @property
    def floquet_max_abs(self) -> float:
        """max |mu| of the stable orbit, else of the least unstable orbit met (NaN: none)."""
        if self.orbit is not None:
            return self.orbit.floquet_max_abs
        return min((o.floquet_max_abs for o in self.unstable), default=float("nan"))

    def columns(self) -> dict[str, Any]:
        """The steady-state columns of a results table (:data:`REGIME_COLUMNS`)."""
        return {"steady_state": self.requested, "regime": self.regime_name, "period_blows": self.period_blows,
                "floquet_max_abs": self.floquet_max_abs}


REGIME_COLUMNS = ("steady_state", "regime", "period_blows", "floquet_max_abs")


@dataclass(frozen=True)
class ExudynModelRecord:
    """An Exudyn model run with items of one's own (models.solvers.exudyn_user_items): the formulation the
    scene asked for, the items added by kind, the scene's extensions, the step and the spectral radius the
    assembled system was given, the user's sensors that stored nothing, and whether a pre-step function set
    on ``mbs`` ran after the model's own; ``note`` what the other formulations do not see."""

    scene_formulation: str
    user_items: Mapping[str, int]
    extensions: tuple[str, ...]
    step_s: float | None
    spectral_radius_per_s: float | None
    note: str
    sensors_not_stored: tuple[str, ...] = ()
    foreign_pre_step: bool = False
