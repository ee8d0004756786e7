"""Histories of every link of the chain, from the bodies' positions and velocities (any formulation).

A link joins body_a (ground: x = 0) to body_b; its compression is x_a - x_b = -delta and its force,
positive in compression, -F of its own law (:meth:`models.definition.links.Link.force_n`: F > 0 pulls). A link
with a gap (a coupling) also gives the gap's opening. Columns ``<link>_force_n``,
``<link>_compression_m``, ``<link>_gap_opening_m`` (models.definition.outputs: LINK_SERIES, COUPLING_SERIES).
"""

from __future__ import annotations

import numpy as np

from ..drill.chain import AxialChain


def link_series(chain: AxialChain, position_m: np.ndarray, velocity_m_per_s: np.ndarray,
                joint_force_n: dict[str, np.ndarray] | None = None) -> dict[str, np.ndarray]:
    """Every link's force, compression (and gap opening) for (samples, bodies) positions and velocities; a
    rigid link's force (a constraint's: models.waves) from ``joint_force_n`` (F > 0 pulling, as a link's)."""
    out: dict[str, np.ndarray] = {}
    positions, velocities = position_m.T, velocity_m_per_s.T
    for link in chain.links:
        stretch, rate = link.stretch(positions), link.stretch(velocities)
        if link.rigid:
            out[f"{link.name}_force_n"] = 0.0 - (joint_force_n or {})[link.name]
            out[f"{link.name}_compression_m"] = 0.0 - stretch
            continue
        out[f"{link.name}_force_n"] = 0.0 - np.broadcast_to(link.force_n(stretch, rate), stretch.shape)  # no -0
        out[f"{link.name}_compression_m"] = 0.0 - stretch
        if hasattr(link, "gap_opening_m"):
            out[f"{link.name}_gap_opening_m"] = link.gap_opening_m(stretch)
    return out
