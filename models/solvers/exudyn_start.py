"""The start of a built Exudyn model (models.solvers.exudyn_model) that holds items of one's own (a scene's
extensions, or items added by hand before it runs).

* **The preloaded start.** ``start: preloaded`` is the static equilibrium under the feed with the bit on the
  rock. The chain's own preload (models.drill.chain.static_preload_m) knows the scene's drill only; a load, a
  spring or a constraint of one's own moves the equilibrium (a 16.6 kN load on the pipe of paper_base doubles
  the feed: the pipe starts at 30.5 mm, not 15.3 mm). So the start of a model with such items is the
  equilibrium of the assembled system, found by Newton's method on Exudyn's own static equations:
  the residual r(q, lambda) of every item's forces at rest (the loads at t = 0, the piston's prescribed blow
  switched off) and the constraints, and its Jacobian (Exudyn's ``MainSolverStatic``:
  ``ComputeNewtonResidual``, ``ComputeNewtonJacobian``), J [dq; dlambda] = -r, from the chain's preload. The
  drill's links and the rock are linear within their modes, so it converges in a step or two. Solved for are
  the drill's bodies and every coordinate joined to them (through the Jacobian): a coordinate of one's own
  that nothing joins to the drill (a reference oscillator on ground) keeps the start its extension gave it,
  the piston's bodies stay parked behind the impact body and the torsion line at its static angle when no
  spring holds it. No equilibrium (a coordinate no spring holds, a load that pulls the
  bit off the rock) or one where the rock takes its crushing threshold is refused naming the items (InputError).
  A drill with wave rods is refused: its rods are not Exudyn items, so the assembled system's statics would
  miss them.
* **Constraints and the solver.** Exudyn's explicit solvers (RK, DOPRI5, ...) eliminate a coordinate
  constraint to ground and integrate no other constraint (``ModelError`` when they start); an item of one's own
  with algebraic equations on an explicit ``solver.type`` is refused before the run, naming it, the extension
  that added it and the solver type (:func:`check_constraints`).
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from dataclasses import replace
from typing import Any

import numpy as np

from ...rocklaw.exudyn_module import exu  # first: it chooses Exudyn's compiled module

# isort: split
from ..definition.formulations import IMPLICIT_SOLVERS
from ..definition.validation import InputError
from ..drill.chain import STATIC_CONDITION_LIMIT
from .exudyn_messages import exudyn_messages_as_warnings
from .exudyn_user_items import coordinate_names

MAX_ITERATIONS = 30
STEP_TOLERANCE = 1e-13  # a Newton step below this fraction of the largest coordinate (1 mm at least): converged
RESIDUAL_TOLERANCE = 1e-8  # the residual force at convergence, as a fraction of the largest force acting


def preloaded_start(model: Any) -> bool:
    """Whether a built model starts from the static preload of the scene (not from a state in motion: a
    steady-state run's start, models.steady)."""
    simulation = model.simulation
    followed = simulation.extension_coordinates
    return simulation.scene.start == "preloaded" and simulation.initial_velocities_m_per_s is None \
        and (followed is None or followed.start is None)


def start_assembled(model: Any) -> None:
    """A built model's start and solver once items of one's own were added (module doc): the constraints checked
    against the solver type, the preloaded start solved on the assembled system."""
    check_constraints(model)
    if preloaded_start(model):
        solve_preload(model)


def item_origin(model: Any, index: int) -> str:
    """What added object ``index``: ``extension 'NAME' (module:function)`` (the scene's extensions are applied and
    prepared at the build, before any item added by hand: models.solvers.exudyn_model), or ``an item added to
    model.mbs``."""
    extensions = model.simulation.scene.extensions or {}
    prepared = model._prepared_items["objects"]
    if extensions and (prepared == model.built_items["objects"] or index < prepared):
        return " or ".join(f"extension {name!r} ({extension.function})" for name, extension in extensions.items())
    return "an item added to model.mbs"


def _object_label(mbs: Any, index: int) -> str:
    item = mbs.GetObject(index)
    return f"{item['objectType']} {item['name']!r} (object {index})"


def _ground_constraint(mbs: Any, item: dict[str, Any]) -> bool:
    """A coordinate constraint with one end on ground, which Exudyn's explicit solvers eliminate."""
    if item["objectType"] != "ConnectorCoordinate":
        return False
    nodes = [mbs.GetMarker(marker).get("nodeNumber") for marker in item["markerNumbers"]]
    return any(node is not None and "Ground" in mbs.GetNode(node)["nodeType"] for node in nodes)


def check_constraints(model: Any) -> None:
    """InputError naming the item, what added it and ``solver.type`` where an item of one's own has algebraic
    equations (a constraint) that the scene's explicit solver cannot integrate (module doc)."""
    settings = model.simulation.settings
    mbs = model.mbs
    if settings.type in IMPLICIT_SOLVERS or not mbs.systemData.AEsize():
        return
    for index in range(model.built_items["objects"], mbs.systemData.NumberOfObjects()):
        item = mbs.GetObject(index)
        if len(mbs.systemData.GetObjectLTGAE(index)) and not _ground_constraint(mbs, item):
            given = "solver.type" if model.simulation.scene.solver.type is not None else \
                f"solver.type, chosen by the {settings.preset or 'standard'} preset"
            raise InputError(
                f"scene '{model.simulation.name}': {item_origin(model, index)} adds the constraint "
                f"{_object_label(mbs, index)}, which Exudyn's explicit solver {settings.type!r} ({given}) cannot "
                "integrate (it eliminates only a coordinate constraint to ground); give solver.type: "
                f"{' or '.join(IMPLICIT_SOLVERS)} (implicit; check its accuracy with a smaller solver.step_s), or "
                "join the bodies with a stiff spring-damper instead")


@contextlib.contextmanager
def _blow_switched_off(model: Any) -> Iterator[None]:
    """The prescribed blow's load function off for the statics (a rectangular pulse is on at t = 0)."""
    mbs = model.mbs  # the build's first load with a function: the blow's, whose function is the first the model keeps
    load = next((i for i in range(model.built_items["loads"]) if mbs.GetLoad(i)["loadUserFunction"]), None)
    try:
        if load is not None:
            mbs.SetLoadParameter(load, "loadUserFunction", 0)
        yield
    finally:
        if load is not None:
            mbs.SetLoadParameter(load, "loadUserFunction", model.symbolic_functions[0])


def _held_coordinates(model: Any) -> set[int]:
    """The ODE2 indices the statics do not solve for: the piston's bodies, a torsion line no spring holds."""
    mbs, simulation = model.mbs, model.simulation
    held = {mbs.GetNodeODE2Index(body.node) for body in list(model.bodies.values())[simulation.chain.size:]}
    if model.torsion is not None and simulation.torsion.stiffness_n_m_per_rad == 0:
        held.add(mbs.GetNodeODE2Index(model.torsion.node))
    return held


def _joined_to_drill(model: Any, jacobian: np.ndarray, candidates: list[int]) -> list[int]:
    """The ``candidates`` (ODE2 and AE indices) joined to the drill's bodies through nonzero entries of the
    static Jacobian (a graph search from the bodies' coordinates)."""
    mbs = model.mbs
    start = {mbs.GetNodeODE2Index(body.node) for body in list(model.bodies.values())[:model.simulation.chain.size]}
    allowed = set(candidates)
    reached, frontier = set(start) & allowed, list(set(start) & allowed)
    coupled = (jacobian != 0) | (jacobian.T != 0)
    while frontier:
        row = frontier.pop()
        for column in np.flatnonzero(coupled[row]):
            if column in allowed and column not in reached:
                reached.add(int(column))
                frontier.append(int(column))
    return sorted(reached)


def _coordinate_label(model: Any, coordinate: int) -> str:
    """A coordinate as a message names it: the drill's body, or the object of one's own on its node."""
    name = coordinate_names(model)[coordinate]
    return f"the body {name!r}" if name in model.bodies else f"{name!r}"


def _refusal(model: Any, why: str) -> InputError:
    scene = model.simulation.scene
    added = f"extensions {', '.join(scene.extensions)}" if scene.extensions else "the items added to model.mbs"
    return InputError(f"scene '{scene.name}': start: 'preloaded' with {added}: {why}; use start: rest")


def solve_preload(model: Any) -> None:
    """Start a built model with items of one's own at the static equilibrium of its assembled system (module
    doc): its nodes' initial coordinates, the rock's initial state and ``model.simulation``'s start set there.
    InputError where there is none (named), or where the rock takes its threshold there."""
    if model.waves is not None:
        raise _refusal(model, "the wave rods are not Exudyn items, so the static equilibrium of the assembled "
                              "system cannot be solved with them")
    mbs = model.mbs
    data = mbs.systemData
    settings = exu.SimulationSettings()
    settings.solution.file.write = False
    settings.staticSolver.verboseMode = 0
    settings.staticSolver.useLoadFactor = False
    settings.show.statistics = False
    settings.show.computationTime = False
    n2, nae = data.ODE2Size(), data.AEsize()
    held = _held_coordinates(model)
    q = np.array(data.GetODE2Coordinates(configuration=exu.ConfigurationType.Initial), dtype=float)
    multipliers = np.zeros(nae)
    solver = exu.MainSolverStatic()
    with exudyn_messages_as_warnings(model.simulation.name), _blow_switched_off(model):
        solver.InitializeSolver(mbs, settings)
        data.SetODE2Coordinates_t(np.zeros(n2).tolist(), configuration=exu.ConfigurationType.Current)
        residual = _residual(solver, mbs, settings, q, multipliers)
        solver.ComputeNewtonJacobian(mbs, settings)
        free = _joined_to_drill(model, np.array(solver.GetSystemJacobian(), dtype=float),
                                [i for i in range(n2 + nae) if i not in held])
        scale = max(float(np.abs(residual[free]).max(initial=0.0)), model.simulation.feed_total_n, 1.0)
        for _ in range(MAX_ITERATIONS):
            solver.ComputeNewtonJacobian(mbs, settings)
            jacobian = np.array(solver.GetSystemJacobian(), dtype=float)[np.ix_(free, free)]
            if not np.all(np.isfinite(jacobian)) or np.linalg.cond(jacobian) > STATIC_CONDITION_LIMIT:
                _check_rock(model, q)  # a rock at its threshold holds nothing more: the likelier cause
                raise _refusal(model, _singular(model, jacobian, free))
            step = np.linalg.solve(jacobian, -residual[free])
            update = np.zeros(n2 + nae)
            update[free] = step
            q, multipliers = q + update[:n2], multipliers + update[n2:]
            residual = _residual(solver, mbs, settings, q, multipliers)
            if np.abs(update[:n2]).max(initial=0.0) <= STEP_TOLERANCE * max(np.abs(q).max(), 1e-3) \
                    and np.abs(residual[free]).max(initial=0.0) <= RESIDUAL_TOLERANCE * scale:
                break
        else:
            raise _refusal(model, f"Newton's method on the assembled system's static equations did not converge in "
                                  f"{MAX_ITERATIONS} steps (residual {np.abs(residual[free]).max():.3g} N)")
    _start_at(model, q)


def _residual(solver: Any, mbs: Any, settings: Any, q: np.ndarray, multipliers: np.ndarray) -> np.ndarray:
    """The static residual at (q, lambda): forces at rest minus the constraints' reactions, then the
    constraints' equations (Exudyn's static solver, at the system's current configuration)."""
    mbs.systemData.SetODE2Coordinates(q.tolist(), configuration=exu.ConfigurationType.Current)
    if multipliers.size:
        mbs.systemData.SetAECoordinates(multipliers.tolist(), configuration=exu.ConfigurationType.Current)
    solver.ComputeNewtonResidual(mbs, settings)
    return np.array(solver.GetSystemResidual(), dtype=float)


def _singular(model: Any, jacobian: np.ndarray, free: list[int]) -> str:
    """Why the static equations have no unique solution: the coordinates of the stiffness's null vector."""
    if not np.all(np.isfinite(jacobian)):
        return "the assembled system's stiffness is not finite"
    _, _, vh = np.linalg.svd(jacobian)
    null = np.abs(vh[-1])
    n2 = model.mbs.systemData.ODE2Size()
    loose = [free[i] for i in np.flatnonzero(null > 0.1 * null.max()) if free[i] < n2]
    names = ", ".join(dict.fromkeys(_coordinate_label(model, i) for i in loose)) or "a constraint's reaction"
    return (f"the assembled system has no static equilibrium: nothing holds {names} at rest (a coordinate no "
            "spring holds, or the bit pulled off the rock)")


def _check_rock(model: Any, q: np.ndarray) -> None:
    """InputError when the bit at ``q`` presses the rock to its crushing threshold (static_preload_m's rule)."""
    law, bit = model.rock.rock, model.bodies[model.chain.bodies[model.chain.bit_body].name].node
    rock_force = law.loading_stiffness_n_per_m * max(float(q[model.mbs.GetNodeODE2Index(bit)]), 0.0)
    if rock_force >= law.threshold_n:
        raise _refusal(model, f"the static loads alone crush the rock (rock force {rock_force:.4g} N >= rock "
                              f"threshold {law.threshold_n:.4g} N)")


def _start_at(model: Any, q: np.ndarray) -> None:
    """Every node's initial coordinates from ``q``, the piston re-parked behind the impact body, the rock's state
    and ``model.simulation``'s start there; InputError when the rock takes its threshold there."""
    mbs, simulation = model.mbs, model.simulation
    nodes = [body.node for body in model.bodies.values()]
    chain = np.array([q[mbs.GetNodeODE2Index(node)] for node in nodes[:simulation.chain.size]])
    if simulation.piston is not None:  # parked behind the impact body where it now is
        for node, value in zip(nodes[simulation.chain.size:], simulation.piston.parked(chain)[simulation.chain.size:],
                               strict=True):
            q[mbs.GetNodeODE2Index(node)] = value
    _check_rock(model, q)
    law = model.rock.rock
    for node in range(mbs.systemData.NumberOfNodes()):
        indices = [int(i) for i in mbs.systemData.GetNodeLTGODE2(node)]
        if indices and "Ground" not in mbs.GetNode(node)["nodeType"]:
            mbs.SetNodeParameter(node, "initialCoordinates", [float(q[i]) for i in indices])
    mbs.Assemble()
    state = law.return_map(float(chain[simulation.chain.bit_body]), law.initial_state())
    model.rock.start_at(state)
    model.simulation = replace(simulation, initial_positions_m=chain, initial_rock_state=state)
