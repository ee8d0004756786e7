"""The Exudyn formulation of a scene with wave rods: Exudyn integrates the drill string's bodies with
mass, the wave rods are an element of their own, updated before every step.

Exudyn's integrators need a mass on every coordinate; a wave rod's faces have none, and a massless
face under a stiff contact or the rock is a stiff first-order system that an explicit step would have
to resolve (and an implicit one spikes at every front: docs/model.md). So the element is the
characteristics of models.waves.stepping with everything that acts on a face (a link or contact that
touches one, the rock or the pulse on one, and a piston striking a wave rod or a face), integrated
exactly over each of Exudyn's steps; the string's bodies with mass are Exudyn's (their links between
them, the rock law on a bit with mass, the pulse and the feed on them, and any item a user adds), seen
by the element as moving at their velocity over the step (kinematic nodes). Before every step the
element

1. takes the bodies' positions and velocities from Exudyn,
2. advances the waves and the faces one step (exactly, the bodies at their velocity),
3. sets on each body the force of the faces' elements on it over the step, a straight line in time
   (its end value and the value that keeps its impulse) on a symbolic ``LoadCoordinate``.

A body joined to a face is so coupled explicitly, first order in the step (the step is the
characteristics' step, a fraction of a rod's transit time: small against a body's own periods).
The histories come from the element's samples, taken at step starts; the rock on a bit with mass from
Exudyn's rock element. The works (the energy account's, the rock's per blow) are the element's, integrated
exactly over its steps (models.waves.works), and those of what Exudyn integrates by the trapezoidal rule
on every step's ends.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
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
    ObjectMass1D,
)

from ...rocklaw.backends import SCALAR, SymbolicBackend
from ...rocklaw.exudyn_element import ExudynRockContact, attach_user_function
from ..drill.chain import joined
from ..drill.pulse import impact_force
from ..evaluation.results import SimulationResult
from ..evaluation.stability import SimulationFailed
from .exact_waves import BLAS, result
from .outgoing import BodyMotion, body_segments, port_work_j
from .recording import Snapshot
from .stepping import Stepper


class WaveExudyn:
    """The Exudyn system of a scene with wave rods (module doc): ``mbs`` with the string's bodies with
    mass (``bodies``: chain index -> (node, object, coordinate marker, position marker)), the links
    between them (``connectors``), the rock element on a bit with mass (``rock``), and the wave element
    (``stepper``) that drives the loads ``loads`` before every step."""

    def __init__(self, simulation: Any, symbolic: bool = True) -> None:
        self.simulation, self.symbolic = simulation, symbolic
        chain, settings = simulation.dynamic_chain, simulation.settings
        string = simulation.chain.size
        self.SC = exu.SystemContainer()
        mbs = self.mbs = self.SC.AddSystem()
        ground = mbs.AddNode(NodePointGround())
        self.ground_marker = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=ground, coordinate=0))
        kinematic = tuple(i for i in range(string) if chain.bodies[i].mass_kg > 0)
        self.stepper = Stepper(simulation, settings.step_s, settings.output_interval_s, kinematic=kinematic,
                               record_steps=False)
        positions = simulation.initial_positions_m
        self.bodies: dict[int, tuple[Any, Any, Any, Any]] = {}
        for i in kinematic:
            body = chain.bodies[i]
            node = mbs.AddNode(Node1D(referenceCoordinates=[0.0], initialCoordinates=[float(positions[i])],
                                      initialVelocities=[0.0]))
            obj = mbs.AddObject(ObjectMass1D(nodeNumber=node, mass=body.mass_kg))
            marker = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node, coordinate=0))
            self.bodies[i] = (node, obj, marker, mbs.AddMarker(MarkerBodyPosition(bodyNumber=obj,
                                                                                  localPosition=[0.0, 0.0, 0.0])))
            if body.constant_force_n:
                mbs.AddLoad(LoadCoordinate(markerNumber=marker, load=body.constant_force_n))
        backend = SymbolicBackend() if symbolic else SCALAR
        self.functions: list[Any] = []
        self.connectors: dict[str, tuple[Any, Any]] = {}
        for link in chain.links:
            if link.body_b not in self.bodies or (link.body_a is not None and link.body_a not in self.bodies):
                continue  # the wave element's
            base = self.ground_marker if link.body_a is None else self.bodies[link.body_a][2]
            connector = mbs.AddObject(ObjectConnectorCoordinateSpringDamper(
                markerNumbers=[base, self.bodies[link.body_b][2]], stiffness=link.stiffness_n_per_m,
                damping=link.damping_n_s_per_m))
            self.connectors[link.name] = (connector, link)
            if not link.linear:
                self.functions.append(attach_user_function(mbs, connector, "springForceUserFunction",
                                                           _link_force(link, backend), symbolic))
        impact = simulation.impact
        if chain.impact_body in self.bodies and impact.piston is None:
            load = mbs.AddLoad(LoadCoordinate(markerNumber=self.bodies[chain.impact_body][2], load=0.0))
            self.functions.append(attach_user_function(
                mbs, load, "loadUserFunction", lambda mbs, t, load: impact_force(impact, t, backend), symbolic))
        self.rock = None
        if chain.bit_body in self.bodies:
            blows = simulation.blow_starts()
            start_blow = None
            if blows is not None:
                def start_blow(position: float, state: tuple[float, ...]) -> tuple[float, ...]:
                    layout = self.stepper.layout
                    angle = self.stepper.w[layout.angle] if layout.torsion else 0.0
                    law, state = blows(position, state, angle)
                    self.rock.set_law(law)
                    return state
            node, _, marker, _ = self.bodies[chain.bit_body]
            self.rock = ExudynRockContact(mbs, self.ground_marker, marker, node, simulation.rock, symbolic=symbolic,
                                          initial_state=simulation.initial_rock_state, start_blow=start_blow,
                                          blow_period_s=impact.period_s)
            self.rock_blows = blows
        self._ports(kinematic)
        self._couple(symbolic)
        mbs.Assemble()
        self.exudyn_links = [link for _, link in self.connectors.values()]
        self.pulse_on_body = self.stepper.pulse_outside = chain.impact_body in self.bodies and impact.piston is None
        self.last_powers: np.ndarray | None = None
        self.indices = np.array([mbs.GetNodeODE2Index(self.bodies[i][0]) for i in kinematic], dtype=int)
        self.body_nodes = np.array(sorted(self.bodies), dtype=int)  # the bodies' places in the element's state
        self.velocity_index = np.array([self.stepper.layout.velocity[i] for i in kinematic], dtype=int)
        self.closed, self.previous = 0, self.stepper.w[:self.stepper.layout.n].copy()
        self.previous_velocity = np.zeros(self.stepper.layout.n)
        self.last_velocity: np.ndarray | None = None  # the bodies' velocities at the last step's start
        self.last_positions = np.zeros(len(self.bodies))
        self.step_start = None  # the snapshot of the step in progress at its start, made if a peak wants it
        self.masses = np.array([chain.bodies[i].mass_kg for i in sorted(self.bodies)])
        self.failed_at_s: float | None = None

    def _ports(self, kinematic: tuple[int, ...]) -> None:
        """The faces joined rigidly to a body with mass move with it: their rods' ends are the body's ports,
        a dashpot Z in Exudyn (implicit in its integrator) and the arriving waves 2 Z w_in in the body's load;
        their outgoing waves are closed from the body's motion after each step (:meth:`pre_step`)."""
        stepper, chain = self.stepper, self.simulation.dynamic_chain
        owner = joined(chain.size, chain.rigid_pairs(), frozenset(kinematic))
        self.attached = {node: owner[node] for node in range(chain.size) if node not in kinematic and owner[node] in kinematic}
        body_ports = [p for p, port in enumerate(stepper.ports) if port.node in self.attached]
        stepper.own_ports = np.array([p for p in range(len(stepper.ports)) if p not in body_ports], dtype=int)
        self.body_ports = np.array(body_ports, dtype=int)
        self.dashpots = np.zeros(len(self.bodies))
        order = sorted(self.bodies)
        for p in body_ports:
            port = stepper.ports[p]
            self.dashpots[order.index(self.attached[port.node])] += port.impedance_n_s_per_m
        for j, i in enumerate(order):
            if self.dashpots[j] > 0:
                self.mbs.AddObject(ObjectConnectorCoordinateSpringDamper(
                    markerNumbers=[self.ground_marker, self.bodies[i][2]], stiffness=0.0, damping=self.dashpots[j]))

    def _couple(self, symbolic: bool) -> None:
        """A load a + b (t - t0) on every body (module doc, 3.)."""
        mbs = self.mbs
        self.start_variable = exu.symbolic.Real("wave_step_start_s", 0.0) if symbolic else None
        self.load_variables: list[tuple[Any, Any]] = []
        self.load_values = np.zeros((len(self.bodies), 2))
        self.step_start_s = 0.0
        for j, i in enumerate(sorted(self.bodies)):
            if symbolic:
                pair = (exu.symbolic.Real(f"wave_load_{j}_a", 0.0), exu.symbolic.Real(f"wave_load_{j}_b", 0.0))
                self.load_variables.append(pair)
            load = mbs.AddLoad(LoadCoordinate(markerNumber=self.bodies[i][2], load=0.0))
            self.functions.append(attach_user_function(mbs, load, "loadUserFunction", self._load_function(j), symbolic))

    def _load_function(self, j: int) -> Callable[..., Any]:
        """Body j's load a + b (t - t0): recorded with the symbolic variables, or reading the floats."""
        if self.symbolic:
            a, b = self.load_variables[j]

            def symbolic_force(mbs, t, load):
                return a + b * (t - self.start_variable)
            return symbolic_force

        def force(mbs, t, load):
            return self.load_values[j, 0] + self.load_values[j, 1] * (t - self.step_start_s)
        return force

    # -- running --------------------------------------------------------------------------------------

    def _sync(self) -> None:
        """The bodies' positions and velocities from Exudyn into the element's state (and their faces'); the
        outgoing waves of the bodies' ports over the step that ended (:meth:`_ports`)."""
        data, stepper = self.mbs.systemData, self.stepper
        if not len(self.indices):
            return
        w = stepper.w
        before = w[:stepper.layout.n].copy()
        w[self.body_nodes] = np.asarray(data.GetODE2Coordinates())[self.indices]
        w[self.velocity_index] = np.asarray(data.GetODE2Coordinates_t())[self.indices]
        for face, body in self.attached.items():
            w[face] = w[body]
        k = stepper.step_index
        velocity = stepper.key().velocity @ w
        if len(self.body_ports) and k > 0 and self.closed < k:
            nodes = stepper.port_nodes
            motion = BodyMotion(self.previous[nodes], w[nodes], self.previous_velocity[nodes], velocity[nodes],
                                stepper.step_s)
            def end() -> Snapshot:  # Exudyn's state at the step's end: exact (taken only for a peak there)
                return stepper._snapshot(k * stepper.step_s, w, stepper.key(), after=False)
            moved = body_segments(stepper.last_segments, motion)
            stepper.close_ports(k - 1, self.body_ports, moved, again=True, ends=(self.step_start, end))
            stepper.works[1] += port_work_j(stepper.last_segments, moved, motion, self.body_ports,
                                            stepper.port_impedances)
            self.closed = k
        if k >= self.closed:
            self.previous, self.previous_velocity = w[:stepper.layout.n].copy(), velocity
        else:
            self.previous = before

    def pre_step(self, mbs: Any, t: float) -> bool:
        """Before the step that ends at ``t`` (Exudyn passes the end; the state is the start's)."""
        stepper = self.stepper
        k = stepper.step_index
        if k >= stepper.steps:
            return True
        self._sync()
        if not np.isfinite(stepper.w).all():
            self.failed_at_s = k * stepper.step_s
            return False
        velocity = stepper.w[self.velocity_index]
        positions = stepper.w[self.body_nodes]
        if self.last_velocity is not None:  # Exudyn's forces over the last step: the bodies' motion predicted
            h = stepper.step_s
            applied = self.load_values[:, 0] + 0.5 * h * self.load_values[:, 1] \
                - self.dashpots * (positions - self.last_positions) / h
            stepper.w[stepper.layout.acceleration:stepper.layout.acceleration + len(velocity)] = \
                (velocity - self.last_velocity) / h - applied / self.masses
        self.last_velocity, self.last_positions = velocity, positions
        self._add_works(k * stepper.step_s)
        if k % stepper.sample_every == 0 or stepper.caught_at_end:
            stepper._record(k * stepper.step_s, stepper.w, stepper.key(), after=stepper.caught_at_end,
                            kept=stepper.caught_at_end)
        if len(self.body_ports):  # the step's start after its arriving jumps: a body port's peak may be there
            stepper._set_inputs(k)
            self.step_start = stepper.snapshot_if_wanted(k * stepper.step_s, stepper.w, stepper.key(), after=True)
        stepper.advance()
        # the dashpots are Exudyn's: their force at the predicted velocity, a straight line, taken out
        start = stepper.body_loads[0] + self.dashpots * velocity
        end = stepper.body_loads[1] + self.dashpots * stepper.w[self.velocity_index]
        slope = (end - start) / stepper.step_s
        self.step_start_s = k * stepper.step_s
        self.load_values[:, 0], self.load_values[:, 1] = start, slope
        if self.symbolic:
            self.start_variable.SetValue(self.step_start_s)
            for (a, b), value_a, value_b in zip(self.load_variables, start, slope, strict=True):
                a.SetValue(float(value_a))
                b.SetValue(float(value_b))
        return True

    def _powers(self, t: float) -> np.ndarray:
        """(impact, internal, rock) powers of what Exudyn integrates itself: the pulse on a body with mass, the
        links between bodies, the rock on a bit with mass (the element integrates its own: models.waves.works)."""
        w, velocity, chain = self.stepper.w, self.stepper.key().velocity @ self.stepper.w, self.stepper.chain
        impact = impact_force(self.simulation.impact, t) * velocity[chain.impact_body] if self.pulse_on_body else 0.0
        internal = 0.0
        for link in self.exudyn_links:
            rate = link.stretch(velocity)
            internal += float(link.force_n(link.stretch(w), rate)) * rate
        rock = 0.0
        if self.rock is not None:
            bit_velocity = float(velocity[chain.bit_body])  # plain floats: the law as fast as it evaluates in Python
            rock = self.rock.rock.force(float(w[chain.bit_body]), bit_velocity, self.rock.state, SCALAR) * bit_velocity
        return np.array([impact, internal + rock, rock])

    def _add_works(self, t: float) -> None:
        """The works of what Exudyn integrates over the step that ended at ``t``, by the trapezoidal rule on
        the states at its ends (smooth: bodies with mass; a port's arriving wave on each side of its jumps),
        added to the element's (its works and the blow's rock work), so that the run's works are whole."""
        powers = self._powers(t)
        stepper = self.stepper
        if self.last_powers is not None:
            done = 0.5 * stepper.step_s * (self.last_powers + powers)
            stepper.works += done[:2]
            stepper.statistics.rock_work_j[-1] += done[2]
        self.last_powers = powers

    def model(self, model_type: type, body_type: type, connector_type: type, settings: Any, named: str) -> Any:
        """The built model (models.solvers.exudyn_model.ExudynModel, its types given: this package sits below
        it) holding the bodies with mass, the links between them, the rock element on a bit with mass and
        this element; refused (SceneError) for an automatic-step solver."""
        simulation = self.simulation
        if simulation.settings.type in ("dopri5", "ode23"):
            raise ValueError(f"solver.type {simulation.settings.type}: wave rods step at the characteristics' fixed "
                             "step (every step advances the waves once): use a fixed-step type such as rk44")
        chain = simulation.dynamic_chain
        bodies = {chain.bodies[i].name: body_type(chain.bodies[i].name, *items) for i, items in self.bodies.items()}
        connectors = {name: connector_type(name, connector, link) for name, (connector, link) in self.connectors.items()}
        counts = {"nodes": self.mbs.systemData.NumberOfNodes(), "objects": self.mbs.systemData.NumberOfObjects(),
                  "markers": self.mbs.systemData.NumberOfMarkers(), "loads": self.mbs.systemData.NumberOfLoads(),
                  "sensors": self.mbs.systemData.NumberOfSensors()}
        return model_type(simulation, chain, self.SC, self.mbs, bodies, connectors, self.rock, None, None, {}, settings,
                          self.functions, scene_formulation=named, symbolic=self.symbolic, _built_items=dict(counts),
                          _prepared_items=dict(counts), waves=self)

    def single_threaded(self) -> Any:
        """BLAS on one thread while the element runs (its small matrices: threads cost more than they save)."""
        return BLAS.limit(limits=1, user_api="blas")

    def finish(self, ok: bool, cpu_s: float) -> SimulationResult:
        """The run's result once Exudyn has solved the system (module doc); SimulationFailed where it stopped."""
        simulation, mbs, stepper = self.simulation, self.mbs, self.stepper
        self._sync()
        self._add_works(stepper.step_index * stepper.step_s)
        stepper._record(stepper.step_index * stepper.step_s, stepper.w, stepper.key(), kept=False)
        stepper.record_peaks()
        stepper.read_envelopes(stepper.step_index)
        if not ok or self.failed_at_s is not None or stepper.step_index < stepper.steps:
            at = self.failed_at_s if self.failed_at_s is not None else stepper.step_index * stepper.step_s
            raise SimulationFailed(f"scene '{simulation.name}': solver {simulation.settings.type} with the wave step "
                                   f"{stepper.step_s:g} s failed at t = {at:.6g} s; try solver.step_s "
                                   f"{stepper.step_s / 2:g}")
        out = result(stepper, "exudyn", cpu_s, coordinates=len(mbs.systemData.GetODE2Coordinates()))
        if self.rock is not None:  # the rock on a bit with mass is Exudyn's
            law, states = self.rock.rock, self.rock.state_at(out.time_s)
            out.rock_state_m = states
            out.bottom_m = states[:, law.bottom_index]
            out.rock_force_n = np.asarray(law.force(out.bit_position_m, out.bit_velocity_m_per_s, tuple(states.T)))
            out.bottom_events = tuple(np.array(column) for column in zip(*self.rock.bottom_history, strict=True))
            if self.rock_blows:
                out.solver = replace(out.solver, fresh_fractions=tuple(self.rock_blows.fresh_fractions))
        return out


def _link_force(link: Any, backend: Any) -> Callable[..., Any]:
    def link_force(mbs, t, itemNumber, displacement, velocity, stiffness, damping, offset):
        return link.force_n(displacement, velocity, backend)
    return link_force
