"""Detection of runs whose numbers must not be reported, and the step limits of explicit solvers.

A run is rejected when its states are non-finite or explode, when the energy stored in the
drill grows beyond the work put in (impossible for this dissipative model), or when the solver
stopped before the end time. Explicit solvers have a largest stable step h_max = factor /
|lambda|_max, the spectral radius of the first-order system matrix with the bit on the rock;
the factors were measured on the hard scenes (docs/stability.md).
"""

from __future__ import annotations

import numpy as np
from rpdrill.models.chain import axial_chain
from rpdrill.models.energy import energy_account
from rpdrill.models.pulse import impulse_per_blow_n_s
from rpdrill.models.results import SimulationResult
from rpdrill.models.scene import Scene

# Positions beyond this are not drilling: the solver has blown up (states near 1e300 seen with
# explicit solvers at too large a step, reported as success by the solver).
POSITION_LIMIT_M = 1e3

# Largest stable h * |lambda|_max measured on the hard scenes (docs/stability.md); None: no step
# is stable on the undamped modes (explicit Euler amplifies every oscillation).
STABLE_STEP_FACTOR: dict[str, float | None] = {
    "rk44": 2.4,
    "rk33": 1.6,
    "explicit_midpoint": 0.2,
    "explicit_euler": None,
}
SUGGESTED = "rk44"


class SimulationFailed(RuntimeError):
    """A run that diverged or did not reach its end time."""


class StepLimitWarning(UserWarning):
    """A fixed explicit step beyond the measured stability limit of the scene's stiffest mode."""


def spectral_radius_per_s(scene: Scene) -> float:
    """|lambda|_max of the first-order system z' = A z, A = [[0, I], [-M^-1 K, -M^-1 C]], with the
    bit on the rock (k_n, c_n added on the bit): what limits an explicit solver's step, the
    stiffest mode for light damping and the fastest decay for heavy damping."""
    chain = axial_chain(scene)
    stiffness, damping = chain.stiffness_matrix(), chain.damping_matrix()
    law = scene.rock_law()
    stiffness[chain.bit_body, chain.bit_body] += max(law.loading_stiffness_n_per_m, law.unloading_stiffness_n_per_m)
    damping[chain.bit_body, chain.bit_body] += law.damping_n_s_per_m
    inverse_mass = np.linalg.inv(chain.mass_matrix())
    n = chain.size
    system = np.block([[np.zeros((n, n)), np.eye(n)], [-inverse_mass @ stiffness, -inverse_mass @ damping]])
    return float(np.abs(np.linalg.eigvals(system)).max())


def largest_stable_step_s(scene: Scene, solver_type: str | None = None) -> float | None:
    """h_max of a fixed-step explicit solver (default: the scene's); None for implicit or adaptive ones."""
    solver_type = solver_type or scene.solver.type
    if solver_type not in STABLE_STEP_FACTOR:
        return None
    factor = STABLE_STEP_FACTOR[solver_type]
    return 0.0 if factor is None else factor / spectral_radius_per_s(scene)


def step_warning(scene: Scene) -> str | None:
    """A warning when a fixed explicit step exceeds the measured stability limit."""
    limit = largest_stable_step_s(scene)
    if limit is None or scene.solver.step_s <= limit:
        return None
    if limit == 0.0:
        return (f"scene '{scene.name}': solver {scene.solver.type} is unstable at any step on the undamped "
                f"modes of this drill; use {SUGGESTED} with step_s <= {largest_stable_step_s(scene, SUGGESTED):.3g}")
    return (f"scene '{scene.name}': solver.step_s {scene.solver.step_s:g} exceeds the stability limit "
            f"{limit:.3g} s of {scene.solver.type} for the stiffest mode of this drill")


def _remedy(scene: Scene) -> str:
    solver = scene.solver
    if solver.type in STABLE_STEP_FACTOR:
        limit = largest_stable_step_s(scene) or 0.0
        if limit > 0 and solver.step_s > limit:
            return f"try solver.step_s {0.5 * limit:.3g} (stability limit {limit:.3g} s)"
        return f"try solver.type {SUGGESTED} with solver.step_s {0.5 * largest_stable_step_s(scene, SUGGESTED):.3g}"
    return f"try solver.step_s {solver.step_s / 4:g} or solver.type {SUGGESTED}"


def _energy_blow_up_index(result: SimulationResult) -> int | None:
    """First step at which the energy accounted for (stored, dissipated, crushing) exceeds 1.5 times
    the work put in, plus one blow's energy scale: energy created by the integrator."""
    account = energy_account(result)
    work_in = np.maximum.accumulate(np.abs(account.impact_work_j) + np.abs(account.feed_work_j))
    created = -account.residual_j  # accounted - work in
    scene = result.scene
    blow_scale_j = impulse_per_blow_n_s(scene.impact) ** 2 / (2 * result.chain.bodies[result.chain.impact_body].mass_kg)
    bad = created > 0.5 * work_in + blow_scale_j
    return int(np.argmax(bad)) if bad.any() else None


def diverged_index(position_m: np.ndarray, velocity_m_per_s: np.ndarray) -> int | None:
    """First stored step with a non-finite state or a position beyond POSITION_LIMIT_M, if any."""
    states = np.column_stack([position_m, velocity_m_per_s])
    bad = ~np.isfinite(states).all(axis=1) | (np.abs(position_m) > POSITION_LIMIT_M).any(axis=1)
    return int(np.argmax(bad)) if bad.any() else None


def check_result(result: SimulationResult, solver_ok: bool, reached_s: float | None = None) -> None:
    """Raise :class:`SimulationFailed` naming scene, solver, time and a remedy if the run is unusable.

    ``reached_s`` is the solver's final time (default: the last stored sample)."""
    scene, solver = result.scene, result.scene.solver
    setting = f"solver {solver.type} with step_s {solver.step_s:g}"
    index = diverged_index(result.position_m, result.velocity_m_per_s)
    if index is None and "energy" in scene.needed_data():  # needs the force histories at every step
        index = _energy_blow_up_index(result)
    if index is not None:
        raise SimulationFailed(
            f"scene '{scene.name}': {setting} diverged at t = {result.time_s[index]:.6g} s; {_remedy(scene)}"
        )
    reached = reached_s if reached_s is not None else (result.time_s[-1] if len(result.time_s) else 0.0)
    if not solver_ok or reached < solver.end_time_s * (1 - 1e-9):
        raise SimulationFailed(
            f"scene '{scene.name}': {setting} stopped at t = {reached:.6g} s before end_time_s "
            f"{solver.end_time_s:g}; {_remedy(scene)}"
        )
