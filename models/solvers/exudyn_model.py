"""The drill as an Exudyn multibody system (the project's main formulation).

Every axial body is a ``Node1D`` + ``ObjectMass1D``; every link of the chain an
``ObjectConnectorCoordinateSpringDamper``; the feed a constant ``LoadCoordinate`` per body; the
piston a ``LoadCoordinate`` with a symbolic load function (models.drill.pulse); the rock the
:class:`rocklaw.exudyn_element.ExudynRockContact` on the bit. Torsion, when its effect is on, is
a ``Node1D`` + ``ObjectRotationalMass1D`` with its own spring-damper to ground and a constant
torque. Only what the scene's effects and outputs need is built: no torsion node, no rock
damping term, no per-step hook for an elastic rock, no force sensors and no per-step storage
unless an output asks for them. Every body carries its graphics to scale (models.solvers.exudyn_graphics).

:func:`build_exudyn` returns the assembled system before it runs for a user to add Exudyn items of their own
(:class:`ExudynModel`; both docstrings say how); a normal run is the same build and run (:func:`simulate`).
A scene with wave rods builds the string's bodies with mass only, the rods an element of their own updated
before every step (models.waves.exudyn_waves).
"""

from __future__ import annotations

import contextlib
import math
import time
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ...rocklaw.exudyn_module import exu  # first: it chooses Exudyn's compiled module

# isort: split
from exudyn.itemInterface import (
    LoadCoordinate,
    MarkerNodeCoordinate,
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
from ..definition.formulations import AUTOMATIC_STEP_SOLVERS
from ..definition.scene import Scene
from ..definition.validation import InputError, short
from ..drill.chain import AxialChain
from ..drill.indexing import BlowStarts
from ..drill.pulse import impact_force
from ..drill.shapes import layout
from ..evaluation.results import SimulationResult
from ..evaluation.run_record import ExudynSolverRecord
from ..evaluation.run_result import Result
from ..evaluation.stability import StepLimitWarning, check_result, step_warning
from .exudyn_graphics import DrillGraphics, body_graphics, chain_cylinders, torsion_graphics
from .exudyn_messages import (
    SOLVER_TYPES,
    MinimumStepGuard,
    NamedItems,
    apply_extensions,
    exudyn_messages_as_warnings,
    no_cyclic_gc,
    pre_step,
    progress_reporter,
    replaced_pre_step,
    set_step,
    simulation_settings,
    solver_errors,
)
from .exudyn_piston import ExudynPiston
from .exudyn_start import start_assembled
from .exudyn_user_items import (
    EnergyTerm,
    ExudynBody,
    ExudynConnector,
    UserAccount,
    add_body,
    assembled_scales,
    coordinate_names,
    item_counts,
    link_force_function,
    time_runs_only,
    user_outcome,
)
from .simulation import Simulation, exudyn_simulation, solver_settings

if TYPE_CHECKING:
    from ..waves.exudyn_waves import WaveExudyn
COORDINATE = exu.OutputVariableType.Coordinates
RATE = exu.OutputVariableType.Coordinates_t
AXIS_X_FROM_Z = [[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]]  # a rotational node's local z onto the drilling axis


@dataclass
class ExudynModel:
    """The drill as an assembled Exudyn system, not yet run (:func:`build_exudyn`).

    :meth:`add_pre_step` adds a per-step function; one set with ``mbs.SetPreStepUserFunction`` replaces the model's
    own (the rock would never crush), so :meth:`run` runs it after them and :meth:`result` refuses a solve it
    replaced. :meth:`add_energy_term` declares an energy of one's own.

    Attributes
    ----------
    SC, mbs : exudyn.SystemContainer, exudyn.MainSystem
        Open to any Exudyn item of one's own: :meth:`run` (or ``exu.SolveDynamic(model.mbs, model.settings,
        solverType=model.solver_type)``, then :meth:`result`) runs it with the scene's solver settings, the step
        sized for the system as assembled; the energy account takes its masses, springs, loads, the series its sensors.
    bodies, connectors : mapping of str to ExudynBody, ExudynConnector
        By scene name: a body's ``.node``, ``.object``, ``.marker_position`` (spatial connectors),
        ``.marker_coordinate`` (coordinate connectors, loads); a connector's ``.object``.

    Examples
    --------
    >>> import rpdrill
    >>> model = rpdrill.build_exudyn(rpdrill.load_scene("paper_base"))
    >>> sorted(model.connectors), model.user_items()  # items of one's own: none yet
    (['collar_bit_joint', 'shank_collar_joint', 'shock_sub'], {})
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
    _settings: Any
    symbolic_functions: list[Any] = field(default_factory=list)  # kept alive with the system
    blows: BlowStarts | None = None  # the blow starts of this run (models.drill.indexing)
    piston: ExudynPiston | None = None  # the piston's strikes and catches (models.drill.piston)
    scene_formulation: str = "exudyn"  # the formulation the scene named (the model is always Exudyn's)
    symbolic: bool = True
    pre_steps: list[Callable[[Any, float], bool]] = field(default_factory=list)
    _built_items: dict[str, int] = field(default_factory=dict)
    _ran: bool = False
    _account: UserAccount | None = None
    _prepared_items: dict[str, int] = field(default_factory=dict)
    _watch: list[Callable[[Any, float], bool]] = field(default_factory=list)  # the run's guard and progress
    _installed: Any = None  # the pre-step function the model set on mbs
    _foreign: Any = None  # a pre-step function of the user's, set on mbs, run after the model's
    solution_path: Path | None = None
    waves: WaveExudyn | None = None  # wave rods: the element updated before every step (models.waves.exudyn_waves)
    extension_sensors: list[Any] = field(default_factory=list)  # models.solvers.exudyn_user_items

    def __post_init__(self) -> None:
        self.bodies, self.connectors = NamedItems("body", self.bodies), NamedItems("connector", self.connectors)
        self._account = UserAccount(*(self._built_items[kind] for kind in ("objects", "loads", "sensors")))
        self._install()

    @property
    def has_run(self) -> bool:
        """Whether the system has been solved (by :meth:`run` or Exudyn's ``SolveDynamic``)."""
        return self._ran or self.mbs.systemData.GetTime() > 0

    @property
    def built_items(self) -> dict[str, int]:
        """How many items of each kind the build made (a user's items are numbered from there)."""
        return dict(self._built_items)

    @property
    def coordinate_count(self) -> int:
        return len(self.mbs.systemData.GetODE2Coordinates())

    @property
    def settings(self) -> Any:
        """Exudyn's simulation settings of the run, its step sized for the system as assembled now
        (:meth:`prepare`): ``exu.SolveDynamic(model.mbs, model.settings, solverType=model.solver_type)``
        runs what :meth:`run` runs (InputError as :meth:`run`'s)."""
        time_runs_only(self.simulation)
        self.prepare()
        return self._settings

    @property
    def solver_type(self) -> Any:
        """Exudyn's ``DynamicSolverType`` of the scene's solver."""
        return SOLVER_TYPES[self.simulation.settings.type]

    def add_pre_step(self, function: Callable[[Any, float], bool]) -> None:
        """Call ``function(mbs, t)`` before every step, after the model's own functions (False stops the run)."""
        self.pre_steps.append(function)
        self._install()

    def add_energy_term(self, name: str, kind: str, joules: Callable[[ExudynModel, np.ndarray], np.ndarray],
                        items: Sequence[Any] = ()) -> None:
        """Declare an energy of one's own for the energy account: ``kind`` ``stored`` (held at each time),
        ``dissipated`` or ``work_in`` (cumulative from the start); ``joules(model, time_s)`` its value at the
        run's stored steps (read from sensors of one's own after the run); ``items`` the Exudyn items it
        accounts for (taken out of the automatic account; an item no term covers and the account cannot
        take makes the balance not a number)."""
        self._account.declare(EnergyTerm(name, kind, joules, tuple(items)))

    def write_solution(self, path: str | Path, period_s: float | None = None) -> None:
        """Have the run write Exudyn's coordinates solution file to ``path`` every ``period_s`` (default: the
        output interval), for ``exudyn.interactive.SolutionViewer`` (``exudyn.utilities.LoadSolutionFile``)."""
        solution = self._settings.solution.file
        solution.write = True
        solution.name = str(path)
        solution.writePeriod = period_s or self.simulation.settings.output_interval_s
        solution.export.velocities = solution.export.accelerations = False
        self.solution_path = Path(path)

    def coordinate_names(self) -> list[str]:
        """Each ODE2 coordinate's name in Exudyn's order, the solution file's columns (exudyn_user_items)."""
        return self.prepare() or coordinate_names(self)

    def user_items(self) -> dict[str, int]:
        """The Exudyn items added to ``mbs`` since the model was built (by the scene's extensions too), by
        kind (none: empty); the sensors the energy account adds are not counted."""
        return self._account.added(self.mbs, self._built_items)

    def prepare(self) -> None:
        """Take in the items added since the last call: assemble the system, size the step for it (the
        assembled system's eigenvalues, models.solvers.exudyn_user_items, where a solver.step_s does not
        fix it) and add the sensors of their energy account. :meth:`run` and :attr:`settings` call it."""
        if item_counts(self.mbs) == self._prepared_items:
            return
        self.mbs.Assemble()
        if self.user_items().keys() - {"sensors"}:
            start_assembled(self)  # a preloaded start, the solver the constraints need (models.solvers.exudyn_start)
            self._size_step()
        self._account.watch(self.mbs, "energy" in self.simulation.needed_data)
        self.mbs.Assemble()
        self._prepared_items = item_counts(self.mbs)

    def _size_step(self) -> None:
        if self.waves is not None:  # the step is the characteristics' (models.waves.steps)
            return
        scales = assembled_scales(self)
        settings = solver_settings(self.simulation.scene, self.simulation.piston, scales)
        self.simulation = replace(self.simulation, step_scales=scales, settings=settings)
        set_step(self._settings, settings)

    def _install(self) -> None:
        """Set the one pre-step function of the model's own functions, the user's and the run's watchers."""
        foreign = [] if self._foreign is None else [self._foreign]  # the user's, set on mbs: last
        actions = [*self._own_actions(), *self.pre_steps, *self._watch, *foreign]
        self._installed = pre_step(actions)
        self.mbs.SetPreStepUserFunction(self._installed or 0)

    def _own_actions(self) -> list[Callable[[Any, float], bool]]:
        actions: list[Callable[[Any, float], bool]] = [self.piston] if self.piston is not None else []
        actions += [self.rock.update_bottom] if self.rock is not None and self.rock.rock.crushes else []
        return actions + ([self.waves.pre_step] if self.waves is not None else [])

    def _replaced(self) -> dict[str, Any] | None:
        """The pre-step function on ``mbs`` when it is not the model's (a user's mbs.SetPreStepUserFunction)."""
        return replaced_pre_step(self.mbs, self._installed)

    def run(self, progress: Callable[[float], None] | None = None) -> Result:
        """Run the system (with any items added) by the scene's solver settings; ``progress(t)`` about
        100 times. The result is ``rpdrill.Result``, as ``rpdrill.simulate`` returns; a model runs once.
        InputError for a scene that asks for ``solver.steady_state: periodic``: a built model runs in time."""
        time_runs_only(self.simulation)
        raw = self.run_raw(progress)  # the step may change with what was added: the simulation after the run
        return Result(self.simulation.scene, raw, source="build_exudyn", code=self.simulation.code_records())

    def run_raw(self, progress: Callable[[float], None] | None = None) -> SimulationResult:
        """Run the system and return the formulation's raw result: what :meth:`run` wraps, and the Exudyn
        formulation's time run (models.solvers.time_run)."""
        if self.has_run:
            raise RuntimeError("an ExudynModel runs once (its rock state has moved on): build_exudyn(scene) again")
        self._ran = True
        replaced = self._replaced()
        if replaced is not None:
            if replaced.get("type") != "Python":
                raise ValueError("mbs.SetPreStepUserFunction replaced the model's per-step functions (the rock's "
                                 "state) with a symbolic one, which cannot run beside them; add it with "
                                 "model.add_pre_step(function) instead")
            self._foreign = replaced["function"]
        self.prepare()  # for what was added
        settings = self._settings
        guard = None
        if self.simulation.settings.type in AUTOMATIC_STEP_SOLVERS:
            guard = MinimumStepGuard(settings.timeIntegration.minimumStepSize)
            self._watch.append(guard)
        if progress is not None:
            self._watch.append(progress_reporter(self.simulation.settings.end_time_s, progress))
        self._install()
        if self.waves is None and (warning := step_warning(self.simulation)):
            warnings.warn(warning, StepLimitWarning, stacklevel=3)
        blas = self.waves.single_threaded() if self.waves is not None else contextlib.nullcontext()
        with no_cyclic_gc(), exudyn_messages_as_warnings(self.simulation.name), blas, solver_errors(self):
            start = time.process_time()
            ok = self.mbs.SolveDynamic(settings, solverType=self.solver_type)
            cpu = time.process_time() - start
        self._watch.clear()
        self._install()
        if guard is not None:
            guard.check(self.simulation.name, self.simulation.settings)
        return _read_result(self, bool(ok), cpu)

    def result(self) -> Result:
        """The result of a run by Exudyn's own ``exu.SolveDynamic(model.mbs, model.settings, ...)`` (as
        :meth:`run` returns it). RuntimeError when the system has not run, or when a function set with
        ``mbs.SetPreStepUserFunction`` replaced the model's per-step functions (the rock's state never
        moved): add such a function with ``model.add_pre_step`` instead; InputError as :meth:`run`'s."""
        time_runs_only(self.simulation)
        if self.mbs.systemData.GetTime() <= 0:
            raise RuntimeError("model.result(): the system has not run; call model.run() or "
                               "exu.SolveDynamic(model.mbs, model.settings, solverType=model.solver_type) first")
        if self._replaced() is not None and self._own_actions():
            raise RuntimeError("model.result(): mbs.SetPreStepUserFunction replaced the model's per-step functions, "
                               "so the rock's state never moved during that solve; add per-step functions with "
                               "model.add_pre_step(function), or run model.run(), which runs both")
        self._ran = True
        return Result(self.simulation.scene, _read_result(self, True, math.nan), source="exu.SolveDynamic",
                      code=self.simulation.code_records())


def build_exudyn(run: Scene | Simulation, symbolic: bool = True, graphics: bool = True) -> ExudynModel:
    """The drill of a scene as an assembled Exudyn system, not yet run, its extensions applied; ``run()`` runs it.

    Parameters
    ----------
    run : Scene or Simulation
        The scene (built for Exudyn whatever its formulation), or a prepared simulation.
    symbolic, graphics : bool, default True
        False: Python callbacks for the impact and rock forces (the same law, slower); no bodies' cylinders,
        which only a renderer shows (a build of 1.2 ms, not 16.3 ms: ``python benchmarks/bench_core.py``).

    Returns
    -------
    ExudynModel

    Raises
    ------
    InputError
        When ``run`` is not a scene, or the scene cannot be built.

    Examples
    --------
    >>> import rpdrill
    >>> model = rpdrill.build_exudyn(rpdrill.load_scene("paper_base").with_({"solver.end_time_s": 0.3}))
    >>> sorted(model.bodies), model.solver_type.name, model.run().formulation
    (['bit', 'collar', 'pipe', 'shank'], 'RK44', 'exudyn')
    """
    if not isinstance(run, (Scene, Simulation)):
        raise InputError(f"rpdrill.build_exudyn: run: {short(run)}: give a rpdrill.Scene (rpdrill.load_scene) or a "
                         "prepared simulation")
    simulation, named = exudyn_simulation(run)
    if simulation.dynamic_chain.waves:  # the string's bodies with mass, the rods an element (models.waves)
        from ..waves.exudyn_waves import WaveExudyn  # here: without wave rods, neither they nor numba load
        model = WaveExudyn(simulation, symbolic).model(ExudynModel, ExudynBody, ExudynConnector,
                                                       simulation_settings(simulation), named)
        apply_extensions(model)
        return model
    chain, impact, piston = simulation.dynamic_chain, simulation.impact, simulation.piston
    initial_positions = simulation.initial_positions_m if piston is None else piston.parked(simulation.initial_positions_m)
    shapes = layout(simulation.scene)
    container = exu.SystemContainer()
    mbs = container.AddSystem()
    ground = mbs.AddNode(NodePointGround())
    ground_marker = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=ground, coordinate=0))

    bodies: list[ExudynBody] = []
    rods = {name for name, body in simulation.scene.drill_string.bodies.items() if body.is_rod}
    velocities = np.pad(simulation.initial_velocities, (0, chain.size - simulation.chain.size))  # a piston's: 0
    for body, cylinder, initial, speed in zip(chain.bodies, chain_cylinders(shapes, chain), initial_positions, velocities,
                                              strict=True):
        shown = VObjectMass1D(graphicsData=body_graphics(cylinder, cylinder.group in rods) if graphics else [])
        bodies.append(add_body(mbs, body.name, lambda n, m=body.mass_kg, x=cylinder.centre_m, v=shown: mbs.AddObject(
            ObjectMass1D(nodeNumber=n, mass=m, referencePosition=[x, 0.0, 0.0], visualization=v)), initial, speed))
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
                mbs, connector, "springForceUserFunction", link_force_function(link, backend), symbolic))

    impact_load = mbs.AddLoad(LoadCoordinate(markerNumber=markers[chain.impact_body], load=0.0))

    def piston_force(mbs, t, load):
        return impact_force(impact, t, backend)

    impact_function = attach_user_function(mbs, impact_load, "loadUserFunction", piston_force, symbolic)
    tor = simulation.torsion
    torsion = None
    if tor is not None:  # before the rock: the blow start reads its angle
        bit = shapes.cylinders[chain.bit_body]
        shown = VObjectRotationalMass1D(graphicsData=torsion_graphics(bit.diameter_m) if graphics else [])
        torsion = add_body(mbs, "torsion", lambda n: mbs.AddObject(ObjectRotationalMass1D(
            nodeNumber=n, inertia=tor.inertia_kg_m2, referencePosition=[bit.centre_m, 0.0, 0.0],
            referenceRotation=AXIS_X_FROM_Z, visualization=shown)), simulation.initial_torsion_angle_rad,
            simulation.initial_torsion_rate_rad_per_s)
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
        sensors[f"x{i}"] = mbs.AddSensor(SensorNode(nodeNumber=body.node, storeInternal=True, outputVariableType=COORDINATE))
        sensors[f"v{i}"] = mbs.AddSensor(SensorNode(nodeNumber=body.node, storeInternal=True, outputVariableType=RATE))
    if "forces" in simulation.needed_data:
        sensors["rock"] = mbs.AddSensor(SensorObject(objectNumber=rock.object, storeInternal=True,
                                                   outputVariableType=exu.OutputVariableType.Force))
        sensors["impact"] = mbs.AddSensor(SensorLoad(loadNumber=impact_load, storeInternal=True))

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
        sensors["phi"] = mbs.AddSensor(SensorNode(nodeNumber=torsion.node, storeInternal=True,
                                                outputVariableType=COORDINATE))
        sensors["omega"] = mbs.AddSensor(SensorNode(nodeNumber=torsion.node, storeInternal=True, outputVariableType=RATE))

    drawn = DrillGraphics(simulation.chain, shapes, [body.node for body in bodies[:simulation.chain.size]], COORDINATE)
    mbs.AddObject(ObjectGround(visualization=VObjectGround(graphicsData=drawn.static(),
                                                           graphicsDataUserFunction=drawn)))
    mbs.Assemble()
    hook = None if piston is None else ExudynPiston(piston, [body.node for body in bodies], mbs, impact.period_s)
    model = ExudynModel(simulation, chain, container, mbs, {body.name: body for body in bodies}, connectors, rock,
                        torsion, drawn, sensors, simulation_settings(simulation), [impact_function, *user_functions],
                        blows, hook, named, symbolic, _built_items=item_counts(mbs), _prepared_items=item_counts(mbs))
    apply_extensions(model)
    return model


def simulate(run: Scene | Simulation, progress: Callable[[float], None] | None = None,
             symbolic: bool = True) -> SimulationResult:
    """Build and run the Exudyn model (:func:`build_exudyn`, without the bodies' graphics: the system
    is not returned, no renderer sees it; :meth:`ExudynModel.run_raw`)."""
    return build_exudyn(run, symbolic, graphics=False).run_raw(progress)


def _read_result(model: ExudynModel, ok: bool, cpu: float) -> SimulationResult:
    """The solved system's sensors read into a result (module doc), checked (models.evaluation.stability)."""
    if model.waves is not None:
        result = model.waves.finish(ok, cpu)
        result.exudyn_model, result.user_energy, result.user_series, result.extension_state = \
            user_outcome(model, result.time_s)
        return result
    simulation, mbs = model.simulation, model.mbs
    reached_s = mbs.systemData.GetTime()
    data = {name: mbs.GetSensorStoredData(sensor) for name, sensor in model.sensors.items()}
    time_s = data["x0"][:, 0]
    position = np.column_stack([data[f"x{i}"][:, 1] for i in range(model.chain.size)])
    velocity = np.column_stack([data[f"v{i}"][:, 1] for i in range(model.chain.size)])
    history = np.array(model.rock.bottom_history)
    piston = None if model.piston is None else model.piston.history(time_s, position, velocity)
    position, velocity = position[:, :simulation.chain.size], velocity[:, :simulation.chain.size]
    rock_state = model.rock.state_at(time_s)
    solver = ExudynSolverRecord(success=ok, samples=len(time_s), coordinates=model.coordinate_count,
                                fresh_fractions=tuple(model.blows.fresh_fractions) if model.blows else ())
    record, energy, series, extension = user_outcome(model, time_s)
    result = SimulationResult(
        simulation=simulation, formulation="exudyn", time_s=time_s, position_m=position, velocity_m_per_s=velocity,
        bottom_m=rock_state[:, model.rock.rock.bottom_index],
        rock_force_n=data["rock"][:, 1] if "rock" in data else None,
        impact_force_n=(data["impact"][:, 1] if piston is None else piston.contact_force_n) if "impact" in data
        else None,
        torsion_angle_rad=data["phi"][:, 1] if "phi" in data else None,
        torsion_rate_rad_per_s=data["omega"][:, 1] if "omega" in data else None,
        solver=solver, cpu_time_s=cpu, bottom_events=(history[:, 0], history[:, 1]), rock_state_m=rock_state,
        piston=piston, user_energy=energy, user_series=series, extension_state=extension, exudyn_model=record,
    )
    check_result(result, solver_ok=ok, reached_s=reached_s)
    return result
