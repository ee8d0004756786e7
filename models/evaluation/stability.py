"""Detection of runs whose numbers must not be reported, and the step limits of explicit solvers.

A run is rejected when its states are non-finite or explode, when the energy stored in the
drill grows beyond the work put in (impossible for this dissipative model), or when the solver
stopped before the end time. Explicit solvers have a largest stable step h_max = factor /
|lambda|_max, the spectral radius of the first-order system matrix with the bit on the rock;
the factors were measured on the hard scenes (docs/stability.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from statistics import median
from typing import TYPE_CHECKING

import numpy as np
from scipy.linalg import block_diag, eigvals

from ...rocklaw import RockLaw
from ..definition.scene import Scene, Torsion
from ..drill.chain import AxialChain, joined, torsion_first_order_matrix
from ..drill.pulse import impulse_per_blow_n_s
from .energy import energy_account
from .solver_settings import StepScales

if TYPE_CHECKING:
    from .prepared_run import PreparedRun
    from .results import SimulationResult

# Positions beyond this are not drilling: the solver has blown up (states near 1e300 seen with
# explicit solvers at too large a step, reported as success by the solver).
POSITION_LIMIT_M = 1e3

# Largest stable h * |lambda|_max measured on the hard scenes (docs/stability.md); None: no step
# is stable on the undamped modes (explicit Euler amplifies every oscillation).
STABLE_STEP_FACTOR: dict[str, float | None] = {
    "rk67": 1.0,
    "rk44": 2.4,
    "rk33": 1.6,
    "explicit_midpoint": 0.2,
    "explicit_euler": None,
}
SUGGESTED = "rk44"


class SimulationFailed(RuntimeError):
    """A run that diverged or did not reach its end time (a ``RuntimeError``; exit status 1 on the command line).

    The message names the scene, the time reached and why: the explicit step beyond its stability limit, a
    state that is not a number, or the error a piece of code of one's own raised in the run (its file and line).

    Parameters
    ----------
    *args
        The message, as for any exception.

    Examples
    --------
    >>> import rpdrill
    >>> issubclass(rpdrill.SimulationFailed, RuntimeError)
    True
    >>> try:
    ...     rpdrill.simulate("my_scene.yaml")  # doctest: +SKIP
    ... except rpdrill.SimulationFailed as error:
    ...     print(f"the run failed: {error}")
    """


class StepLimitWarning(UserWarning):
    """A fixed explicit step beyond the measured stability limit of the scene's stiffest mode; the message
    names the solver that is stable and its largest step.

    Parameters
    ----------
    *args
        The message, as for any warning.

    Examples
    --------
    >>> import warnings
    >>> import rpdrill
    >>> warnings.simplefilter("error", rpdrill.StepLimitWarning)  # doctest: +SKIP
    >>> rpdrill.simulate("my_scene.yaml")  # doctest: +SKIP
    Traceback (most recent call last):
    rpdrill.StepLimitWarning: scene 'my_scene': solver explicit_euler is unstable ...
    """


def contact_eigenvalues_per_s(chain: AxialChain, law: RockLaw, torsion: Torsion | None = None) -> np.ndarray:
    """The eigenvalues lambda of the first-order system z' = A z, A = [[0, I], [-M^-1 K, -M^-1 C]] of
    every link at its full stiffness, with the bit on the rock (its stiffest slope and its damper added
    on the bit), and the torsion line when given. Infinite when an entry of A overflows
    (:func:`fastest_element` names the scene key)."""
    stiffest = max(law.loading_stiffness_n_per_m, law.unloading_stiffness_n_per_m)
    with np.errstate(over="ignore"):
        system = chain.first_order_matrix(chain.links, stiffest, law.damping_n_s_per_m)[:, :-1]
        if torsion is not None:
            system = block_diag(system, torsion_first_order_matrix(torsion)[:, :-1])
    if not np.isfinite(system).all():
        return np.array([math.inf])
    return np.linalg.eigvals(system)


def spectral_radius_per_s(chain: AxialChain, law: RockLaw, torsion: Torsion | None = None) -> float:
    """|lambda|_max of :func:`contact_eigenvalues_per_s`: what limits an explicit solver's step, the
    stiffest mode for light damping and the fastest decay for heavy damping."""
    return float(np.abs(contact_eigenvalues_per_s(chain, law, torsion)).max())


def step_scales(chain: AxialChain, law: RockLaw, torsion: Torsion | None, blow_period_s: float) -> StepScales:
    """The :class:`StepScales` of a drill on its rock, blows ``blow_period_s`` apart."""
    return scales_of(contact_eigenvalues_per_s(chain, law, torsion), blow_period_s,
                     law.damping_n_s_per_m / chain.bodies[chain.bit_body].mass_kg)


def scales_of(eigenvalues: np.ndarray, blow_period_s: float, damper_rate_per_s: float) -> StepScales:
    """The :class:`StepScales` of a system of these first-order eigenvalues, blows ``blow_period_s`` apart:
    |lambda|_max, the largest |lambda| still ringing at the next blow (-Re(lambda) T < 1) and c_n / m_bit."""
    ringing = np.abs(eigenvalues[-eigenvalues.real * blow_period_s < 1.0])
    return StepScales(float(np.abs(eigenvalues).max(initial=0.0)), float(ringing.max(initial=0.0)), damper_rate_per_s)


def wave_bodies_eigenvalues_per_s(chain: AxialChain, law: RockLaw) -> np.ndarray:
    """The eigenvalues of what Exudyn integrates in a scene with wave rods (models.waves.exudyn_waves): the
    bodies with mass, the links between them (and ground), the rock on a bit with mass at its stiffest, and
    the dashpot Z of every rod end joined rigidly to one of them; the faces, the rods and what touches a face
    are the wave element's, integrated exactly (not on the explicit solver's step), so a rigid joint's
    infinite stiffness and a face's zero mass take no part."""
    masses = np.array([body.mass_kg for body in chain.bodies])
    bodies = np.flatnonzero(masses > 0)
    if not len(bodies):
        return np.zeros(0)
    index = {int(node): i for i, node in enumerate(bodies)}
    n = len(bodies)
    stiffness, damping = np.zeros((n, n)), np.zeros((n, n))
    for link in chain.links:
        if link.rigid or link.body_b not in index or (link.body_a is not None and link.body_a not in index):
            continue
        ends = [(index[link.body_b], 1.0)] + ([] if link.body_a is None else [(index[link.body_a], -1.0)])
        for i, si in ends:
            for j, sj in ends:
                stiffness[i, j] += si * sj * link.stiffness_n_per_m
                damping[i, j] += si * sj * link.damping_n_s_per_m
    if chain.bit_body in index:
        bit = index[chain.bit_body]
        stiffness[bit, bit] += max(law.loading_stiffness_n_per_m, min(law.unloading_stiffness_n_per_m, 1e300))
        damping[bit, bit] += law.damping_n_s_per_m
    owner = joined(chain.size, chain.rigid_pairs(), frozenset(index))
    for rod in chain.waves:
        for node in (rod.top, rod.bottom):
            if owner[node] in index:  # a face joined rigidly to a body with mass: the rod's dashpot on it
                damping[index[owner[node]], index[owner[node]]] += rod.impedance_n_s_per_m
    return second_order_eigenvalues_per_s(np.diag(masses[bodies]), stiffness, damping)


def second_order_eigenvalues_per_s(mass: np.ndarray, stiffness: np.ndarray, damping: np.ndarray) -> np.ndarray:
    """The finite eigenvalues lambda of M q'' + D q' + K q = 0 (any system: an assembled Exudyn one), from
    the pencil [[0, I], [-K, -D]] z = lambda [[I, 0], [0, M]] z (a coordinate without mass gives an infinite
    one, left out: it sets no step of an explicit solver, which cannot run it anyway)."""
    n = len(mass)
    with np.errstate(all="ignore"):
        if not (np.isfinite(mass).all() and np.isfinite(stiffness).all() and np.isfinite(damping).all()):
            return np.array([math.inf])
        system = np.block([[np.zeros((n, n)), np.eye(n)], [-stiffness, -damping]])
        weights = np.block([[np.eye(n), np.zeros((n, n))], [np.zeros((n, n)), mass]])
        eigenvalues = eigvals(system, weights)
    return eigenvalues[np.isfinite(eigenvalues)]


@dataclass(frozen=True)
class FastestElement:
    """The element of the highest rate, sqrt(k (1/m_a + 1/m_b)) of a spring or c (1/m_a + 1/m_b) of a
    damper, in 1/s (|lambda|_max is of that order), with the two scene keys that set it: ``key`` the
    one that departs more from the drill's other values (the stiffness or damping against the median
    of all stiffnesses or dampers, the mass against the median mass), ``other_key`` the other."""

    rate_per_s: float
    key: str
    value: float
    other_key: str
    other_value: float


# Torsion has one element: its values are compared with those of studies/scenes/paper_base.yaml.
TORSION_REFERENCE = {"inertia_kg_m2": 2.0, "stiffness_n_m_per_rad": 1e5, "damping_n_m_s_per_rad": 200.0}


def _mass_key(scene: Scene, body: str) -> tuple[str, float]:
    """The key that sets a drill-string body's (segment) mass: mass_kg, segments, or the rod's density."""
    values = scene.drill_string.bodies[body]
    key = "mass_kg" if values.mass_kg is not None else "segments" if values.segments > 1 else \
        "mass_per_length_kg_per_m" if values.mass_per_length_kg_per_m is not None else "density_kg_per_m3"
    return f"drill_string.bodies.{body}.{key}", getattr(values, key)


def fastest_element(scene: Scene, chain: AxialChain, law: RockLaw, torsion: Torsion | None = None) -> FastestElement:
    """The element of the highest rate (:class:`FastestElement`) of :func:`element_rates` (a rate of 0 when
    every element acts on a wave rod's massless face: those are integrated exactly, models.waves)."""
    rates = element_rates(scene, chain, law, torsion)
    if not rates:
        return FastestElement(0.0, "drill_string", 0.0, "drill_string", 0.0)
    return max(rates, key=lambda element: element.rate_per_s)


def element_rates(scene: Scene, chain: AxialChain, law: RockLaw, torsion: Torsion | None = None) -> list[FastestElement]:
    """The rate of every element (:class:`FastestElement`): the rock's spring and damper under the
    bit, every link's spring and damper, the torsion line's when given; not those that move a wave rod's
    massless face (no rate of a mass; models.waves integrates them exactly) nor a rigid joint."""
    owner = {i: name for name, (first, last) in chain.groups.items() for i in range(first, last + 1)}
    masses = [body.mass_kg for body in chain.bodies]
    connectors = scene.drill_string.connectors
    rock_stiffness = max(law.loading_stiffness_n_per_m, law.unloading_stiffness_n_per_m)
    rock_key = "rock.unloading_stiffness_n_per_m" if scene.rock.law == "bilinear" else "rock.stiffness_n_per_m"
    # (stiffness or damping, its key, the bodies it moves, spring or damper)
    elements = [(rock_stiffness, rock_key, [chain.bit_body], True),
                (law.damping_n_s_per_m, "rock.damping_n_s_per_m", [chain.bit_body], False)]
    for link in chain.links:
        path = f"drill_string.connectors.{link.name}" if link.name in connectors else \
            f"drill_string.bodies.{owner[link.body_b]}"
        moved = [i for i in (link.body_a, link.body_b) if i is not None]
        elements += [(link.stiffness_n_per_m, f"{path}.stiffness_n_per_m" if link.name in connectors
                      else f"{path}.youngs_modulus_pa", moved, True),
                     (link.damping_n_s_per_m, f"{path}.damping_n_s_per_m", moved, False)]
    typical = {spring: median([e[0] for e in elements if e[3] == spring and e[0] > 0] or [1.0]) for spring in (True, False)}
    typical_mass = median([m for m in masses if m > 0] or [1.0])
    candidates = []
    for value, key, moved, spring in elements:
        if any(masses[i] == 0.0 for i in moved) or math.isinf(value):
            continue
        inverse_mass = sum(1.0 / masses[i] for i in moved)
        rate = math.sqrt(value * inverse_mass) if spring else value * inverse_mass
        lightest = min(moved, key=lambda i: masses[i])
        departs = math.log10(value) - math.log10(typical[spring]) if value > 0 else -math.inf
        pair = ((key, value), _mass_key(scene, owner[lightest]))
        first, second = pair if departs >= math.log10(typical_mass) - math.log10(masses[lightest]) else pair[::-1]
        candidates.append(FastestElement(rate, *first, *second))
    if torsion is not None:
        for key, spring in (("stiffness_n_m_per_rad", True), ("damping_n_m_s_per_rad", False)):
            value, inertia = getattr(torsion, key), torsion.inertia_kg_m2
            rate = math.sqrt(value / inertia) if spring else value / inertia
            pair = ((f"torsion.{key}", value), ("torsion.inertia_kg_m2", inertia))
            departs = math.log10(value) - math.log10(TORSION_REFERENCE[key]) if value > 0 else -math.inf
            first, second = pair if departs >= math.log10(TORSION_REFERENCE["inertia_kg_m2"]) - math.log10(inertia) else pair[::-1]
            candidates.append(FastestElement(rate, *first, *second))
    return candidates


def spring_spread(scene: Scene, chain: AxialChain, law: RockLaw) -> tuple[str, float, float, float]:
    """The stiffest spring of the drill and the rock (its key, the key's value, its stiffness [N/m]) and
    the softest spring's stiffness (a rod segment's from its Young's modulus: the key is the modulus)."""
    owner = {i: name for name, (first, last) in chain.groups.items() for i in range(first, last + 1)}
    rock_key = "rock.unloading_stiffness_n_per_m" if scene.rock.law == "bilinear" else "rock.stiffness_n_per_m"
    rock = max(law.loading_stiffness_n_per_m, law.unloading_stiffness_n_per_m)
    springs = [(rock, rock_key, getattr(scene.rock, rock_key.split(".")[1]))]
    for rod in chain.waves:  # a wave rod is a spring E A / L in the statics (models.waves.statics)
        if rod.name in scene.drill_string.bodies:
            springs.append((rod.stiffness_n_per_m, f"drill_string.bodies.{rod.name}.youngs_modulus_pa",
                            scene.drill_string.bodies[rod.name].youngs_modulus_pa))
    for link in chain.links:
        if 0 < link.stiffness_n_per_m < math.inf:  # a rigid joint is one point in the statics, not a spring
            connector = scene.drill_string.connectors.get(link.name)
            key = f"drill_string.connectors.{link.name}.stiffness_n_per_m" if connector is not None else \
                f"drill_string.bodies.{owner[link.body_b]}.youngs_modulus_pa"
            value = link.stiffness_n_per_m if connector is not None else \
                scene.drill_string.bodies[owner[link.body_b]].youngs_modulus_pa
            springs.append((link.stiffness_n_per_m, key, value))
    stiffest = max(springs)
    return stiffest[1], stiffest[2], stiffest[0], min(springs)[0]


def largest_stable_step_s(simulation: PreparedRun, solver_type: str | None = None) -> float | None:
    """h_max of a fixed-step explicit solver (default: the simulation's); None for implicit or
    adaptive ones."""
    solver_type = solver_type or simulation.settings.type
    if solver_type not in STABLE_STEP_FACTOR:
        return None
    factor = STABLE_STEP_FACTOR[solver_type]
    if simulation.dynamic_chain.waves:  # what Exudyn integrates beside the wave element
        rates = np.abs(wave_bodies_eigenvalues_per_s(simulation.chain, simulation.rock))
        if simulation.torsion is not None:
            rates = np.concatenate([rates, np.abs(np.linalg.eigvals(
                torsion_first_order_matrix(simulation.torsion)[:, :-1]))])
        radius = float(rates.max(initial=0.0))
        if radius == 0.0:
            return math.inf
    else:
        radius = simulation.spectral_radius_per_s or spectral_radius_per_s(simulation.chain, simulation.rock,
                                                                            simulation.torsion)
    return 0.0 if factor is None else factor / radius


def step_warning(simulation: PreparedRun) -> str | None:
    """A warning when a fixed explicit step exceeds the measured stability limit."""
    settings = simulation.settings
    limit = largest_stable_step_s(simulation)
    if limit is None or settings.step_s <= limit:
        return None
    if limit == 0.0:
        return (f"scene '{simulation.name}': solver {settings.type} is unstable at any step on the undamped "
                f"modes of this drill; use {SUGGESTED} with step_s <= "
                f"{largest_stable_step_s(simulation, SUGGESTED):.3g}")
    return (f"scene '{simulation.name}': solver.step_s {settings.step_s:g} exceeds the stability limit "
            f"{limit:.3g} s of {settings.type} for the stiffest mode of this drill")


def _remedy(simulation: PreparedRun) -> str:
    """What to try after a run failed: never a step larger than half the one that failed."""
    settings = simulation.settings
    smaller = 0.5 * settings.step_s
    if settings.type in STABLE_STEP_FACTOR:
        limit = largest_stable_step_s(simulation) or 0.0
        if limit > 0 and settings.step_s > limit:
            return f"try solver.step_s {min(0.5 * limit, smaller):.3g} (stability limit {limit:.3g} s)"
        suggested = 0.5 * largest_stable_step_s(simulation, SUGGESTED)
        if settings.type != SUGGESTED and suggested < settings.step_s:
            return f"try solver.type {SUGGESTED} with solver.step_s {suggested:.3g}"
        return (f"try solver.step_s {smaller:.3g} (the step was within the stability limit of the linearised "
                "system, so what diverged is stiffer than it: a contact, or an item of one's own)")
    return f"try solver.step_s {settings.step_s / 4:g} or solver.type {SUGGESTED}"


def _energy_blow_up_index(result: SimulationResult) -> int | None:
    """First step at which the energy accounted for (stored, dissipated, crushing) exceeds 1.5 times
    the work put in, plus one blow's energy scale: energy created by the integrator."""
    account = energy_account(result)
    if not account.complete:  # an item of one's own unaccounted for: no balance to check
        return None
    user_work = 0.0 if account.user is None else np.abs(account.user.work_in_j)
    work_in = np.maximum.accumulate(np.abs(account.impact_work_j) + np.abs(account.feed_work_j) + user_work)
    created = -account.residual_j  # accounted - work in
    chain = result.chain
    blow_scale_j = impulse_per_blow_n_s(result.scene.impact) ** 2 / (2 * chain.bodies[chain.impact_body].mass_kg)
    bad = created > 0.5 * work_in + blow_scale_j
    return int(np.argmax(bad)) if bad.any() else None


def diverged_index(position_m: np.ndarray, velocity_m_per_s: np.ndarray) -> int | None:
    """First stored step with a non-finite state or a position beyond POSITION_LIMIT_M, if any."""
    states = np.column_stack([position_m, velocity_m_per_s])
    bad = ~np.isfinite(states).all(axis=1) | (np.abs(position_m) > POSITION_LIMIT_M).any(axis=1)
    return int(np.argmax(bad)) if bad.any() else None


def check_result(result: SimulationResult, solver_ok: bool, reached_s: float | None = None) -> None:
    """Raise :class:`SimulationFailed` naming scene, solver, time and a remedy if an Exudyn run is
    unusable. ``reached_s`` is the solver's final time (default: the last stored sample)."""
    simulation = result.simulation
    settings = simulation.settings
    setting = f"solver {settings.type} with step_s {settings.step_s:g}"
    index = diverged_index(result.position_m, result.velocity_m_per_s)
    if index is None and "energy" in simulation.needed_data:  # needs the force histories at every step
        index = _energy_blow_up_index(result)
    if index is not None:
        raise SimulationFailed(f"scene '{simulation.name}': {setting} diverged at t = "
                               f"{result.time_s[index]:.6g} s; {_remedy(simulation)}")
    reached = reached_s if reached_s is not None else (result.time_s[-1] if len(result.time_s) else 0.0)
    if not solver_ok or reached < settings.end_time_s * (1 - 1e-9):
        raise SimulationFailed(
            f"scene '{simulation.name}': {setting} stopped at t = {reached:.6g} s before end_time_s "
            f"{settings.end_time_s:g}; {_remedy(simulation)}"
        )
