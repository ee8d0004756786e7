"""Which scenes the exact formulation solves: piecewise-linear ones, the paper's Jenkins law on a
string of linear links (no couplings or other nonlinear connector types). Elsewhere the state is
not a matrix exponential between switches; the Exudyn model and the ODE formulation apply."""

from __future__ import annotations

from rpdrill.models.chain import axial_chain
from rpdrill.models.scene import Scene


def exact_unsupported(scene: Scene) -> str | None:
    """Why the exact formulation cannot run ``scene``, or None if it can."""
    law = scene.rock_law()
    if law.name != "jenkins":
        return f"rock law {law.name!r} (the exact formulation solves the jenkins law only)"
    nonlinear = [link.name for link in axial_chain(scene).nonlinear_links()]
    if nonlinear:
        return (f"nonlinear connectors {', '.join(nonlinear)} (the exact formulation needs linear "
                f"spring-dampers)")
    return None
