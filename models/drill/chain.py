"""The axial chain as data: bodies, spring-dampers between them, where loads act.

Every formulation assembles from this one description (built from a scene's ``drill_string`` by
:func:`axial_chain`), so the Exudyn model, the ODE (Eq. 4: M q'' + C q' + K q = F) and the exact
solver cannot disagree on the topology. The chain owns the first-order form of its linear part,
:meth:`AxialChain.first_order_matrix`, which the ODE, the exact solver and the stability limits use. A rod of ``segments`` N becomes N lumped masses
``name[0]`` .. ``name[N-1]`` joined by springs E A N / L; connectors attach to a rod's first
segment (``to``) and last segment (``from``). A rod with ``model: waves`` becomes its two end faces,
massless nodes ``name[top]`` and ``name[bottom]``, and a wave element between them
(``AxialChain.waves``, models.drill.wave_rod); a connector without a stiffness that joins only rigid faces
(a wave rod's, a rigid body's) is rigid (stiffness infinite: :attr:`Link.rigid`).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from ...rocklaw import RockLaw
from ...rocklaw.modes import ONE
from ..definition.drill_string import EVERY_BODY, GROUND, Body, Connector
from ..definition.links import CLOSED as CLOSED_MODE
from ..definition.links import LINK_TYPES, RATE, STRETCH, Link
from ..definition.scene import Scene, Torsion
from .wave_rod import WaveRod, wave_rod


@dataclass(frozen=True)
class ChainBody:
    """A rigid body (or rod segment) moving along the drilling axis (positive into the rock)."""

    name: str
    mass_kg: float
    constant_force_n: float  # feed force acting on this body


@dataclass(frozen=True)
class AxialChain:
    bodies: tuple[ChainBody, ...]
    links: tuple[Link, ...]
    impact_body: int
    bit_body: int
    groups: dict[str, tuple[int, int]]  # drill-string body name -> (first, last) chain index
    waves: tuple[WaveRod, ...] = ()  # the rods carried as waves, between their face nodes (massless)

    @property
    def size(self) -> int:
        return len(self.bodies)

    @property
    def massless(self) -> tuple[int, ...]:
        """The nodes without mass: the faces of the wave rods."""
        return tuple(i for i, body in enumerate(self.bodies) if body.mass_kg == 0.0)

    @property
    def is_linear(self) -> bool:
        """True when every link is a linear spring-damper (no couplings): K and C describe them all."""
        return all(link.linear for link in self.links)

    def index(self, name: str) -> int:
        """Chain index of a drill-string body (the last segment of a segmented rod) or of a rod segment
        (``rod[0]``)."""
        if name in self.groups:
            return self.groups[name][1]
        for i, body in enumerate(self.bodies):
            if body.name == name:
                return i
        raise KeyError(f"no body {name!r} in the drill string; bodies: {', '.join(b.name for b in self.bodies)}")

    def rigid_pairs(self) -> list[tuple[int, int]]:
        """The (a, b) nodes of every rigid link (rigid faces joined without a stiffness)."""
        return [(link.body_a, link.body_b) for link in self.links
                if link.linear and link.rigid and link.body_a is not None]

    def _assemble(self, attribute: str, links: tuple[Link, ...]) -> np.ndarray:
        """D^T diag(values) D: the links' stiffness or damping matrix, from their incidence D."""
        incidence = self.incidence(links)
        values = np.array([getattr(link, attribute) for link in links])
        return incidence.T @ (values[:, None] * incidence)

    def with_rock(self, matrix: np.ndarray, rock_value: float) -> np.ndarray:
        """``matrix`` + rock_value e_b e_b^T: a stiffness (or damping) with the rock's in contact on the bit."""
        matrix = matrix.copy()
        matrix[self.bit_body, self.bit_body] += rock_value
        return matrix

    def linear_links(self) -> tuple[Link, ...]:
        return tuple(link for link in self.links if link.linear)

    def nonlinear_links(self) -> tuple[Link, ...]:
        return tuple(link for link in self.links if not link.linear)

    def stiffness_matrix(self, linear_only: bool = False) -> np.ndarray:
        """K of every link at its full stiffness (couplings closed: the stiffest state), or of the
        linear links only."""
        return self._assemble("stiffness_n_per_m", self.linear_links() if linear_only else self.links)

    def constant_forces(self) -> np.ndarray:
        return np.array([b.constant_force_n for b in self.bodies])

    def first_order_matrix(self, links: tuple[Link, ...] | None = None, bit_stiffness_n_per_m: float = 0.0,
                           bit_damping_n_s_per_m: float = 0.0) -> np.ndarray:
        """A of z' = A (x, v, 1) for the linear part of Eq. 4 (2n x (2n + 1)):

            x' = v,   v' = M^-1 (-K x - C v + F_feed),

        K and C of ``links`` (default: the linear links; the others are added by each formulation
        from their own laws) plus a spring and damper from the bit to ground (the rock in contact)."""
        links = self.linear_links() if links is None else links
        n = self.size
        stiffness = self.with_rock(self._assemble("stiffness_n_per_m", links), bit_stiffness_n_per_m)
        damping = self.with_rock(self._assemble("damping_n_s_per_m", links), bit_damping_n_s_per_m)
        inverse_mass = 1.0 / np.array([b.mass_kg for b in self.bodies])
        matrix = np.zeros((2 * n, 2 * n + 1))
        matrix[:n, n:2 * n] = np.eye(n)
        matrix[n:, :n] = -inverse_mass[:, None] * stiffness
        matrix[n:, n:2 * n] = -inverse_mass[:, None] * damping
        matrix[n:, 2 * n] = inverse_mass * self.constant_forces()
        return matrix

    def incidence(self, links: tuple[Link, ...] | None = None) -> np.ndarray:
        """D (n_links x n_bodies) with delta = D x: +1 at each link's body_b, -1 at its body_a (none: ground)."""
        links = self.links if links is None else links
        matrix = np.zeros((len(links), self.size))
        for row, link in enumerate(links):
            matrix[row, link.body_b] = 1.0
            if link.body_a is not None:
                matrix[row, link.body_a] = -1.0
        return matrix

    def link_stretch(self, positions: np.ndarray, links: tuple[Link, ...] | None = None) -> np.ndarray:
        """delta = x_b - x_a of every link (or of ``links``), for (..., n_bodies) positions."""
        return positions @ self.incidence(links).T

    def link_energy(self, positions: np.ndarray, velocities: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(elastic energy sum F_spring^2 / (2 k) [J], damper power sum (F - F_spring) delta' [W]) of the
        links, for (samples, n_bodies) positions and velocities (link by link on contiguous rows)."""
        incidence = self.incidence()
        stretch, rate = incidence @ positions.T, incidence @ velocities.T
        elastic, damping = np.zeros(len(positions)), np.zeros(len(positions))
        for link, delta, delta_rate in zip(self.links, stretch, rate, strict=True):
            if link.rigid:  # a constraint stores and dissipates nothing
                continue
            spring = link.spring_force_n(delta)
            elastic += spring**2 * (0.5 / link.stiffness_n_per_m)
            damping += (link.force_n(delta, delta_rate) - spring) * delta_rate
        return elastic, damping


def joined(size: int, pairs: list[tuple[int, int]], keep: frozenset[int] = frozenset()) -> list[int]:
    """The representative node of each of ``size`` nodes joined through ``pairs`` (a node of ``keep``
    represents its group when one is in it)."""
    parent = list(range(size))

    def find(i: int) -> int:
        while parent[i] != i:
            i = parent[i]
        return i
    for a, b in pairs:
        a, b = find(a), find(b)
        if a != b:
            parent[b if b not in keep else a] = a if b not in keep else b
    return [find(i) for i in range(size)]


def _derived_stiffness_n_per_m(ends: list[Body]) -> float:
    """Series stiffness of the half-segments a connector joins: 1 / sum L_i / (2 E_i A_i N_i)."""
    return 1.0 / sum(body.half_segment_compliance_m_per_n() for body in ends)


def axial_chain(scene: Scene, joint_damping: bool = True) -> AxialChain:
    """The chain of the scene's drill string, rods split into their segments.

    Feed: ``force_n`` on the body ``feed.acts_on`` or on every body (a rod's share split evenly
    over its segments). Without ``joint_damping`` (the effect off) every connector's damping is zero.
    """
    string, feed = scene.drill_string, scene.feed
    bodies: list[ChainBody] = []
    links: list[Link] = []
    groups: dict[str, tuple[int, int]] = {}
    waves: list[WaveRod] = []
    for name, body in string.bodies.items():
        n, first = body.segments, len(bodies)
        force = feed.force_n if feed.acts_on in (EVERY_BODY, name) else 0.0
        if body.is_wave:  # two massless faces; the feed on the top face (module doc of models.waves)
            bodies += [ChainBody(f"{name}[top]", 0.0, force), ChainBody(f"{name}[bottom]", 0.0, 0.0)]
            groups[name] = (first, first + 1)
            waves.append(wave_rod(name, body, first, first + 1))
            continue
        bodies += [ChainBody(name if n == 1 else f"{name}[{i}]", body.total_mass_kg / n, force / n) for i in range(n)]
        groups[name] = (first, first + n - 1)
        links += [Link(f"{name}[{i}-{i + 1}]", first + i, first + i + 1,
                       _derived_stiffness_n_per_m([body, body]), 0.0) for i in range(n - 1)]
    for name, connector in string.connectors.items():
        links.append(_connector_link(scene, name, connector, groups, joint_damping))
    return AxialChain(tuple(bodies), tuple(links), impact_body=groups[string.impact_body][0],
                      bit_body=groups[string.foot][1], groups=groups, waves=tuple(waves))


def _connector_link(scene: Scene, name: str, connector: Connector, groups: dict[str, tuple[int, int]],
                    damped: bool) -> Link:
    bodies = scene.drill_string.bodies
    ends = [bodies[b] for b in (connector.from_body, connector.to_body) if b != GROUND]
    compliance = sum(body.half_segment_compliance_m_per_n() for body in ends)
    rigid = math.inf if compliance == 0 else None  # rigid faces joined without a stiffness (module doc)
    stiffness = connector.stiffness_n_per_m or sleeve_stiffness_n_per_m(connector, ends) or rigid or \
        _derived_stiffness_n_per_m(ends)
    body_a = None if connector.from_body == GROUND else groups[connector.from_body][1]
    extra = {key: getattr(connector, key) for key in LINK_TYPES[connector.type].parameters()
             if getattr(connector, key) is not None}
    return LINK_TYPES[connector.type](name, body_a, groups[connector.to_body][0], stiffness,
                                      connector.damping_n_s_per_m if damped else 0.0, **extra)


def sleeve_stiffness_n_per_m(connector: Connector, ends: list[Body]) -> float | None:
    """A coupling's sleeve as a spring: E pi (D_s^2 - D^2) / (4 L_s), D the larger of the joined bodies' diameters
    (its bore: the threads), E the first's modulus; None without a sleeve."""
    if connector.sleeve_length_m is None:
        return None
    bore = max(body.diameter_m or 0.0 for body in ends)
    if connector.sleeve_outer_diameter_m <= bore:
        raise ValueError(f"sleeve_outer_diameter_m {connector.sleeve_outer_diameter_m} must exceed the rods' diameter "
                         f"{bore}")
    area = math.pi * (connector.sleeve_outer_diameter_m**2 - bore**2) / 4
    return ends[0].youngs_modulus_pa * area / connector.sleeve_length_m


def link_load_n(chain: AxialChain, positions: np.ndarray, velocities: np.ndarray,
                links: tuple[Link, ...] | None = None) -> np.ndarray:
    """Force of the links (default: all) on every body, sum of F (e_a - e_b), for (n_bodies,) states."""
    load = np.zeros(chain.size)
    for link in chain.links if links is None else links:
        force = link.force_n(link.stretch(positions), link.stretch(velocities))
        load[link.body_b] -= force
        if link.body_a is not None:
            load[link.body_a] += force
    return load


def torsion_first_order_matrix(torsion: Torsion) -> np.ndarray:
    """The torsion line of Eq. 4, J phi'' + c_x phi' + k_x phi = M_x - M_c, as
    (phi, omega)' = T (phi, omega, 1) (2 x 3)."""
    inertia = torsion.inertia_kg_m2
    return np.array([[0.0, 1.0, 0.0],
                     [-torsion.stiffness_n_m_per_rad / inertia, -torsion.damping_n_m_s_per_rad / inertia,
                      (torsion.drive_torque_n_m - torsion.resisting_torque_n_m) / inertia]])


Modes = tuple[str, ...]  # a mode of each nonlinear link, in chain order
# The static system K q = F is solved when cond(K) is below this (double precision: 16 digits, 2 kept);
# beyond it a body has no rest position, or the stiffnesses are too far apart to solve for one.
STATIC_CONDITION_LIMIT = 1e14


def _static_system(chain: AxialChain, law: RockLaw, modes: Modes, contact: bool) -> tuple[np.ndarray, np.ndarray]:
    """K and F of the static equilibrium K q = F with each nonlinear link in its mode of ``modes`` (its
    force at rest a delta + b, linear in that mode: rocklaw.modes) and the bit on the rock (``contact``:
    k_load) or off it."""
    stiffness = chain.stiffness_matrix(linear_only=True)
    forces = chain.constant_forces().astype(float)
    for link, mode in zip(chain.nonlinear_links(), modes, strict=True):
        force = link.modes()[mode].force
        a, b = force.get(STRETCH, 0.0), force.get(ONE, 0.0)
        direction = chain.incidence((link,))[0]  # delta = direction . q
        stiffness += a * np.outer(direction, direction)
        forces -= b * direction
    if contact:
        stiffness = chain.with_rock(stiffness, law.loading_stiffness_n_per_m)
    return stiffness, forces


def _consistent(chain: AxialChain, positions: np.ndarray, modes: Modes, contact: bool) -> tuple[Modes, bool]:
    """The modes and contact that the state ``positions`` at rest implies."""
    implied = tuple(link.initial_mode({STRETCH: float(link.stretch(positions)), RATE: 0.0})
                    for link in chain.nonlinear_links())
    return implied, bool(positions[chain.bit_body] > 0.0)


def _solve_static(chain: AxialChain, law: RockLaw, modes: Modes, contact: bool) -> np.ndarray | None:
    stiffness, forces = _static_system(chain, law, modes, contact)
    if np.linalg.cond(stiffness) > STATIC_CONDITION_LIMIT:  # a body with no rest position (held by an open coupling only)
        return None
    return np.linalg.solve(stiffness, forces)


def static_preload_m(chain: AxialChain, law: RockLaw) -> np.ndarray:
    """The static equilibrium under the feed with the bit pressed on the rock (loading stiffness
    k_load): F_feed + F_links(q0) - k_load max(q0_bit, 0) = 0. Every link is linear within its mode
    (a coupling open or closed), so the equilibrium is exact: the modes are iterated from those of the
    linear guess (every coupling closed) until the solution implies the modes it was solved with,
    then every combination is tried. ValueError naming the couplings when there is none, or when the
    feed alone would crush the rock."""
    nonlinear = chain.nonlinear_links()
    contact, modes = True, tuple(CLOSED_MODE if CLOSED_MODE in link.modes() else link.initial_mode(
        {STRETCH: 0.0, RATE: 0.0}) for link in nonlinear)
    positions = None
    tried: set[tuple[Modes, bool]] = set()
    while (modes, contact) not in tried:  # iterate: converges in a step or two on a drill string
        tried.add((modes, contact))
        positions = _solve_static(chain, law, modes, contact)
        if positions is None:
            break
        implied = _consistent(chain, positions, modes, contact)
        if implied == (modes, contact):
            break
        modes, contact = implied
    else:
        positions = None
    if positions is None or _consistent(chain, positions, modes, contact) != (modes, contact):
        positions = next((q for candidate in itertools.product(*(tuple(link.modes()) for link in nonlinear))
                          for touching in (True, False)
                          if (q := _solve_static(chain, law, candidate, touching)) is not None
                          and _consistent(chain, q, candidate, touching) == (candidate, touching)), None)
    if positions is None:
        names = ", ".join(link.name for link in nonlinear) or "none"
        raise ValueError(f"no static equilibrium under the feed: no state of the couplings ({names}; each open or "
                         "closed) is at rest (a body held only by an open coupling has no rest position); "
                         "use start: rest")
    rock_force = law.loading_stiffness_n_per_m * max(float(positions[chain.bit_body]), 0.0)
    if rock_force >= law.threshold_n:
        raise ValueError(f"the static feed alone crushes the rock (rock force {rock_force:.4g} N >= rock "
                         f"threshold {law.threshold_n:.4g} N); lower feed.force_n or use start: rest")
    return positions


def static_torsion_angle_rad(torsion: Torsion) -> float:
    """phi of the static equilibrium, (M_x - M_c) / k_x (zero without a torsion spring)."""
    if torsion.stiffness_n_m_per_rad == 0:
        return 0.0
    return (torsion.drive_torque_n_m - torsion.resisting_torque_n_m) / torsion.stiffness_n_m_per_rad
