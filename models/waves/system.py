"""The linear system between two wave steps: lumped bodies, massless faces and the waves arriving at them.

Over one step of the characteristics (models.waves.stepping) every rod's arriving wave is a known
linear function of time, w_in(t) = a + b (t - t_k), and the rest of the drill is the piecewise-linear
model of the other formulations, with the faces of the wave rods as massless nodes. In the augmented
state

    w = (x (every node), v (nodes with mass), rock states, [phi, phi'], 1, u1, u2, [acceleration per kinematic node],
         (a_p, b_p) per port)

(a_p' = b_p, b_p' = 0; 1, u1, u2 the pulse generator of models.drill.pulse) the model is linear and
autonomous in each key (the modes of its piecewise elements, the pulse phase): w' = A w, A generated
here, never written by hand:

* every force on a node is a row over z = (w, v of every node): the chain's linear links, each
  piecewise element in its mode (the rock law, couplings, the piston's contact: rocklaw.modes), the feed,
  the pulse, and each rod end (port) on its node: F = Z (2 a_p - v) (models.drill.wave_rod);
* nodes joined by a rigid link (a connector without stiffness between rigid faces) or by a rigid
  contact that is closed form a group that moves as one: with the group's body (at most one node with
  mass) or, without one, at the velocity that balances the forces on its massless members; the
  velocities of the massless groups solve the linear system "sum of forces = 0" (a face's dashpots Z
  and any damper on it make it regular), and substituting them turns every row over z into a row over
  w (:meth:`Key.over_w`);
* a rigid link or contact carries the force that balances the massless side of its group
  (:meth:`WaveSystem.key`: ``constraints``); a rigid contact opens when that force would pull.

A node may also be *kinematic* (the Exudyn formulation's bodies seen from the waves, models.waves.exudyn_waves):
the element predicts its motion over the step, m v' = (this system's force on it) + m a_e, a_e' = 0, with a_e
the acceleration of the forces Exudyn applies (its links, the rock on a bit with mass, items of one's own) as
over the last step: what acts between a face and a body (a stiff spring, a port) is integrated with the
body's inertia, not at first order in the step. What acts only between kinematic
nodes (and ground) is then Exudyn's, not this system's: those links, the rock law on a kinematic bit,
the pulse on a kinematic impact body and the feed on kinematic nodes; the system gives each kinematic
node the force of everything else on it (``Key.body_forces``), which the Exudyn model applies as a load.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field

import numpy as np

from ...rocklaw import RockLaw
from ...rocklaw.base import POSITION, VELOCITY
from ...rocklaw.modes import Mode, ModeTable
from ..definition.links import CLOSED, OPEN, RATE, STRETCH, Link
from ..definition.scene import Impact, Torsion
from ..drill.chain import AxialChain, joined, torsion_first_order_matrix
from ..drill.piecewise import Element
from ..drill.pulse import phase_generator, phase_row
from ..drill.wave_rod import BOTTOM, TOP

Modes = tuple[str, ...]
CONSTRAINT = "constraint"  # a rigid element's closed mode: its force is the constraint force


@dataclass(frozen=True)
class Port:
    """One end of a wave rod on its node; its arriving wave is w[input] + w[input + 1] (t - t_k)."""

    rod: int
    end: str
    node: int
    impedance_n_s_per_m: float
    input: int


@dataclass(frozen=True)
class Layout:
    """Indices into w (module doc)."""

    n: int
    velocity_nodes: tuple[int, ...]  # the nodes with a velocity state (bodies with mass, kinematic bodies)
    rock_states: int
    torsion: bool
    ports: int
    accelerations: int = 0  # the kinematic nodes' a_e (in node order)

    @property
    def velocity(self) -> dict[int, int]:
        return {node: self.n + i for i, node in enumerate(self.velocity_nodes)}

    @property
    def rock(self) -> int:
        return self.n + len(self.velocity_nodes)

    @property
    def angle(self) -> int:
        return self.rock + self.rock_states

    @property
    def one(self) -> int:
        return self.angle + 2 * self.torsion

    @property
    def acceleration(self) -> int:
        return self.one + 3

    @property
    def inputs(self) -> int:
        return self.one + 3 + self.accelerations

    @property
    def size(self) -> int:
        return self.inputs + 2 * self.ports


@dataclass
class Key:
    """Everything of one (modes, phase): A, the nodes' velocity rows V (v = V w), the node force rows,
    the exits and their resets, and the rows the outputs read."""

    matrix: np.ndarray
    velocity: np.ndarray  # (n, m)
    exits: list[tuple[np.ndarray, int, Modes, list[tuple[int, np.ndarray]], int]]  # row, direction, next, resets, element
    rock_force: np.ndarray
    element_forces: list[np.ndarray | None]  # each element's force row in its mode (None: no force)
    constraints: dict[str, np.ndarray]  # rigid link or closed rigid contact -> its force row (F > 0 pulls)
    link_forces: dict[str, np.ndarray] = field(default_factory=dict)  # finite linear links, spring part
    body_forces: np.ndarray | None = None  # (kinematic nodes, m): the system's force on each
    phase: str = ""  # the pulse phase of the key
    cache: dict = field(default_factory=dict)  # propagators of this key (models.waves.stepping)

    def over_w(self, row_z: np.ndarray) -> np.ndarray:
        m = self.matrix.shape[0]
        return row_z[:m] + row_z[m:] @ self.velocity


def _unit(size: int, index: int) -> np.ndarray:
    row = np.zeros(size)
    row[index] = 1.0
    return row


def _rigid_table(link: Link) -> ModeTable:
    """The modes of a rigid compression-only element: open as declared, closed as a constraint that opens
    when its force would pull (the exit is generated by :meth:`WaveSystem.key`)."""
    table = dict(link.modes())
    table[CLOSED] = Mode({}, ())
    return {name: mode for name, mode in table.items() if name != "clipped"}


class WaveSystem:
    """The generated system of one run (module doc); :meth:`key` builds (and caches) a key's arrays."""

    def __init__(self, chain: AxialChain, rock: RockLaw, torsion: Torsion | None, impact: Impact,
                 kinematic: Iterable[int] = (), catch_by_row: bool = True) -> None:
        self.chain, self.rock, self.torsion, self.impact = chain, rock, torsion, impact
        n = chain.size
        self.masses = np.array([body.mass_kg for body in chain.bodies])
        self.kinematic = frozenset(kinematic)
        external = self._external
        self.rock_owned = chain.bit_body not in self.kinematic
        velocity_nodes = tuple(i for i in range(n) if self.masses[i] > 0 or i in self.kinematic)
        self.layout = layout = Layout(n, velocity_nodes, len(rock.state_names), torsion is not None,
                                      2 * len(chain.waves), len(self.kinematic))
        self.ports = tuple(Port(r, end, rod.node(end), rod.impedance_n_s_per_m, layout.inputs + 2 * (2 * r + e))
                           for r, rod in enumerate(chain.waves) for e, end in enumerate((TOP, BOTTOM)))
        self.z = layout.size + n
        self.rigid_links = tuple(link for link in chain.links if link.linear and link.rigid)
        self.springs = tuple(link for link in chain.links if link.linear and not link.rigid and not external(link))
        self.pieces = (self._rock_element(), *(self._link_element(link, catch_by_row)
                                               for link in chain.nonlinear_links() if not external(link)))
        self.rigid = tuple(i for i, piece in enumerate(self.pieces) if i > 0 and piece.law.rigid)
        self.keys: dict[tuple[Modes, str], Key] = {}

    def _external(self, link: Link) -> bool:
        """Whether ``link`` acts between kinematic nodes (and ground) only: the Exudyn model's."""
        return link.body_b in self.kinematic and (link.body_a is None or link.body_a in self.kinematic)

    # -- placement ------------------------------------------------------------------------------------

    def _rock_element(self) -> Element:
        bit, rock, layout = self.chain.bit_body, self.rock, self.layout
        states = {name: layout.rock + i for i, name in enumerate(rock.state_names)}
        variables = {POSITION: _unit(self.z, bit), VELOCITY: _unit(self.z, layout.size + bit),
                     **{name: _unit(self.z, index) for name, index in states.items()}}
        return Element("rock", rock, rock.modes(), variables, states, states[rock.state_names[rock.bottom_index]],
                       -_unit(self.layout.n, bit))

    def _link_element(self, link: Link, catch_by_row: bool) -> Element:
        m, n = self.layout.size, self.layout.n
        a, b = link.body_a, link.body_b
        ends = _unit(self.z, b) - (0.0 if a is None else _unit(self.z, a))
        rates = _unit(self.z, m + b) - (0.0 if a is None else _unit(self.z, m + a))
        load = (0.0 if a is None else _unit(n, a)) - _unit(n, b)
        more, states = link.placed(m, self.z)
        table = _rigid_table(link) if link.rigid else link.modes()
        if not catch_by_row:  # a wave piston's momentum is in its waves: the stepping catches it
            table = {name: Mode(mode.force, tuple(s for s in mode.exits if s.next_mode != "caught"), mode.rates,
                                mode.entry) for name, mode in table.items()}
        return Element(link.name, link, table, {STRETCH: ends, RATE: rates, **more}, states, None, load)

    def initial_modes(self, w: np.ndarray) -> Modes:
        """Each element's mode at state w (the velocities of massless nodes taken as zero)."""
        z = np.concatenate([w, np.zeros(self.layout.n)])
        z[self.layout.size + np.array(self.layout.velocity_nodes, dtype=int)] = w[self.layout.n:self.layout.rock]
        return tuple(piece.initial_mode(z) for piece in self.pieces)

    # -- one key --------------------------------------------------------------------------------------

    def _groups(self, modes: Modes) -> list[list[int]]:
        """The nodes joined by rigid links and closed rigid contacts."""
        pairs = self._rigid_pairs(modes)
        grounded = [b for a, b in pairs if a is None]
        if grounded:
            raise ValueError(f"a rigid joint to ground at node {self.chain.bodies[grounded[0]].name}")
        owner = joined(self.layout.n, pairs)
        groups: dict[int, list[int]] = {}
        for i in range(self.layout.n):
            groups.setdefault(owner[i], []).append(i)
        return list(groups.values())

    def _rigid_pairs(self, modes: Modes) -> list[tuple[int | None, int]]:
        pairs = [(link.body_a, link.body_b) for link in self.rigid_links]
        pairs += [(self.pieces[i].law.body_a, self.pieces[i].law.body_b) for i in self.rigid if modes[i] == CLOSED]
        return pairs

    def key(self, modes: Modes, phase: str) -> Key:
        """The arrays of (modes, phase) (module doc), built on first use."""
        if (modes, phase) not in self.keys:
            self.keys[(modes, phase)] = self._build(modes, phase)
        return self.keys[(modes, phase)]

    def _node_forces(self, modes: Modes, phase: str) -> tuple[np.ndarray, list[np.ndarray | None]]:
        """Every force on every node as rows over z (n, z), and each element's force row (z)."""
        layout, n, m = self.layout, self.layout.n, self.layout.size
        forces = np.zeros((n, self.z))
        for link in self.springs:
            row = link.stiffness_n_per_m * self._stretch(link) + link.damping_n_s_per_m * self._stretch(link, m)
            forces[link.body_b] -= row
            if link.body_a is not None:
                forces[link.body_a] += row
        element_forces: list[np.ndarray | None] = []
        for index, (piece, mode) in enumerate(zip(self.pieces, modes, strict=True)):
            if (index in self.rigid and mode == CLOSED) or (index == 0 and not self.rock_owned):
                element_forces.append(None)
                continue
            row, constant = piece.row(piece.table[mode].force)
            row = row.copy()
            row[layout.one] += constant
            element_forces.append(row)
            forces += np.outer(piece.load, row)
        for port in self.ports:
            forces[port.node, port.input] += 2.0 * port.impedance_n_s_per_m
            forces[port.node, m + port.node] -= port.impedance_n_s_per_m
        owned = np.array([i not in self.kinematic for i in range(n)])
        forces[owned, layout.one] += self.chain.constant_forces()[owned]
        if self.chain.impact_body not in self.kinematic:
            forces[self.chain.impact_body, layout.one:layout.one + 3] += phase_row(self.impact, phase)
        return forces, element_forces

    def _stretch(self, link: Link, offset: int = 0) -> np.ndarray:
        row = _unit(self.z, offset + link.body_b)
        if link.body_a is not None:
            row -= _unit(self.z, offset + link.body_a)
        return row

    def _build(self, modes: Modes, phase: str) -> Key:
        layout, n, m = self.layout, self.layout.n, self.layout.size
        groups = self._groups(modes)
        velocity_index = layout.velocity
        known = np.zeros((n, m))  # P: node velocities of the groups with a body
        unknown_groups = []
        owner = {}
        for group in groups:
            bodies = [i for i in group if i in velocity_index]
            if len(bodies) > 1:
                names = ", ".join(self.chain.bodies[i].name for i in bodies)
                raise ValueError(f"bodies with mass {names} are joined rigidly (through rigid faces); give the "
                                 "connector or contact between them a stiffness")
            for i in group:
                owner[i] = group
                if bodies:
                    known[i, velocity_index[bodies[0]]] = 1.0
            if not bodies:
                unknown_groups.append(group)
        spread = np.zeros((n, len(unknown_groups)))  # E
        for g, group in enumerate(unknown_groups):
            spread[group, g] = 1.0
        forces_z, element_forces = self._node_forces(modes, phase)
        forces_w = forces_z[:, :m] + forces_z[:, m:] @ known
        forces_u = forces_z[:, m:] @ spread
        if unknown_groups:
            sums_w = np.array([forces_w[group].sum(axis=0) for group in unknown_groups])
            sums_u = np.array([forces_u[group].sum(axis=0) for group in unknown_groups])
            solved = -np.linalg.solve(sums_u, sums_w)  # u = U w
        else:
            solved = np.zeros((0, m))
        velocity = known + spread @ solved
        forces = forces_w + forces_u @ solved
        matrix = np.zeros((m, m))
        matrix[:n] = velocity
        for node, index in velocity_index.items():
            if node not in self.kinematic:
                matrix[index] = forces[owner[node]].sum(axis=0) / self.masses[node]
        for j, node in enumerate(sorted(self.kinematic)):
            matrix[velocity_index[node]] = forces[owner[node]].sum(axis=0) / self.masses[node]
            matrix[velocity_index[node], layout.acceleration + j] += 1.0
        key = Key(matrix, velocity, [], np.zeros(m), [], {}, phase=phase)
        key.body_forces = np.array([forces[owner[node]].sum(axis=0) for node in sorted(self.kinematic)]).reshape(-1, m)
        for index, (piece, mode) in enumerate(zip(self.pieces, modes, strict=True)):
            if index == 0 and not self.rock_owned:
                continue
            for state, affine in piece.table[mode].rates.items():
                row, constant = piece.row(affine)
                matrix[piece.states[state]] += key.over_w(row)
                matrix[piece.states[state], layout.one] += constant
        if self.torsion is not None:
            torsion = torsion_first_order_matrix(self.torsion)
            phi = layout.angle
            matrix[phi:phi + 2, phi:phi + 2], matrix[phi:phi + 2, layout.one] = torsion[:, :2], torsion[:, 2]
        matrix[layout.one:layout.one + 3, layout.one:layout.one + 3] = phase_generator(self.impact, phase)
        for port in range(layout.ports):
            matrix[layout.inputs + 2 * port, layout.inputs + 2 * port + 1] = 1.0
        key.element_forces = [None if row is None else key.over_w(row) for row in element_forces]
        key.rock_force = key.element_forces[0] if self.rock_owned else np.zeros(m)
        key.constraints = self._constraints(modes, groups, forces, velocity_index)
        key.link_forces = {link.name: link.stiffness_n_per_m * key.over_w(self._stretch(link))
                           for link in self.springs}
        key.exits = self._exits(modes, key)
        return key

    def _constraints(self, modes: Modes, groups: list[list[int]], forces: np.ndarray,
                     velocity_index: dict[int, int]) -> dict[str, np.ndarray]:
        """The force row (F > 0 pulls, as a link's) of each rigid link and closed rigid contact: the group
        split at it, the force that balances the side without a body (module doc)."""
        named = [(link.name, link.body_a, link.body_b) for link in self.rigid_links]
        named += [(self.pieces[i].name, self.pieces[i].law.body_a, self.pieces[i].law.body_b) for i in self.rigid
                  if modes[i] == CLOSED]
        out = {}
        for name, a, b in named:
            side = self._side(modes, name, b)
            if any(i in velocity_index for i in side):  # the body is on b's side: balance a's
                side = self._side(modes, name, a)
                out[name] = -forces[side].sum(axis=0)
            else:
                out[name] = forces[side].sum(axis=0)
        return out

    def _side(self, modes: Modes, cut: str, start: int) -> list[int]:
        """The nodes rigidly joined to ``start`` without the rigid joint named ``cut``."""
        pairs = [(link.body_a, link.body_b) for link in self.rigid_links if link.name != cut]
        pairs += [(self.pieces[i].law.body_a, self.pieces[i].law.body_b) for i in self.rigid
                  if modes[i] == CLOSED and self.pieces[i].name != cut]
        side, frontier = {start}, [start]
        while frontier:
            node = frontier.pop()
            for a, b in pairs:
                for here, there in ((a, b), (b, a)):
                    if here == node and there is not None and there not in side:
                        side.add(there)
                        frontier.append(there)
        return sorted(side)

    def _exits(self, modes: Modes, key: Key) -> list:
        """(row over w, direction, next modes, resets (index in w, row), element) of every exit."""
        out = []
        velocity_index = self.layout.velocity
        for index, (piece, mode) in enumerate(zip(self.pieces, modes, strict=True)):
            if index == 0 and not self.rock_owned:
                continue
            switches: list[tuple[np.ndarray, int, str]] = []
            if index in self.rigid and mode == CLOSED:
                switches.append((key.constraints[piece.name], 1, OPEN))
            for switch in piece.table[mode].exits:
                row, constant = piece.row(switch.surface)
                row = key.over_w(row)
                row[self.layout.one] += constant
                switches.append((row, switch.direction, switch.next_mode))
            for row, direction, following in switches:
                resets = []
                for state, affine in piece.table[following].entry.items():
                    target = self._state_index(piece.states[state], velocity_index)
                    if target is None:
                        continue
                    reset, constant = piece.row(affine)
                    reset = key.over_w(reset)
                    reset[self.layout.one] += constant
                    resets.append((target, reset))
                out.append((row, direction, modes[:index] + (following,) + modes[index + 1:], resets, index))
        return out

    def _state_index(self, z_index: int, velocity_index: dict[int, int]) -> int | None:
        """A state named by an element (over z) as an index into w; None for a massless node's velocity."""
        m = self.layout.size
        if z_index < m:
            return z_index
        return velocity_index.get(z_index - m)

