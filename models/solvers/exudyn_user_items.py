"""The items of a built Exudyn model (models.solvers.exudyn_model): those it hands a user, and what a user
adds, as the model's services see it.

* **The drill's items** (:class:`ExudynBody`, :class:`ExudynConnector`): how a body and a link's law are
  added (:func:`add_body`, :func:`link_force_function`), and the solver types by their scene names.

* **The step** (:func:`assembled_eigenvalues_per_s`): the eigenvalues of the assembled system linearised
  by Exudyn (``exudyn.solver.ComputeLinearizedSystem``: M, K, D of every item, the user's included),
  with the bit on the rock and every nonlinear link closed, as the chain's own rule has them
  (models.evaluation.stability): the rock and the nonlinear links are switched off for the
  linearisation (their kinks have no derivative at rest) and stamped in at their stiffest slope.
  Constraints of one's own are projected out (the null space of their Jacobian).
* **The energy** (:class:`UserAccount`): the items added after the build, by Exudyn type. Masses
  (``Mass1D``, ``MassPoint``, ``MassPoint2D``, ``RotationalMass1D``) hold kinetic energy; spring-dampers
  (``ConnectorCoordinateSpringDamper``, ``ConnectorSpringDamper``, ``ConnectorCartesianSpringDamper``) store
  k (stretch - offset)^2 / 2 and dissipate c rate^2; constant loads (``LoadCoordinate``,
  ``LoadForceVector``) put in F (displacement); grounds and coordinate constraints hold none. Each gets
  the sensors it needs before the run (every step when the energy is asked for). An item of another type,
  or one with a user function, is *unaccounted* unless an energy term an extension declares covers it
  (``model.add_energy_term``); then the balance is not a number and the result's info names the item.
* **The sensors** (:func:`user_series`): every sensor of the user's with stored data, by its name
  (vector outputs ``name[0]``, ``name[1]``, ...), for the result's time series.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from scipy.linalg import null_space

from ...rocklaw.base import cumulative_trapezoid
from ...rocklaw.exudyn_module import exu  # first: it chooses Exudyn's compiled module

# isort: split
from exudyn.itemInterface import (
    MarkerBodyPosition,
    MarkerNodeCoordinate,
    Node1D,
    SensorMarker,
    SensorNode,
    SensorObject,
)
from exudyn.solver import ComputeLinearizedSystem

from ..definition.validation import InputError
from ..drill.chain import Link
from ..evaluation.results import UserEnergy
from ..evaluation.run_record import ExudynModelRecord
from ..evaluation.solver_settings import StepScales
from ..evaluation.stability import scales_of, second_order_eigenvalues_per_s


@dataclass(frozen=True)
class ExudynBody:
    """One axial body (a rod segment ``rod[0]`` too), or the torsion line, as Exudyn items."""

    name: str
    node: Any  # Node1D: the body's axial displacement (the torsion line: its angle)
    object: Any  # ObjectMass1D (torsion: ObjectRotationalMass1D)
    marker_coordinate: Any  # MarkerNodeCoordinate: for coordinate connectors and loads
    marker_position: Any  # MarkerBodyPosition at the body's centre: a 3-D point for Exudyn's spatial connectors


@dataclass(frozen=True)
class ExudynConnector:
    """One link of the chain (a scene connector, a rod's inner link ``rod[0-1]``) as its Exudyn object."""

    name: str
    object: Any  # ObjectConnectorCoordinateSpringDamper
    link: Link


def add_body(mbs: Any, name: str, make_object: Callable[[Any], Any], initial: float = 0.0,
              velocity: float = 0.0) -> ExudynBody:
    node = mbs.AddNode(Node1D(referenceCoordinates=[0.0], initialCoordinates=[initial], initialVelocities=[velocity]))
    body = make_object(node)
    return ExudynBody(name, node, body, mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node, coordinate=0)),
                      mbs.AddMarker(MarkerBodyPosition(bodyNumber=body, localPosition=[0.0, 0.0, 0.0])))


def link_force_function(link: Link, backend: Any) -> Callable[..., Any]:
    """A connector's spring-force user function carrying the link's own law (:meth:`Link.force_n`)."""
    def link_force(mbs, t, itemNumber, displacement, velocity, stiffness, damping, offset):
        return link.force_n(displacement, velocity, backend)
    return link_force


OUTPUT = exu.OutputVariableType
KINDS = ("stored", "dissipated", "work_in")
MASSES = {"Mass1D": ("mass", OUTPUT.Coordinates_t), "RotationalMass1D": ("inertia", OUTPUT.Coordinates_t),
          "MassPoint": ("mass", OUTPUT.Velocity), "MassPoint2D": ("mass", OUTPUT.Velocity)}
LOADS = ("Coordinate", "ForceVector")  # Exudyn's loadType of LoadCoordinate, LoadForceVector
SPRINGS = ("ConnectorCoordinateSpringDamper", "ConnectorSpringDamper", "ConnectorCartesianSpringDamper")
NO_ENERGY = ("Ground", "ConnectorCoordinate")


def item_counts(mbs: Any) -> dict[str, int]:
    data = mbs.systemData
    return {"nodes": data.NumberOfNodes(), "objects": data.NumberOfObjects(), "markers": data.NumberOfMarkers(),
            "loads": data.NumberOfLoads(), "sensors": data.NumberOfSensors()}


def label(item: dict[str, Any], kind: str, index: int) -> str:
    """How a message names an item: its type, name and index (``Mass1D 'clamp' (object 9)``)."""
    type_name = item.get("objectType") or item.get("loadType") or item.get("sensorType")
    return f"{type_name} {item['name']!r} ({kind} {index})"


def linearised_system(mbs: Any, settings: Any, switched: Sequence[Any], stamps: Sequence[tuple[Any, Any, float, float]]
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(M, K, D, the constraints' Jacobian: empty without constraints) of the assembled system linearised by
    Exudyn (module doc): ``switched`` the objects left out of the linearisation, ``stamps`` (node a or None
    for ground, node b, stiffness, damping) put in instead."""
    active = {item: mbs.GetObjectParameter(item, "activeConnector") for item in switched}
    try:
        for item in switched:
            mbs.SetObjectParameter(item, "activeConnector", False)
        linearised = ComputeLinearizedSystem(mbs, settings, returnConstraintJacobian=True)
        mass, stiffness, damping = linearised[:3]
        jacobian = linearised[3] if len(linearised) > 3 else []  # only with constraints
    finally:
        for item, state in active.items():
            mbs.SetObjectParameter(item, "activeConnector", state)
    stiffness, damping = np.array(stiffness, dtype=float), np.array(damping, dtype=float)
    for node_a, node_b, k, c in stamps:
        direction = np.zeros(len(mass))
        direction[mbs.GetNodeODE2Index(node_b)] += 1.0
        if node_a is not None:
            direction[mbs.GetNodeODE2Index(node_a)] -= 1.0
        stiffness += k * np.outer(direction, direction)
        damping += c * np.outer(direction, direction)
    return np.asarray(mass, dtype=float), stiffness, damping, np.asarray(jacobian, dtype=float)


def assembled_eigenvalues_per_s(mbs: Any, settings: Any, switched: Sequence[Any],
                                stamps: Sequence[tuple[Any, Any, float, float]]) -> np.ndarray:
    """The eigenvalues of the assembled system (module doc, :func:`linearised_system`); constraints of one's
    own projected out (the null space of their Jacobian)."""
    mass, stiffness, damping, jacobian = linearised_system(mbs, settings, switched, stamps)
    if jacobian.size and np.any(jacobian):  # constraints of one's own: their null space
        basis = null_space(jacobian.T)
        mass, stiffness, damping = (basis.T @ matrix @ basis for matrix in (mass, stiffness, damping))
    return second_order_eigenvalues_per_s(mass, stiffness, damping)


def closed_chain(model: Any, rock: bool = True) -> tuple[list[Any], list[tuple[Any, Any, float, float]]]:
    """What a built model's linearisation switches off and stamps in instead (:func:`linearised_system`):
    the rock, at its stiffest slope on the bit (``rock`` False: left out), and every nonlinear link of the
    chain, closed."""
    law = model.rock.rock
    nonlinear = [c for c in model.connectors.values() if not c.link.linear]
    nodes = [body.node for body in model.bodies.values()]
    stamps = [(None, nodes[model.chain.bit_body], max(law.loading_stiffness_n_per_m, law.unloading_stiffness_n_per_m),
               law.damping_n_s_per_m)] if rock else []
    stamps += [(None if c.link.body_a is None else nodes[c.link.body_a], nodes[c.link.body_b],
                c.link.stiffness_n_per_m, c.link.damping_n_s_per_m) for c in nonlinear]
    return [model.rock.object, *(c.object for c in nonlinear)], stamps


def assembled_scales(model: Any) -> StepScales:
    """The step scales (models.evaluation.solver_settings.StepScales) of a built model's system as assembled
    now (:func:`assembled_eigenvalues_per_s`): the rock at its stiffest slope on the bit, every nonlinear
    link of the chain closed (:func:`closed_chain`)."""
    law = model.rock.rock
    eigenvalues = assembled_eigenvalues_per_s(model.mbs, model._settings, *closed_chain(model))
    scales = scales_of(eigenvalues, model.simulation.impact.period_s,
                       law.damping_n_s_per_m / model.chain.bodies[model.chain.bit_body].mass_kg)
    if not np.isfinite(scales.spectral_radius_per_s):
        raise ValueError(f"scene '{model.simulation.name}': the assembled system's fastest rate is "
                         f"{scales.spectral_radius_per_s}: an item of one's own has a mass, stiffness or damping that "
                         "is not a finite number, or a stiffness or damping beyond floating point over its mass")
    return scales


def node_labels(model: Any, node: int, count: int) -> list[str]:
    """The name of the first object of one's own on ``node`` (else the node's), with [i] for a node of several
    coordinates."""
    mbs = model.mbs
    name = mbs.GetNode(node)["name"]
    for index in range(model.built_items["objects"], mbs.systemData.NumberOfObjects()):
        item = mbs.GetObject(index)
        numbers = item.get("nodeNumber", item.get("nodeNumbers", []))
        if node in [int(number) for number in (numbers if isinstance(numbers, list | tuple) else [numbers])]:
            name = item["name"]
            break
    return [name] if count == 1 else [f"{name}[{i}]" for i in range(count)]


def coordinate_names(model: Any) -> list[str]:
    """The name of every ODE2 coordinate of an assembled model (ExudynModel.coordinate_names), in Exudyn's order:
    the index of ``mbs.systemData.GetODE2Coordinates()`` and the column after the time of Exudyn's solution file
    (``model.write_solution``). The drill's bodies come first, in the order the scene lists them (a rod's segments
    ``rod1[0]``, ``rod1[1]``, ..., then a piston's), then ``torsion`` where it is built, then the coordinates of
    items of one's own in the order they were added, each by :func:`node_labels`."""
    mbs = model.mbs
    names = [""] * mbs.systemData.ODE2Size()
    drill = {int(body.node): body.name for body in model.bodies.values()}
    if model.torsion is not None:
        drill[int(model.torsion.node)] = "torsion"
    for node in range(mbs.systemData.NumberOfNodes()):
        indices = [int(i) for i in mbs.systemData.GetNodeLTGODE2(node)]
        if not indices or "Ground" in mbs.GetNode(node)["nodeType"]:
            continue
        labels = [drill[node]] if node in drill else node_labels(model, node, len(indices))
        for index, label in zip(indices, labels, strict=True):
            names[index] = label
    return names


def extension_nodes(model: Any) -> list[tuple[int, list[int]]]:
    """The nodes added to a built model after its build (by its extensions, or by a user) that have ODE2
    coordinates: (node, its coordinates' global ODE2 indices) in the order of the nodes."""
    mbs, found = model.mbs, []
    for node in range(model.built_items["nodes"], mbs.systemData.NumberOfNodes()):
        if "Ground" in mbs.GetNode(node)["nodeType"]:
            continue
        indices = [int(i) for i in mbs.systemData.GetNodeLTGODE2(node)]
        if indices:
            found.append((node, indices))
    return found


def follow_extension_coordinates(model: Any) -> None:
    """Prepare a built model (``model.prepare``) with the ODE2 coordinates its extensions add followed, where
    its simulation asks (Simulation.extension_coordinates, a steady-state run): a sensor of the values and
    one of the rates of each such node (the model's own: not among the user's series), and their start
    (Exudyn's initial configuration, set after the last assembly)."""
    followed = model.simulation.extension_coordinates
    if followed is None:
        model.prepare()
        return
    nodes = extension_nodes(model)
    indices = [i for _, node_indices in nodes for i in node_indices]
    if len(indices) != len(followed.drift):
        raise ValueError(f"scene '{model.simulation.name}': the extensions added {len(indices)} ODE2 coordinates, "
                         f"not the {len(followed.drift)} the steady-state section holds")
    for node, _ in nodes:
        model.extension_sensors += [model._account.own_sensor(model.mbs, SensorNode(
            nodeNumber=node, storeInternal=True, writeToFile=False, outputVariableType=output))
            for output in (OUTPUT.Coordinates, OUTPUT.Coordinates_t)]
    model.prepare()
    if followed.start is not None:
        data, initial, count = model.mbs.systemData, exu.ConfigurationType.Initial, len(indices)
        for values, read, write in ((followed.start[:count], data.GetODE2Coordinates, data.SetODE2Coordinates),
                                    (followed.start[count:], data.GetODE2Coordinates_t, data.SetODE2Coordinates_t)):
            state = np.array(read(configuration=initial))
            state[indices] = values
            write(state, configuration=initial)


def initial_coordinates(model: Any, indices: list[int]) -> np.ndarray:
    """The ODE2 coordinates ``indices`` of a prepared model's start (Exudyn's initial configuration): their
    positions, then their velocities."""
    data, initial = model.mbs.systemData, exu.ConfigurationType.Initial
    return np.concatenate([np.asarray(data.GetODE2Coordinates(configuration=initial))[indices],
                           np.asarray(data.GetODE2Coordinates_t(configuration=initial))[indices]])


def extension_history(model: Any, time_s: np.ndarray) -> np.ndarray | None:
    """The followed extension coordinates (:func:`follow_extension_coordinates`) at ``time_s``: samples x
    (positions, then velocities); None where none are followed."""
    if not model.extension_sensors:
        return None
    values = [_read(model, sensor, time_s) for sensor in model.extension_sensors]
    return np.hstack(values[0::2] + values[1::2])


def time_runs_only(simulation: Any) -> None:
    """InputError when a built model's scene asks for ``solver.steady_state: periodic``: a built model (and
    what a user adds to it) runs in time; the steady state of a scene is rpdrill.simulate's, with the items
    given as an extension, whose coordinates it follows (models.steady.extension_section)."""
    if simulation.scene.solver.steady_state == "periodic":
        raise InputError(f"scene '{simulation.name}': solver.steady_state: 'periodic': a built model runs in time "
                         "(model.run(), exu.SolveDynamic), so it would not be the periodic orbit the scene asks for; "
                         "give the items you add as an extension of the scene and run rpdrill.simulate(scene) for "
                         "its orbit (docs/extending.md), or set solver.steady_state: time for a time run")


USER_ITEMS_NOTE = ("items added to model.mbs are seen only by the Exudyn formulation (the exact and ODE "
                   "formulations know the scene's drill only); the step, the energy account and the time series "
                   "take them in")


def user_outcome(model: Any, time_s: np.ndarray) -> tuple[ExudynModelRecord | None, UserEnergy | None,
                                                       dict[str, np.ndarray], np.ndarray | None]:
    """What a run of a model with items of one's own adds to its result: its record (the items, the
    extensions, the step they were given: None for a model of the scene alone), the items' energy (what is
    accounted for and what is not), the user's sensors by name, and the extension coordinates a steady-state
    run follows (:func:`extension_history`)."""
    mbs, account, simulation = model.mbs, model._account, model.simulation
    added = model.user_items()
    sensors = [i for i in range(account.first_sensor, mbs.systemData.NumberOfSensors()) if i not in account.own_sensors]
    series, unstored = user_series(mbs, sensors, time_s)
    energy = account.energies(model, time_s) if added.keys() - {"sensors"} or account.terms else None
    record = None
    if added or model.scene_formulation != "exudyn" or model._foreign is not None:
        record = ExudynModelRecord(
            scene_formulation=model.scene_formulation, user_items=added,
            extensions=tuple(simulation.scene.extensions or {}), step_s=simulation.settings.step_s,
            spectral_radius_per_s=simulation.spectral_radius_per_s, note=USER_ITEMS_NOTE,
            sensors_not_stored=tuple(unstored), foreign_pre_step=model._foreign is not None)
    return record, energy, series, extension_history(model, time_s)


@dataclass(frozen=True)
class EnergyTerm:
    """An energy term an extension declares (``model.add_energy_term``): ``kind`` stored (held now),
    dissipated or work_in (cumulative from the start); ``joules(model, time_s)`` its value at every
    stored step after the run; ``items`` the Exudyn items it accounts for."""

    name: str
    kind: Literal["stored", "dissipated", "work_in"]
    joules: Callable[[Any, np.ndarray], np.ndarray]
    items: tuple[Any, ...] = ()


@dataclass
class UserAccount:
    """The energy of the items added after the build (module doc): sensors added by :meth:`watch`, the
    energies read by :meth:`energies` after the run."""

    first_object: int
    first_load: int
    first_sensor: int
    terms: list[EnergyTerm] = field(default_factory=list)
    _parts: list[tuple[str, str, Callable[[Any, np.ndarray], np.ndarray]]] = field(default_factory=list)
    _watched: set[tuple[str, int]] = field(default_factory=set)
    own_sensors: set[int] = field(default_factory=set)  # the sensors this account added
    unaccounted: list[str] = field(default_factory=list)

    def declare(self, term: EnergyTerm) -> None:
        """Take an energy term an extension declares (``model.add_energy_term``)."""
        if term.kind not in KINDS:
            raise ValueError(f"add_energy_term {term.name!r}: kind {term.kind!r} is not one of {', '.join(KINDS)}")
        self.terms.append(term)

    def added(self, mbs: Any, built: dict[str, int]) -> dict[str, int]:
        """The items of each kind added to ``mbs`` since it was built with ``built`` (the account's sensors not
        counted), the kinds with none left out."""
        counts = item_counts(mbs)
        counts["sensors"] -= len(self.own_sensors)
        return {kind: counts[kind] - built[kind] for kind in counts if counts[kind] != built[kind]}

    def own_sensor(self, mbs: Any, sensor: Any) -> Any:
        """Add a sensor of the model's own (not among the user's items or series)."""
        index = mbs.AddSensor(sensor)
        self.own_sensors.add(int(index))
        return index

    def watch(self, mbs: Any, energy: bool) -> None:
        """Take in the items added since the last call: their sensors (with ``energy``), or, without a way
        to account for them, their names."""
        covered = {_typed(item) for term in self.terms for item in term.items}
        data = mbs.systemData
        for index in range(self.first_object, data.NumberOfObjects()):
            self._take(mbs, "object", index, mbs.GetObject(index), covered, energy)
        for index in range(self.first_load, data.NumberOfLoads()):
            self._take(mbs, "load", index, mbs.GetLoad(index), covered, energy)

    def _take(self, mbs: Any, kind: str, index: int, item: dict[str, Any], covered: set[str], energy: bool) -> None:
        if (kind, index) in self._watched:
            return
        self._watched.add((kind, index))
        type_name = item.get("objectType") or item.get("loadType")
        name = label(item, kind, index)
        user_function = any(key.endswith("UserFunction") and value not in (0, None) for key, value in item.items())
        if (kind, index) in covered:
            return
        if user_function or type_name not in (*MASSES, *SPRINGS, *NO_ENERGY, *LOADS) \
                or (type_name == "ForceVector" and item.get("bodyFixed")):
            self.unaccounted.append(name)
            return
        if not energy or type_name in NO_ENERGY:
            return
        if type_name in MASSES:
            self._mass(mbs, name, item, *MASSES[type_name])
        elif type_name in SPRINGS:
            self._spring(mbs, name, index, item)
        else:
            self._load(mbs, name, item)

    def _mass(self, mbs: Any, name: str, item: dict[str, Any], key: str, output: Any) -> None:
        sensor = self.own_sensor(mbs, SensorNode(nodeNumber=item["nodeNumber"], storeInternal=True, writeToFile=False,
                                              outputVariableType=output))
        inertia = float(item[key])
        self._parts.append((name, "stored", lambda m, t: 0.5 * inertia * np.sum(_read(m, sensor, t) ** 2, axis=1)))

    def _spring(self, mbs: Any, name: str, index: int, item: dict[str, Any]) -> None:
        def sensor(output: Any) -> Any:
            return self.own_sensor(mbs, SensorObject(objectNumber=index, storeInternal=True, writeToFile=False,
                                                  outputVariableType=output))
        if not item.get("activeConnector", True):
            return
        stiffness = np.atleast_1d(np.asarray(item["stiffness"], dtype=float))
        damping = np.atleast_1d(np.asarray(item["damping"], dtype=float))
        if item["objectType"] == "ConnectorSpringDamper":
            distance, displacement, velocity = sensor(OUTPUT.Distance), sensor(OUTPUT.Displacement), \
                sensor(OUTPUT.Velocity)
            length0, preload = float(item["referenceLength"]), float(item["force"])
            offset = float(item["velocityOffset"])

            def rate(m: Any, t: np.ndarray) -> np.ndarray:
                return np.sum(_read(m, displacement, t) * _read(m, velocity, t), axis=1) / _read(m, distance, t)[:, 0]

            def stretch(m: Any, t: np.ndarray) -> np.ndarray:
                return _read(m, distance, t)[:, 0] - length0
            self._parts += [
                (name, "stored", lambda m, t: 0.5 * stiffness[0] * stretch(m, t) ** 2 + preload * stretch(m, t)),
                (name, "dissipated", lambda m, t: cumulative_trapezoid(damping[0] * (rate(m, t) - offset) * rate(m, t), t))]
            return
        displacement, velocity = sensor(OUTPUT.Displacement), sensor(OUTPUT.Velocity)
        offset = np.atleast_1d(np.asarray(item["offset"], dtype=float))
        self._parts += [
            (name, "stored", lambda m, t: 0.5 * np.sum(stiffness * (_read(m, displacement, t) - offset) ** 2, axis=1)),
            (name, "dissipated", lambda m, t: cumulative_trapezoid(np.sum(damping * _read(m, velocity, t) ** 2, axis=1), t))]

    def _load(self, mbs: Any, name: str, item: dict[str, Any]) -> None:
        marker = mbs.GetMarker(item["markerNumber"])
        if item["loadType"] == "Coordinate":
            node = mbs.GetNode(marker["nodeNumber"])
            if node["nodeType"] == "PointGround":
                return
            sensor = self.own_sensor(mbs, SensorNode(nodeNumber=marker["nodeNumber"], storeInternal=True,
                                                  writeToFile=False, outputVariableType=OUTPUT.Coordinates))
            load, column = np.array([float(item["load"])]), [marker["coordinate"]]
        else:
            sensor = self.own_sensor(mbs, SensorMarker(markerNumber=item["markerNumber"], storeInternal=True,
                                                    writeToFile=False, outputVariableType=OUTPUT.Position))
            load, column = np.asarray(item["loadVector"], dtype=float), [0, 1, 2]

        def work(m: Any, t: np.ndarray) -> np.ndarray:
            moved = _read(m, sensor, t)[:, column]
            return (moved - moved[0]) @ load
        self._parts.append((name, "work_in", work))

    def energies(self, model: Any, time_s: np.ndarray) -> UserEnergy:
        """The user's energies at every stored step (after the run)."""
        totals = {kind: np.zeros(len(time_s)) for kind in KINDS}
        with np.errstate(all="ignore"):  # a run that diverged: its energies are not numbers, and it is refused
            for _, kind, joules in self._parts:
                totals[kind] = totals[kind] + joules(model, time_s)
            for term in self.terms:
                totals[term.kind] = totals[term.kind] + np.asarray(term.joules(model, time_s), dtype=float)
        return UserEnergy(totals["stored"], totals["dissipated"], totals["work_in"], tuple(self.unaccounted),
                          tuple(sorted({name for name, _, _ in self._parts})), tuple(term.name for term in self.terms))


def _typed(item: Any) -> tuple[str, int]:
    """(object or load, number) of an Exudyn item index (a plain number: an object)."""
    typed = item.GetTypeString() if hasattr(item, "GetTypeString") else "ObjectIndex"
    return ("load" if typed == "LoadIndex" else "object"), int(item)


def _read(model: Any, sensor: Any, time_s: np.ndarray) -> np.ndarray:
    """A sensor's stored values (samples x components) at ``time_s``."""
    data = np.asarray(model.mbs.GetSensorStoredData(sensor), dtype=float)
    if len(data) == len(time_s) and np.allclose(data[:, 0], time_s):
        return data[:, 1:]
    return np.column_stack([np.interp(time_s, data[:, 0], column) for column in data[:, 1:].T])


def user_series(mbs: Any, sensors: Sequence[int], time_s: np.ndarray) -> tuple[dict[str, np.ndarray], list[str]]:
    """The stored data of the user's ``sensors`` at ``time_s`` by name (vectors as ``name[i]``), and the
    sensors that store nothing (written to a file only)."""
    series: dict[str, np.ndarray] = {}
    unstored = []
    for index in sensors:
        item = mbs.GetSensor(index)
        if not item.get("storeInternal"):
            unstored.append(label(item, "sensor", index))
            continue
        data = np.asarray(mbs.GetSensorStoredData(index), dtype=float)
        if data.ndim != 2 or len(data) == 0:
            unstored.append(label(item, "sensor", index))
            continue
        values = [np.interp(time_s, data[:, 0], column) for column in data[:, 1:].T]
        if len(values) == 1:
            series[item["name"]] = values[0]
        else:
            series.update({f"{item['name']}[{i}]": column for i, column in enumerate(values)})
    return series, unstored
