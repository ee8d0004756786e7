"""The drill as an Exudyn multibody system (the project's main formulation).

Every axial body is a ``Node1D`` + ``ObjectMass1D``; every link of the chain an
``ObjectConnectorCoordinateSpringDamper``; the feed a constant ``LoadCoordinate`` per body; the
piston a ``LoadCoordinate`` with a symbolic load function (models.pulse); the rock the
:class:`rocklaw.exudyn_element.ExudynRockContact` on the bit. Torsion, when its effect is on, is
a ``Node1D`` + ``ObjectRotationalMass1D`` with its own spring-damper to ground and a constant
torque. Only what the scene's effects and outputs need is built: no torsion node, no rock
damping term, no per-step hook for an elastic rock, no force sensors and no per-step storage
unless an output asks for them.
"""

from __future__ import annotations

import contextlib
import gc
import time
import warnings
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..rocklaw.exudyn_module import exu  # first: it chooses Exudyn's compiled module

# isort: split
from exudyn.itemInterface import (
    LoadCoordinate,
    MarkerNodeCoordinate,
    Node1D,
    NodePointGround,
    ObjectConnectorCoordinateSpringDamper,
    ObjectMass1D,
    ObjectRotationalMass1D,
    SensorLoad,
    SensorNode,
    SensorObject,
)

from ..rocklaw.backends import SCALAR, SymbolicBackend
from ..rocklaw.exudyn_element import ExudynRockContact, attach_user_function
from .chain import AxialChain, Link
from .exudyn_piston import ExudynPiston
from .formulations import AUTOMATIC_STEP_SOLVERS
from .indexing import BlowStarts
from .pulse import impact_force
from .results import SimulationResult
from .scene import Scene
from .simulation import Simulation, as_simulation
from .stability import SimulationFailed, StepLimitWarning, check_result, step_warning

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


@dataclass
class ExudynDrill:
    """A built, assembled system and the handles needed to run and read it."""

    simulation: Simulation
    chain: AxialChain
    system_container: Any
    mbs: Any
    rock: ExudynRockContact
    sensors: dict[str, Any]
    settings: Any
    symbolic_functions: list[Any] = field(default_factory=list)  # kept alive with the system
    blows: BlowStarts | None = None  # the blow starts of this run (models.indexing)
    piston: ExudynPiston | None = None  # the piston's strikes and catches (models.piston)

    @property
    def coordinate_count(self) -> int:
        return len(self.mbs.systemData.GetODE2Coordinates())


def _add_coordinate_body(mbs: Any, make_object: Callable[[Any], Any], initial: float = 0.0) -> tuple[Any, Any]:
    node = mbs.AddNode(Node1D(referenceCoordinates=[0.0], initialCoordinates=[initial], initialVelocities=[0.0]))
    make_object(node)
    return node, mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node, coordinate=0))


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


def build_exudyn(simulation: Simulation, symbolic: bool = True) -> ExudynDrill:
    """Build and assemble the Exudyn system of a prepared simulation.

    ``symbolic=False`` uses Python callbacks for the impact and rock forces (same law, slower:
    kept for the benchmark that measures what the symbolic functions save).
    """
    chain, impact = simulation.dynamic_chain, simulation.impact
    piston = simulation.piston
    initial_positions = simulation.initial_positions_m if piston is None else piston.parked(simulation.initial_positions_m)
    container = exu.SystemContainer()
    mbs = container.AddSystem()
    ground = mbs.AddNode(NodePointGround())
    ground_marker = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=ground, coordinate=0))

    nodes, markers = [], []
    for body, initial in zip(chain.bodies, initial_positions, strict=True):
        node, marker = _add_coordinate_body(
            mbs, lambda n, m=body.mass_kg: mbs.AddObject(ObjectMass1D(nodeNumber=n, mass=m)), initial)
        nodes.append(node)
        markers.append(marker)
        if body.constant_force_n:
            mbs.AddLoad(LoadCoordinate(markerNumber=marker, load=body.constant_force_n))
    backend = SymbolicBackend() if symbolic else SCALAR
    user_functions = []
    for link in chain.links:
        base = ground_marker if link.body_a is None else markers[link.body_a]
        connector = mbs.AddObject(
            ObjectConnectorCoordinateSpringDamper(
                markerNumbers=[base, markers[link.body_b]],
                stiffness=link.stiffness_n_per_m,
                damping=link.damping_n_s_per_m,
            )
        )
        if not link.linear:
            user_functions.append(attach_user_function(
                mbs, connector, "springForceUserFunction", _link_force_function(link, backend), symbolic))

    impact_load = mbs.AddLoad(LoadCoordinate(markerNumber=markers[chain.impact_body], load=0.0))

    def piston_force(mbs, t, load):
        return impact_force(impact, t, backend)

    impact_function = attach_user_function(mbs, impact_load, "loadUserFunction", piston_force, symbolic)
    tor = simulation.torsion
    torsion_node = None
    if tor is not None:  # before the rock: the blow start reads its angle
        torsion_node, torsion_marker = _add_coordinate_body(
            mbs, lambda n: mbs.AddObject(ObjectRotationalMass1D(nodeNumber=n, inertia=tor.inertia_kg_m2)),
            simulation.initial_torsion_angle_rad,
        )
    blows = simulation.blow_starts()
    start_blow = None
    if blows is not None:
        def start_blow(position: float, state: tuple[float, ...]) -> tuple[float, ...]:
            """The state the blow meets; the contact's return map takes the blow's law."""
            angle = mbs.GetNodeOutput(torsion_node, COORDINATE) if torsion_node is not None else 0.0
            law, state = blows(position, state, angle)
            rock.set_law(law)
            return state
    rock = ExudynRockContact(mbs, ground_marker, markers[chain.bit_body], nodes[chain.bit_body], simulation.rock,
                             symbolic=symbolic, initial_state=simulation.initial_rock_state, start_blow=start_blow,
                             blow_period_s=impact.period_s)

    sensors: dict[str, Any] = {}
    for i, node in enumerate(nodes):
        sensors[f"x{i}"] = _store(mbs, SensorNode(nodeNumber=node, storeInternal=True, outputVariableType=COORDINATE))
        sensors[f"v{i}"] = _store(mbs, SensorNode(nodeNumber=node, storeInternal=True, outputVariableType=RATE))
    if "forces" in simulation.needed_data:
        sensors["rock"] = _store(mbs, SensorObject(objectNumber=rock.object, storeInternal=True,
                                                   outputVariableType=exu.OutputVariableType.Force))
        sensors["impact"] = _store(mbs, SensorLoad(loadNumber=impact_load, storeInternal=True))

    if tor is not None:
        mbs.AddObject(
            ObjectConnectorCoordinateSpringDamper(
                markerNumbers=[ground_marker, torsion_marker],
                stiffness=tor.stiffness_n_m_per_rad,
                damping=tor.damping_n_m_s_per_rad,
            )
        )
        mbs.AddLoad(LoadCoordinate(markerNumber=torsion_marker, load=tor.drive_torque_n_m - tor.resisting_torque_n_m))
        sensors["phi"] = _store(mbs, SensorNode(nodeNumber=torsion_node, storeInternal=True,
                                                outputVariableType=COORDINATE))
        sensors["omega"] = _store(mbs, SensorNode(nodeNumber=torsion_node, storeInternal=True, outputVariableType=RATE))

    mbs.Assemble()
    hook = None if piston is None else ExudynPiston(piston, nodes, mbs, impact.period_s)
    return ExudynDrill(simulation, chain, container, mbs, rock, sensors, _simulation_settings(simulation),
                       [impact_function, *user_functions], blows, hook)


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


@contextlib.contextmanager
def _no_cyclic_gc() -> Iterator[None]:
    """Python's cyclic garbage collector paused: the per-step hooks allocate small objects without
    cycles (freed by reference counting), and the collections they would trigger cost ~5 % of a run."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()


def _sensor(mbs: Any, sensor: Any) -> np.ndarray:
    return mbs.GetSensorStoredData(sensor)


def simulate(run: Scene | Simulation, progress: Callable[[float], None] | None = None,
             symbolic: bool = True) -> SimulationResult:
    """Build and run the Exudyn model; ``progress(t)`` is called about 100 times during the run."""
    simulation = as_simulation(run)
    settings = simulation.settings
    warning = step_warning(simulation)
    if warning:
        warnings.warn(warning, StepLimitWarning, stacklevel=2)
    drill = build_exudyn(simulation, symbolic)
    mbs = drill.mbs
    actions = [drill.rock.update_bottom] if drill.rock.rock.crushes else []
    if drill.piston is not None:
        actions.insert(0, drill.piston)
    guard = None
    if settings.type in AUTOMATIC_STEP_SOLVERS:
        guard = _MinimumStepGuard(drill.settings.timeIntegration.minimumStepSize)
        actions.append(guard)
    if progress is not None:
        actions.append(_progress_reporter(settings.end_time_s, progress))
    pre_step = _pre_step(actions)
    if pre_step is not None:
        mbs.SetPreStepUserFunction(pre_step)
    with _no_cyclic_gc():
        start = time.process_time()
        ok = mbs.SolveDynamic(drill.settings, solverType=SOLVER_TYPES[settings.type])
        cpu = time.process_time() - start
    reached_s = mbs.systemData.GetTime()
    data = {name: _sensor(mbs, sensor) for name, sensor in drill.sensors.items()}
    time_s = data["x0"][:, 0]
    n = drill.chain.size
    position = np.column_stack([data[f"x{i}"][:, 1] for i in range(n)])
    velocity = np.column_stack([data[f"v{i}"][:, 1] for i in range(n)])
    history = np.array(drill.rock.bottom_history)
    piston = None if drill.piston is None else drill.piston.history(time_s, position, velocity)
    position, velocity = position[:, :simulation.chain.size], velocity[:, :simulation.chain.size]
    rock_state = drill.rock.state_at(time_s)
    result = SimulationResult(
        simulation=simulation,
        formulation="exudyn",
        time_s=time_s,
        position_m=position,
        velocity_m_per_s=velocity,
        bottom_m=rock_state[:, drill.rock.rock.bottom_index],
        rock_force_n=data["rock"][:, 1] if "rock" in data else None,
        impact_force_n=(data["impact"][:, 1] if piston is None else piston.contact_force_n) if "impact" in data else None,
        torsion_angle_rad=data["phi"][:, 1] if "phi" in data else None,
        torsion_rate_rad_per_s=data["omega"][:, 1] if "omega" in data else None,
        cpu_time_s=cpu,
        info={"solver_success": bool(ok), "coordinates": drill.coordinate_count,
              **({"fresh_fractions": drill.blows.fresh_fractions} if drill.blows else {})},
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
