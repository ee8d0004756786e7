"""The drill as an Exudyn multibody system (the project's main formulation).

Every axial body is a ``Node1D`` + ``ObjectMass1D``; every link of the chain an
``ObjectConnectorCoordinateSpringDamper``; the feed a constant ``LoadCoordinate`` per body; the
piston a ``LoadCoordinate`` with a symbolic load function (models.drill.pulse); the rock the
:class:`rocklaw.exudyn_element.ExudynRockContact` on the bit. Torsion, when its effect is on, is
a ``Node1D`` + ``ObjectRotationalMass1D`` with its own spring-damper to ground and a constant
torque. Only what the scene's effects and outputs need is built: no torsion node, no rock
damping term, no per-step hook for an elastic rock, no force sensors and no per-step storage
unless an output asks for them. Every body carries its graphics to scale (models.solvers.exudyn_graphics).

:func:`build_exudyn` returns the assembled system before it runs (:class:`ExudynModel`: ``SC``,
``mbs``, ``bodies[name]`` with their node, object and markers, ``connectors[name]``) for a user to
add Exudyn items of their own; ``model.run()`` runs it. A normal run is the same build and run
(:func:`simulate`).
"""

from __future__ import annotations

import math
import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ...rocklaw.exudyn_module import exu  # first: it chooses Exudyn's compiled module

# isort: split
from exudyn.itemInterface import (
    LoadCoordinate,
    MarkerBodyPosition,
    MarkerNodeCoordinate,
    Node1D,
    NodePointGround,
    ObjectConnectorCoordinateSpringDamper,
    ObjectGround,
    ObjectMass1D,
    ObjectRotationalMass1D,
    SensorLoad,
    SensorNode,
    SensorObject,
    VObjectConnectorCoordinateSpringDamper,
    VObjectGround,
    VObjectMass1D,
    VObjectRotationalMass1D,
)

from ...rocklaw.backends import SCALAR, SymbolicBackend
from ...rocklaw.exudyn_element import ExudynRockContact, attach_user_function
from ..definition.drill_string import STEEL_DENSITY_KG_PER_M3
from ..definition.formulations import AUTOMATIC_STEP_SOLVERS
from ..definition.scene import Scene
from ..drill.chain import AxialChain, Link
from ..drill.indexing import BlowStarts
from ..drill.pulse import impact_force
from ..drill.shapes import DEFAULT_DIAMETER_M, Cylinder, Layout, layout
from ..evaluation.results import SimulationResult
from ..evaluation.run_result import Result
from ..evaluation.stability import SimulationFailed, StepLimitWarning, check_result, step_warning
from ..waves.exudyn_waves import WaveExudyn
from .exudyn_graphics import DrillGraphics, body_graphics, torsion_graphics
from .exudyn_messages import exudyn_messages_as_warnings, no_cyclic_gc
from .exudyn_piston import ExudynPiston
from .simulation import SceneError, Simulation, as_simulation, prepare

SOLVER_TYPES = {
    "rk67": exu.DynamicSolverType.RK67,
    "rk44": exu.DynamicSolverType.RK44,
    "rk33": exu.DynamicSolverType.RK33,
    "explicit_midpoint": exu.DynamicSolverType.ExplicitMidpoint,
    "explicit_euler": exu.DynamicSolverType.ExplicitEuler,
    "generalized_alpha": exu.DynamicSolverType.GeneralizedAlpha,
    "trapezoidal_index2": exu.DynamicSolverType.TrapezoidalIndex2,
    "dopri5": exu.DynamicSolverType.DOPRI5,
    "ode23": exu.DynamicSolverType.ODE23,
}
COORDINATE = exu.OutputVariableType.Coordinates
RATE = exu.OutputVariableType.Coordinates_t
AXIS_X_FROM_Z = [[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]]  # a rotational node's local z onto the drilling axis


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


@dataclass
class ExudynModel:
    """The drill as an assembled Exudyn system, not yet run (:func:`build_exudyn`).

    ``mbs`` is open to any Exudyn item of a user's own: join it to ``bodies[name].marker_position``
    (spatial connectors) or ``.marker_coordinate`` (coordinate connectors, loads); ``run()`` assembles
    what was added and runs it with the scene's solver settings. ``add_pre_step(function)`` adds a
    per-step hook (``mbs.SetPreStepUserFunction`` would replace the model's own).
    """

    simulation: Simulation
    chain: AxialChain
    SC: Any
    mbs: Any
    bodies: dict[str, ExudynBody]
    connectors: dict[str, ExudynConnector]
    rock: ExudynRockContact
    torsion: ExudynBody | None
    graphics: DrillGraphics
    sensors: dict[str, Any]
    settings: Any
    symbolic_functions: list[Any] = field(default_factory=list)  # kept alive with the system
    blows: BlowStarts | None = None  # the blow starts of this run (models.drill.indexing)
    piston: ExudynPiston | None = None  # the piston's strikes and catches (models.drill.piston)
    scene_formulation: str = "exudyn"  # the formulation the scene named (the model is always Exudyn's)
    symbolic: bool = True
    pre_steps: list[Callable[[Any, float], bool]] = field(default_factory=list)
    waves: WaveExudyn | None = None  # wave rods: the element updated before every step (models.waves.exudyn_waves)
    _built_items: dict[str, int] = field(default_factory=dict)
    _ran: bool = False

    @property
    def system_container(self) -> Any:
        return self.SC

    @property
    def coordinate_count(self) -> int:
        return len(self.mbs.systemData.GetODE2Coordinates())

    def add_pre_step(self, function: Callable[[Any, float], bool]) -> None:
        """Call ``function(mbs, t)`` before every step, after the model's own hooks (False stops the run)."""
        self.pre_steps.append(function)

    def write_solution(self, path: str | Path, period_s: float | None = None) -> None:
        """Have the run write Exudyn's coordinates solution file to ``path`` every ``period_s`` (default: the
        output interval), for ``exudyn.interactive.SolutionViewer`` (``exudyn.utilities.LoadSolutionFile``)."""
        solution = self.settings.solution.file
        solution.write = True
        solution.name = str(path)
        solution.writePeriod = period_s or self.simulation.settings.output_interval_s
        solution.export.velocities = solution.export.accelerations = False

    def user_items(self) -> dict[str, int]:
        """The Exudyn items added to ``mbs`` since the model was built, by kind (none: empty)."""
        counts = _item_counts(self.mbs)
        return {kind: counts[kind] - self._built_items[kind] for kind in counts if counts[kind] != self._built_items[kind]}

    def run(self, progress: Callable[[float], None] | None = None) -> Result:
        """Run the system (with any items added) by the scene's solver settings; ``progress(t)`` about
        100 times. The result is ``rpdrill.Result``, as ``rpdrill.simulate`` returns; a model runs once."""
        return Result(self.simulation.scene, self.solve(progress), {"source": "build_exudyn"})

    def solve(self, progress: Callable[[float], None] | None = None) -> SimulationResult:
        """Run the system and return the formulation's raw result (:meth:`run` wraps it)."""
        if self._ran:
            raise RuntimeError("an ExudynModel runs once (its rock state has moved on): build_exudyn(scene) again")
        self._ran = True
        added = self.user_items()
        if added:
            self.mbs.Assemble()
        return _run(self, progress, added)


def _item_counts(mbs: Any) -> dict[str, int]:
    data = mbs.systemData
    return {"nodes": data.NumberOfNodes(), "objects": data.NumberOfObjects(), "markers": data.NumberOfMarkers(),
            "loads": data.NumberOfLoads(), "sensors": data.NumberOfSensors()}


def _add_body(mbs: Any, name: str, make_object: Callable[[Any], Any], initial: float = 0.0) -> ExudynBody:
    node = mbs.AddNode(Node1D(referenceCoordinates=[0.0], initialCoordinates=[initial], initialVelocities=[0.0]))
    body = make_object(node)
    return ExudynBody(name, node, body, mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node, coordinate=0)),
                      mbs.AddMarker(MarkerBodyPosition(bodyNumber=body, localPosition=[0.0, 0.0, 0.0])))


def _store(mbs: Any, sensor: Any) -> Any:
    return mbs.AddSensor(sensor)


def _simulation_settings(simulation: Simulation) -> Any:
    solver = simulation.settings
    settings = exu.SimulationSettings()
    integration = settings.timeIntegration
    integration.endTime = solver.end_time_s
    integration.numberOfSteps = round(solver.end_time_s / solver.step_s)
    integration.verboseMode = 0
    integration.generalizedAlpha.spectralRadius = solver.spectral_radius
    integration.newton.useModifiedNewton = True
    if solver.type in AUTOMATIC_STEP_SOLVERS:
        integration.automaticStepSize = True
        integration.relativeTolerance = solver.relative_tolerance
        integration.absoluteTolerance = solver.absolute_tolerance
        integration.initialStepSize = solver.step_s / 10
    else:
        integration.automaticStepSize = False
        integration.adaptiveStep = False
    # the explicit solvers' extra right-hand side per step computes accelerations for output only (none
    # is stored; the states are bitwise the same without it, and a rk44 step costs ~12 % less)
    integration.explicit.computeEndOfStepAccelerations = False
    settings.show.statistics = False
    settings.solution.file.write = False
    # energies are integrated over every step; otherwise store only at the output interval
    settings.solution.sensors.writePeriod = 0.0 if "energy" in simulation.needed_data else solver.output_interval_s
    return settings


def _link_force_function(link: Link, backend: Any) -> Callable[..., Any]:
    """A connector's spring-force user function carrying the link's own law (:meth:`Link.force_n`)."""
    def link_force(mbs, t, itemNumber, displacement, velocity, stiffness, damping, offset):
        return link.force_n(displacement, velocity, backend)
    return link_force


def _exudyn_simulation(run: Scene | Simulation) -> tuple[Simulation, str]:
    """The prepared simulation to build, and the formulation the scene named: a scene of another
    formulation is run by Exudyn with its common solver keys (end time, preset, output interval)."""
    simulation = as_simulation(run)
    named = simulation.settings.formulation
    if named != "exudyn":
        simulation = prepare(simulation.scene.with_solver("exudyn"))
    return simulation, named


def build_exudyn(run: Scene | Simulation, symbolic: bool = True) -> ExudynModel:
    """The drill of a scene (or prepared simulation) as an assembled Exudyn system, not yet run
    (:class:`ExudynModel`); ``model.run()`` runs it. A scene of another formulation is built for Exudyn.

    ``symbolic=False`` uses Python callbacks for the impact and rock forces (same law, slower:
    kept for the benchmark that measures what the symbolic functions save).
    """
    simulation, named = _exudyn_simulation(run)
    if simulation.dynamic_chain.waves:
        return _wave_model(simulation, named, symbolic)
    chain, impact, piston = simulation.dynamic_chain, simulation.impact, simulation.piston
    initial_positions = simulation.initial_positions_m if piston is None else piston.parked(simulation.initial_positions_m)
    shapes = layout(simulation.scene)
    container = exu.SystemContainer()
    mbs = container.AddSystem()
    ground = mbs.AddNode(NodePointGround())
    ground_marker = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=ground, coordinate=0))

    bodies: list[ExudynBody] = []
    rods = {name for name, body in simulation.scene.drill_string.bodies.items() if body.is_rod}
    for body, cylinder, initial in zip(chain.bodies, _cylinders(shapes, chain), initial_positions, strict=True):
        shown = VObjectMass1D(graphicsData=body_graphics(cylinder, cylinder.group in rods))
        bodies.append(_add_body(mbs, body.name, lambda n, m=body.mass_kg, x=cylinder.centre_m, v=shown: mbs.AddObject(
            ObjectMass1D(nodeNumber=n, mass=m, referencePosition=[x, 0.0, 0.0], visualization=v)), initial))
        if body.constant_force_n:
            mbs.AddLoad(LoadCoordinate(markerNumber=bodies[-1].marker_coordinate, load=body.constant_force_n))
    markers = [body.marker_coordinate for body in bodies]
    backend = SymbolicBackend() if symbolic else SCALAR
    user_functions = []
    connectors: dict[str, ExudynConnector] = {}
    for link in chain.links:
        base = ground_marker if link.body_a is None else markers[link.body_a]
        connector = mbs.AddObject(
            ObjectConnectorCoordinateSpringDamper(
                markerNumbers=[base, markers[link.body_b]],
                stiffness=link.stiffness_n_per_m,
                damping=link.damping_n_s_per_m,
                visualization=VObjectConnectorCoordinateSpringDamper(show=False),  # drawn by DrillGraphics
            )
        )
        connectors[link.name] = ExudynConnector(link.name, connector, link)
        if not link.linear:
            user_functions.append(attach_user_function(
                mbs, connector, "springForceUserFunction", _link_force_function(link, backend), symbolic))

    impact_load = mbs.AddLoad(LoadCoordinate(markerNumber=markers[chain.impact_body], load=0.0))

    def piston_force(mbs, t, load):
        return impact_force(impact, t, backend)

    impact_function = attach_user_function(mbs, impact_load, "loadUserFunction", piston_force, symbolic)
    tor = simulation.torsion
    torsion = None
    if tor is not None:  # before the rock: the blow start reads its angle
        bit = shapes.cylinders[chain.bit_body]
        shown = VObjectRotationalMass1D(graphicsData=torsion_graphics(bit.diameter_m))
        torsion = _add_body(mbs, "torsion", lambda n: mbs.AddObject(ObjectRotationalMass1D(
            nodeNumber=n, inertia=tor.inertia_kg_m2, referencePosition=[bit.centre_m, 0.0, 0.0],
            referenceRotation=AXIS_X_FROM_Z, visualization=shown)), simulation.initial_torsion_angle_rad)
    blows = simulation.blow_starts()
    start_blow = None
    if blows is not None:
        def start_blow(position: float, state: tuple[float, ...]) -> tuple[float, ...]:
            """The state the blow meets; the contact's return map takes the blow's law."""
            angle = mbs.GetNodeOutput(torsion.node, COORDINATE) if torsion is not None else 0.0
            law, state = blows(position, state, angle)
            rock.set_law(law)
            return state
    rock = ExudynRockContact(mbs, ground_marker, markers[chain.bit_body], bodies[chain.bit_body].node, simulation.rock,
                             symbolic=symbolic, initial_state=simulation.initial_rock_state, start_blow=start_blow,
                             blow_period_s=impact.period_s)
    mbs.SetObjectParameter(rock.object, "Vshow", False)  # drawn as the rock block of DrillGraphics

    sensors: dict[str, Any] = {}
    for i, body in enumerate(bodies):
        sensors[f"x{i}"] = _store(mbs, SensorNode(nodeNumber=body.node, storeInternal=True, outputVariableType=COORDINATE))
        sensors[f"v{i}"] = _store(mbs, SensorNode(nodeNumber=body.node, storeInternal=True, outputVariableType=RATE))
    if "forces" in simulation.needed_data:
        sensors["rock"] = _store(mbs, SensorObject(objectNumber=rock.object, storeInternal=True,
                                                   outputVariableType=exu.OutputVariableType.Force))
        sensors["impact"] = _store(mbs, SensorLoad(loadNumber=impact_load, storeInternal=True))

    if torsion is not None:
        mbs.AddObject(
            ObjectConnectorCoordinateSpringDamper(
                markerNumbers=[ground_marker, torsion.marker_coordinate],
                stiffness=tor.stiffness_n_m_per_rad,
                damping=tor.damping_n_m_s_per_rad,
                visualization=VObjectConnectorCoordinateSpringDamper(show=False),
            )
        )
        mbs.AddLoad(LoadCoordinate(markerNumber=torsion.marker_coordinate,
                                   load=tor.drive_torque_n_m - tor.resisting_torque_n_m))
        sensors["phi"] = _store(mbs, SensorNode(nodeNumber=torsion.node, storeInternal=True,
                                                outputVariableType=COORDINATE))
        sensors["omega"] = _store(mbs, SensorNode(nodeNumber=torsion.node, storeInternal=True, outputVariableType=RATE))

    drawn = DrillGraphics(simulation.chain, shapes, [body.node for body in bodies[:simulation.chain.size]], COORDINATE)
    mbs.AddObject(ObjectGround(visualization=VObjectGround(graphicsData=drawn.static(),
                                                           graphicsDataUserFunction=drawn)))
    mbs.Assemble()
    hook = None if piston is None else ExudynPiston(piston, [body.node for body in bodies], mbs, impact.period_s)
    return ExudynModel(simulation, chain, container, mbs, {body.name: body for body in bodies}, connectors, rock,
                       torsion, drawn, sensors, _simulation_settings(simulation), [impact_function, *user_functions],
                       blows, hook, named, symbolic, _built_items=_item_counts(mbs))


def _wave_model(simulation: Simulation, named: str, symbolic: bool) -> ExudynModel:
    """The Exudyn model of a scene with wave rods: the string's bodies with mass in ``mbs``, the wave rods an
    element of their own (models.waves.exudyn_waves); ``bodies`` and ``connectors`` hold the Exudyn items."""
    if simulation.settings.type in AUTOMATIC_STEP_SOLVERS:
        raise SceneError(("solver", "type"), simulation.settings.type, "wave rods step at the characteristics' "
                         "fixed step (every step advances the waves once): use a fixed-step type such as rk44")
    element = WaveExudyn(simulation, symbolic)
    chain = simulation.dynamic_chain
    bodies = {chain.bodies[i].name: ExudynBody(chain.bodies[i].name, *items) for i, items in element.bodies.items()}
    connectors = {name: ExudynConnector(name, connector, link) for name, (connector, link) in element.connectors.items()}
    return ExudynModel(simulation, chain, element.SC, element.mbs, bodies, connectors, element.rock, None, None, {},
                       _simulation_settings(simulation), element.functions, waves=element, scene_formulation=named,
                       symbolic=symbolic, _built_items=_item_counts(element.mbs))


def _cylinders(shapes: Layout, chain: AxialChain) -> list[Cylinder]:
    """The drawn cylinder of every body of the dynamic chain: the string's from its layout, a piston's
    bodies (after the string's) as steel cylinders of the default diameter behind the string."""
    cylinders = list(shapes.cylinders)
    start_m = min((c.start_m for c in cylinders), default=0.0)
    for body in chain.bodies[len(cylinders):]:
        length_m = body.mass_kg / (STEEL_DENSITY_KG_PER_M3 * math.pi * DEFAULT_DIAMETER_M**2 / 4)
        start_m -= length_m + shapes.joint_gap_m
        cylinders.append(Cylinder(body.name, "piston", start_m, length_m, DEFAULT_DIAMETER_M))
    return cylinders


class _MinimumStepGuard:
    """Stops an automatic-step run whose step fell to Exudyn's minimum (Exudyn would go on with
    errors beyond the tolerance, or crawl for hours at that step) and remembers when. The step
    is the solver's own (rejected attempts also call the pre-step function)."""

    def __init__(self, minimum_step_s: float) -> None:
        self.minimum_step_s, self.reached_at_s = minimum_step_s, None

    def __call__(self, mbs: Any, t: float) -> bool:
        if mbs.sys["dynamicSolver"].it.currentStepSize <= self.minimum_step_s * (1 + 1e-6):
            self.reached_at_s = t
            return False
        return True


def _progress_reporter(end_time_s: float, progress: Callable[[float], None]) -> Callable[[Any, float], bool]:
    every = end_time_s / 100
    next_report = [every]

    def report(mbs: Any, t: float) -> bool:
        if t >= next_report[0]:
            next_report[0] += every
            progress(t)
        return True
    return report


def _pre_step(actions: list[Callable[[Any, float], bool]]) -> Callable[[Any, float], bool] | None:
    """One Exudyn pre-step hook running ``actions`` in order; a False stops the run."""
    if len(actions) <= 1:
        return actions[0] if actions else None

    def pre_step(mbs: Any, t: float) -> bool:
        return all(action(mbs, t) for action in actions)
    return pre_step


def _sensor(mbs: Any, sensor: Any) -> np.ndarray:
    return mbs.GetSensorStoredData(sensor)


def simulate(run: Scene | Simulation, progress: Callable[[float], None] | None = None,
             symbolic: bool = True) -> SimulationResult:
    """Build and run the Exudyn model (:func:`build_exudyn`, :meth:`ExudynModel.run`)."""
    return build_exudyn(run, symbolic).solve(progress)


USER_ITEMS_NOTE = ("items added to model.mbs are seen only by the Exudyn formulation (the exact and ODE "
                   "formulations and the energy account know the scene's drill only)")


def _run(model: ExudynModel, progress: Callable[[float], None] | None, added: dict[str, int]) -> SimulationResult:
    """Solve the built system and read its sensors into a result (module doc)."""
    simulation = model.simulation
    settings = simulation.settings
    if model.waves is not None:
        actions = ([] if progress is None else [_progress_reporter(settings.end_time_s, progress)]) + model.pre_steps
        with no_cyclic_gc(), exudyn_messages_as_warnings(simulation.name):
            result = model.waves.solve(model.settings, SOLVER_TYPES[settings.type], actions)
        if added or model.scene_formulation != "exudyn":
            result.info["exudyn_model"] = {"scene_formulation": model.scene_formulation, "user_items": added,
                                           "note": USER_ITEMS_NOTE}
        return result
    warning = step_warning(simulation)
    if warning:
        warnings.warn(warning, StepLimitWarning, stacklevel=3)
    mbs = model.mbs
    actions = [model.rock.update_bottom] if model.rock.rock.crushes else []
    if model.piston is not None:
        actions.insert(0, model.piston)
    guard = None
    if settings.type in AUTOMATIC_STEP_SOLVERS:
        guard = _MinimumStepGuard(model.settings.timeIntegration.minimumStepSize)
        actions.append(guard)
    if progress is not None:
        actions.append(_progress_reporter(settings.end_time_s, progress))
    pre_step = _pre_step(actions + model.pre_steps)
    if pre_step is not None:
        mbs.SetPreStepUserFunction(pre_step)
    with no_cyclic_gc(), exudyn_messages_as_warnings(simulation.name):
        start = time.process_time()
        ok = mbs.SolveDynamic(model.settings, solverType=SOLVER_TYPES[settings.type])
        cpu = time.process_time() - start
    reached_s = mbs.systemData.GetTime()
    data = {name: _sensor(mbs, sensor) for name, sensor in model.sensors.items()}
    time_s = data["x0"][:, 0]
    n = model.chain.size
    position = np.column_stack([data[f"x{i}"][:, 1] for i in range(n)])
    velocity = np.column_stack([data[f"v{i}"][:, 1] for i in range(n)])
    history = np.array(model.rock.bottom_history)
    piston = None if model.piston is None else model.piston.history(time_s, position, velocity)
    position, velocity = position[:, :simulation.chain.size], velocity[:, :simulation.chain.size]
    rock_state = model.rock.state_at(time_s)
    info: dict[str, Any] = {"solver_success": bool(ok), "coordinates": model.coordinate_count,
                            **({"fresh_fractions": model.blows.fresh_fractions} if model.blows else {})}
    if added or model.scene_formulation != "exudyn":
        info["exudyn_model"] = {"scene_formulation": model.scene_formulation, "user_items": added,
                                "note": USER_ITEMS_NOTE}
    result = SimulationResult(
        simulation=simulation,
        formulation="exudyn",
        time_s=time_s,
        position_m=position,
        velocity_m_per_s=velocity,
        bottom_m=rock_state[:, model.rock.rock.bottom_index],
        rock_force_n=data["rock"][:, 1] if "rock" in data else None,
        impact_force_n=(data["impact"][:, 1] if piston is None else piston.contact_force_n) if "impact" in data
        else None,
        torsion_angle_rad=data["phi"][:, 1] if "phi" in data else None,
        torsion_rate_rad_per_s=data["omega"][:, 1] if "omega" in data else None,
        cpu_time_s=cpu,
        info=info,
        bottom_events=(history[:, 0], history[:, 1]),
        rock_state_m=rock_state,
        piston=piston,
    )
    if guard is not None and guard.reached_at_s is not None:
        raise SimulationFailed(
            f"scene '{simulation.name}': solver {settings.type} with relative_tolerance "
            f"{settings.relative_tolerance:g} reached the minimum step "
            f"{guard.minimum_step_s:g} s at t = {guard.reached_at_s:.6g} s; try relative_tolerance "
            f"{settings.relative_tolerance * 100:g} or a fixed-step preset (solver: {{preset: standard}})")
    check_result(result, solver_ok=bool(ok), reached_s=reached_s)
    return result
