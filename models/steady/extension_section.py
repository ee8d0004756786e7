"""The coordinates an Exudyn scene's extensions add, taken into the Poincare section.

A scene's extensions (models.definition.extensions) may add bodies of their own to the Exudyn model: a clamp
on the collar is a mass on its own node, held by a spring-damper. Its coordinates are part of the drill's
state: a periodic orbit must return them too, or every run of the blow map would start the clamp afresh
(at rest where the extension puts it) and the orbit found would be of another machine. So every ODE2
coordinate of the assembled system that the model's own build did not make is followed: its position and
its velocity are appended to the section state y (models.steady.section), the Exudyn model starts them
there and records them (models.solvers.exudyn_user_items.follow_extension_coordinates).

**Which coordinates drift with the hole.** Relative to the bottom, a coordinate moves by e_j when the whole
drill moves by one: the section holds q_j - e_j x_bottom. The drill string's bodies (a piston's too) have
e = 1, the torsion line e = 0; an extension's e_u are those for which the shift changes no force of the
assembled system: K e = 0, with K the stiffness of the system linearised by Exudyn
(models.solvers.exudyn_user_items.linearised_system; the rock switched off, as it moves with the bottom,
and the chain's nonlinear links closed). The rows of the extension's coordinates give
K_uu e_u = -K_uo e_o; e_u = 1 for a clamp held on a body by a spring (of any stiffness), 0 for a
coordinate no spring ties to the string (a rotation with a spring to ground). Where the rows of the
string's bodies then leave a force (K e != 0 beyond GROUNDED, checked also where the extensions add no
coordinates: a spring of theirs to ground on a body that moves with the drill), the drill cannot repeat relative to the bottom, as with a link of the scene's own to
ground (models.steady.section.drift_problem). A coordinate that no spring holds (K_uu singular: a free
mass, a freely turning shaft) has no shift that the forces decide, and its position may wander from
blow to blow: the steady state is refused naming it. So are first-order (ODE1) and data coordinates and
per-step functions an extension adds (model.add_pre_step): states the section does not hold.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..solvers.exudyn_model import ExudynModel, build_exudyn
from ..solvers.exudyn_user_items import (
    closed_chain,
    extension_nodes,
    initial_coordinates,
    linearised_system,
    node_labels,
)
from ..solvers.simulation import ExtensionCoordinates, Simulation
from .steady_state import SteadyStateUnavailable

# a force K e beyond this fraction of the largest stiffness: held to ground. K e is exactly 0 for the drill's
# and a clamp's linear springs and 5e-17 of it for a spring-force user function's (Exudyn's numerical
# linearisation); a spring of 1 N/m to ground on the test drill (tests/pipe_drill.yaml) is 6e-11 of it
GROUNDED = 1e-12
SINGULAR = 1e-12  # a pivot of K_uu below this fraction of its largest: a coordinate no spring holds


def with_extension_coordinates(simulation: Simulation) -> Simulation:
    """``simulation`` with the ODE2 coordinates its Exudyn extensions add taken into the section (module
    doc): their labels, drift and start; unchanged when they add none or the formulation builds no Exudyn
    model. SteadyStateUnavailable naming the extensions where the section cannot hold what they add."""
    if simulation.settings.formulation != "exudyn" or not simulation.scene.extensions \
            or simulation.extension_coordinates is not None:
        return simulation
    model = build_exudyn(simulation)
    _refuse_hidden_states(model)
    nodes = extension_nodes(model)
    indices = [i for _, node_indices in nodes for i in node_indices]
    labels = [label for node, node_indices in nodes for label in node_labels(model, node, len(node_indices))]
    drift = _drift(model, indices, labels)  # also where they add no coordinates: a spring to ground
    # the start the model solved (start: preloaded: the assembled system's equilibrium, models.solvers.exudyn_start)
    simulation = replace(simulation, initial_positions_m=model.simulation.initial_positions_m,
                         initial_rock_state=model.simulation.initial_rock_state)
    if not nodes:
        return simulation
    start = initial_coordinates(model, indices)
    return replace(simulation, extension_coordinates=ExtensionCoordinates(
        tuple(labels), tuple(float(e) for e in drift), tuple(float(v) for v in start)))


def _extensions(model: ExudynModel) -> str:
    scene = model.simulation.scene
    return f"scene '{scene.name}': extensions {', '.join(scene.extensions or {})}"


def _refuse_hidden_states(model: ExudynModel) -> None:
    """SteadyStateUnavailable where the extensions add states the section does not hold (module doc)."""
    data = model.mbs.systemData
    hidden = [f"{count} {kind} coordinates" for count, kind in ((data.ODE1Size(), "first-order (ODE1)"),
                                                               (data.DataSize(), "data")) if count]
    if model.pre_steps or model._replaced() is not None:
        hidden.append("a per-step function")
    if hidden:
        raise SteadyStateUnavailable(
            f"{_extensions(model)} add {' and '.join(hidden)} to the Exudyn model: a state the Poincare section of "
            "the steady-state solver does not hold (it holds the ODE2 coordinates and velocities), so an orbit "
            "could not return it; use solver.steady_state: time")


def _drift(model: ExudynModel, indices: list[int], labels: list[str]) -> np.ndarray:
    """e_u of the extension's coordinates (module doc: K_uu e_u = -K_uo e_o, then K e = 0 checked)."""
    mbs = model.mbs
    _, stiffness, _, constraints = linearised_system(mbs, model._settings, *closed_chain(model, rock=False))
    shift = np.zeros(len(stiffness))
    for body in model.bodies.values():  # the chain's bodies (a piston's too) move with the drill
        shift[mbs.GetNodeODE2Index(body.node)] = 1.0
    held = stiffness[np.ix_(indices, indices)]
    pivots = np.abs(np.linalg.qr(held, mode="r").diagonal()) if held.size else np.zeros(0)
    loose = [labels[i] for i, pivot in enumerate(pivots) if pivot <= SINGULAR * np.abs(held).max()]
    if loose:
        raise SteadyStateUnavailable(
            f"{_extensions(model)} add the coordinate(s) {', '.join(loose)}, which no spring holds: no force decides "
            "how they move with the drilling drill, so their position need not repeat from blow to blow; hold "
            "them with a spring (to the drill or to ground), or use solver.steady_state: time")
    if indices:
        shift[indices] = np.linalg.solve(held, -stiffness[indices] @ shift)
    force = np.abs(stiffness @ shift).max()
    moved = np.abs(constraints @ shift).max() if constraints.size else 0.0
    if force > GROUNDED * np.abs(stiffness).max() or moved > GROUNDED:
        raise SteadyStateUnavailable(
            f"{_extensions(model)} hold the drill string to ground (moving the whole drill changes a force of "
            f"theirs by {force:.3g} N per metre), so the drill's shape relative to the advancing bottom cannot repeat: "
            "there is no periodic orbit relative to the bottom; use solver.steady_state: time")
    return shift[indices]
