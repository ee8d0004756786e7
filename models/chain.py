"""The axial chain as data: bodies, spring-dampers between them, where loads act.

Both formulations assemble from this one description, so the Exudyn model and the ODE
(Eq. 4: M q'' + C q' + K q = F) cannot disagree on the topology.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from models.scene import Scene

SHANK, COLLAR, BIT, CARRIAGE = 0, 1, 2, 3


@dataclass(frozen=True)
class Body:
    """A rigid body moving along the drilling axis (positive into the rock)."""

    name: str
    mass_kg: float
    constant_force_n: float  # feed force acting on this body


@dataclass(frozen=True)
class Link:
    """Spring-damper between two bodies; ``body_a`` None means ground."""

    name: str
    body_a: int | None
    body_b: int
    stiffness_n_per_m: float
    damping_n_s_per_m: float


@dataclass(frozen=True)
class AxialChain:
    bodies: tuple[Body, ...]
    links: tuple[Link, ...]
    impact_body: int
    bit_body: int

    @property
    def size(self) -> int:
        return len(self.bodies)

    def mass_matrix(self) -> np.ndarray:
        return np.diag([b.mass_kg for b in self.bodies])

    def _assemble(self, attribute: str) -> np.ndarray:
        matrix = np.zeros((self.size, self.size))
        for link in self.links:
            value = getattr(link, attribute)
            matrix[link.body_b, link.body_b] += value
            if link.body_a is not None:
                matrix[link.body_a, link.body_a] += value
                matrix[link.body_a, link.body_b] -= value
                matrix[link.body_b, link.body_a] -= value
        return matrix

    def stiffness_matrix(self) -> np.ndarray:
        return self._assemble("stiffness_n_per_m")

    def damping_matrix(self) -> np.ndarray:
        return self._assemble("damping_n_s_per_m")

    def constant_forces(self) -> np.ndarray:
        return np.array([b.constant_force_n for b in self.bodies])

    def link_stretch(self, positions: np.ndarray) -> np.ndarray:
        """Relative displacement x_b - x_a of every link, for (..., n_bodies) positions."""
        columns = []
        for link in self.links:
            base = 0.0 if link.body_a is None else positions[..., link.body_a]
            columns.append(positions[..., link.body_b] - base)
        return np.stack(columns, axis=-1)


def paper_chain(scene: Scene) -> AxialChain:
    """Shank, collar, bit (indices 0, 1, 2) and, with a feed carriage, the carriage (index 3).

    Joint damping (c1, c2, c3) is zero when the scene's ``joint_damping`` effect is off.
    """
    per_body = scene.feed.arrangement == "per_body"
    body_force = scene.feed.force_n if per_body else 0.0
    bodies = [
        Body("shank", scene.bodies.shank_mass_kg, body_force),
        Body("collar", scene.bodies.collar_mass_kg, body_force),
        Body("bit", scene.bodies.bit_mass_kg, body_force),
    ]
    anchor = None
    if not per_body:
        bodies.append(Body("carriage", scene.feed.carriage_mass_kg, scene.feed.force_n))
        anchor = CARRIAGE
    joint_damping = scene.effects.joint_damping
    links = tuple(
        Link(name, anchor if name == "shock_absorber" else a, b, pair.stiffness_n_per_m,
             pair.damping_n_s_per_m if joint_damping else 0.0)
        for name, a, b in (("shock_absorber", None, SHANK), ("shank_collar_joint", SHANK, COLLAR),
                           ("collar_bit_joint", COLLAR, BIT))
        for pair in (getattr(scene.connectors, name),)
    )
    return AxialChain(tuple(bodies), links, impact_body=SHANK, bit_body=BIT)


def initial_positions_m(scene: Scene) -> np.ndarray:
    """Positions at t = 0: zero from rest, or the static equilibrium under the feed forces with the
    bit on the rock, (K + k_n e_bit e_bit^T) q0 = F_feed, for ``start: preloaded``."""
    chain = paper_chain(scene)
    if scene.start == "rest":
        return np.zeros(chain.size)
    stiffness = chain.stiffness_matrix()
    stiffness[chain.bit_body, chain.bit_body] += scene.rock.stiffness_n_per_m
    positions = np.linalg.solve(stiffness, chain.constant_forces())
    if scene.rock.stiffness_n_per_m * positions[chain.bit_body] >= scene.rock.threshold_n:
        raise ValueError(f"start: 'preloaded': the static feed alone crushes the rock (rock force "
                         f"{scene.rock.stiffness_n_per_m * positions[chain.bit_body]:.4g} N >= rock.threshold_n "
                         f"{scene.rock.threshold_n:.4g} N); lower feed.force_n or use start: rest")
    return positions


def initial_torsion_angle_rad(scene: Scene) -> float:
    """phi at t = 0: zero from rest, (M_x - M_c) / k_x preloaded (zero without a torsion spring)."""
    tor = scene.torsion
    if scene.start == "rest" or tor is None or tor.stiffness_n_m_per_rad == 0:
        return 0.0
    return (tor.drive_torque_n_m - tor.resisting_torque_n_m) / tor.stiffness_n_m_per_rad
