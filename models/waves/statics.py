"""The static preload of a drill with wave rods: each rod a spring E A / L between its faces, each rigid
joint one point (models.drill.chain.static_preload_m on that reduced chain). The rods' compression at
rest sets their initial waves (initial_outgoing)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ...rocklaw import RockLaw
from ..definition.links import Link
from ..drill.chain import AxialChain, ChainBody, joined, static_preload_m


def wave_preload_m(chain: AxialChain, law: RockLaw) -> np.ndarray:
    """The node positions of the static equilibrium under the feed (module doc; ValueError as
    static_preload_m)."""
    owner = joined(chain.size, chain.rigid_pairs())
    points = sorted(set(owner))
    index = {node: points.index(owner[node]) for node in range(chain.size)}
    forces = np.zeros(len(points))
    for node, body in enumerate(chain.bodies):
        forces[index[node]] += body.constant_force_n
    bodies = tuple(ChainBody(f"point{p}", 1.0, float(forces[p])) for p in range(len(points)))
    links: list[Link] = []
    for link in chain.links:
        if link.linear and link.rigid:
            continue
        a = None if link.body_a is None else index[link.body_a]
        links.append(replace(link, body_a=a, body_b=index[link.body_b]))
    links += [Link(rod.name, index[rod.top], index[rod.bottom], rod.stiffness_n_per_m, 0.0) for rod in chain.waves]
    reduced = AxialChain(bodies, tuple(links), impact_body=index[chain.impact_body], bit_body=index[chain.bit_body],
                         groups={})
    positions = static_preload_m(reduced, law)
    return np.array([positions[index[node]] for node in range(chain.size)])


def initial_outgoing(simulation, chain) -> np.ndarray:
    """Every port's outgoing wave before the start: at rest, P / (2 Z) at the top and -P / (2 Z) at the
    bottom of a rod compressed by P (a preload: P = (E A / L) (x_top - x_bottom))."""
    positions = simulation.initial_positions_m
    out = np.zeros(2 * len(chain.waves))
    for r, rod in enumerate(chain.waves):
        if rod.top < len(positions):
            compression = rod.stiffness_n_per_m * (positions[rod.top] - positions[rod.bottom])
            out[2 * r], out[2 * r + 1] = compression / (2 * rod.impedance_n_s_per_m), \
                -compression / (2 * rod.impedance_n_s_per_m)
    return out
