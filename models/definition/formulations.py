"""The formulations of the same model, by name: one registry that every command dispatches through.

``exudyn``: the multibody model (default). ``ode``: the paper's Eq. 4 as an event-located SciPy
ODE (independent cross-check). ``exact``: the piecewise-linear model propagated by matrix
exponentials between located switches (the reference and the fast path for large sweeps).

A scene chooses one in ``solver.formulation`` and gives its options next to it (the keys listed
here; a key of another formulation is an error). This registry is data: the names of each
formulation's implementation module in models.solvers and of its lighter ``checks`` module;
models.solvers.simulation.implementation imports and runs them.
"""

from __future__ import annotations

from dataclasses import dataclass

# accuracy tiers that every formulation resolves into its own settings (models.evaluation.solver_settings)
PRESETS = ("fast", "standard", "reference")
DEFAULT_PRESET = "standard"
EXUDYN_SOLVERS = ("rk67", "rk44", "rk33", "explicit_midpoint", "explicit_euler", "generalized_alpha",
                  "trapezoidal_index2", "dopri5", "ode23")
AUTOMATIC_STEP_SOLVERS = ("dopri5", "ode23")
IMPLICIT_SOLVERS = ("generalized_alpha", "trapezoidal_index2")  # the types that integrate constraints
ODE_METHODS = ("DOP853", "Radau", "LSODA")


@dataclass(frozen=True)
class Formulation:
    """A formulation: its implementation module (in models.solvers), the ``solver`` keys it takes, and the
    module with its ``unsupported`` check when that is lighter to import than the implementation
    (``checks``)."""

    name: str
    module: str
    option_keys: tuple[str, ...]
    summary: str
    checks: str | None = None


FORMULATIONS: dict[str, Formulation] = {f.name: f for f in (
    Formulation("exudyn", "exudyn_model",
                ("type", "step_s", "spectral_radius", "relative_tolerance", "absolute_tolerance"),
                "the Exudyn multibody model"),
    Formulation("exact", "exact_model",
                ("sample_interval_s", "min_switch_interval_s", "max_switches_per_blow", "wave_step_s"),
                "exact piecewise-linear propagation between located switches", checks="exact_system"),
    Formulation("ode", "ode_model",
                ("method", "relative_tolerance", "absolute_tolerance", "sample_interval_s"),
                "the paper's Eq. 4 as an event-located SciPy ODE"),
)}
COMMON_SOLVER_KEYS = ("formulation", "preset", "end_time_s", "output_interval_s", "steady_state")
# how a run reaches the drill's steady drilling (models.steady): ``time`` runs from the scene's start to its
# end time and averages after the transient blows; ``periodic`` solves for the periodic orbit (the time run
# the fallback where none is found)
STEADY_STATES = ("time", "periodic")
DEFAULT_STEADY_STATE = "time"
