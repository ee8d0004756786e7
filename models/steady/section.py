"""The Poincare section of the blow period, in coordinates relative to the borehole bottom.

A drilling drill does not return to its state: it advances. What repeats is its shape relative to the
bottom. At a blow start (just before any blow-start reset: models.drill.indexing, models.drill.piston) the
physical state is

    y = (x (n string bodies), v (n), rock states (r), [phi, omega], [q_u (m), q_u' (m)])

(the exact formulation's layout without its augmented part, models.solvers.exact_system.Layout; q_u the
ODE2 coordinates an Exudyn scene's extensions add: models.steady.extension_section). Shifting every body
and every rock state that is a length (a name ending in ``_m``: the bottom, the bilinear law's surface),
and each extension coordinate by its drift e_u, by the same a, y -> y + a e, changes nothing in the
equations when no spring holds a body to ground: the drill drifts. The section coordinates are then z = y - y_bottom e with the bottom
entry dropped (d - 1 numbers); a periodic orbit of n blows is a fixed point z = P_n(z) of the n-blow
map, and the bottom's change over it is the advance of n blows.

A scene whose chain has a stiff link to ground is not translation invariant: it has no orbit relative to
the bottom (:func:`drift_problem` says why; the steady-state solver reports it rather than iterate).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property, lru_cache

import numpy as np

from ..solvers.simulation import Simulation

LENGTH_SUFFIX = "_m"  # a rock state measured in metres moves with the drill (the project's unit-in-name rule)


@dataclass(frozen=True)
class Section:
    """The section coordinates of one simulation (module doc)."""

    bodies: int  # n, the drill string's bodies (a piston's are set at every strike: not part of the section)
    rock_states: int
    torsion: bool
    bottom: int  # index of the borehole bottom in y
    shift: np.ndarray  # e (d)
    extension: int = 0  # m, the extensions' coordinates (models.steady.extension_section)

    @property
    def size(self) -> int:
        """d, the entries of y."""
        return len(self.shift)

    @cached_property
    def kept(self) -> np.ndarray:
        """The indices of y that z holds (all but the bottom)."""
        return np.delete(np.arange(self.size), self.bottom)

    def reduce(self, y: np.ndarray) -> tuple[np.ndarray, float]:
        """(z, y_bottom): y relative to its bottom, the bottom entry dropped."""
        bottom = float(y[self.bottom])
        return (y - bottom * self.shift)[self.kept], bottom

    def embed(self, z: np.ndarray, bottom_m: float = 0.0) -> np.ndarray:
        """y with the bottom at ``bottom_m`` from section coordinates z."""
        y = bottom_m * self.shift
        y[self.kept] += z
        return y

    def jacobian(self, monodromy: np.ndarray) -> np.ndarray:
        """dz'/dz of the map z -> reduce(Y(embed(z))) from dY/dy (d x d): D (I - e b^T) dY/dy E, with E
        inserting a zero bottom entry and D dropping it (b the bottom's unit row)."""
        relative = monodromy - np.outer(self.shift, monodromy[self.bottom])
        return relative[np.ix_(self.kept, self.kept)]

    def labels(self, simulation: Simulation) -> list[str]:
        """A name for every entry of z (positions and the rock's lengths relative to the bottom)."""
        labels = self.state_labels(simulation)
        del labels[self.bottom]
        return labels

    def state_labels(self, simulation: Simulation) -> list[str]:
        """A name for every entry of y (an extension's coordinates in their own units: a length or an angle)."""
        names = [body.name for body in simulation.chain.bodies]
        labels = [f"{name}_position_m" for name in names] + [f"{name}_velocity_m_per_s" for name in names]
        labels += list(simulation.rock.state_names)
        labels += ["torsion_angle_rad", "torsion_rate_rad_per_s"] if self.torsion else []
        followed = simulation.extension_coordinates
        names = () if followed is None else followed.labels
        labels += [f"{name}_position" for name in names] + [f"{name}_velocity" for name in names]
        return labels


def section_of(simulation: Simulation) -> Section:
    """The section of ``simulation`` (module doc)."""
    rock, followed = simulation.rock, simulation.extension_coordinates
    return _section(simulation.chain.size, rock.state_names, rock.bottom_index, simulation.torsion is not None,
                    () if followed is None else followed.drift)


@lru_cache(maxsize=64)
def _section(n: int, state_names: tuple[str, ...], bottom_index: int, torsion: bool,
             extension_drift: tuple[float, ...]) -> Section:
    lengths = [name.endswith(LENGTH_SUFFIX) for name in state_names]
    shift = np.concatenate([np.ones(n), np.zeros(n), np.array(lengths, dtype=float), np.zeros(2 * torsion),
                            extension_drift, np.zeros(len(extension_drift))])
    return Section(n, len(state_names), torsion, 2 * n + bottom_index, shift, len(extension_drift))


def physical_state(simulation: Simulation, w: np.ndarray) -> np.ndarray:
    """y from a state over the dynamic chain (x, v of every body with a piston's, rock states, [phi, omega],
    anything after): the string's bodies only."""
    n, dynamic = simulation.chain.size, simulation.dynamic_chain.size
    rest = 2 * dynamic
    tail = len(simulation.rock.state_names) + 2 * (simulation.torsion is not None)
    return np.concatenate([w[:n], w[dynamic:dynamic + n], w[rest:rest + tail]])


def drift_problem(simulation: Simulation) -> str | None:
    """Why the scene has no periodic orbit relative to the bottom, or None: a link that holds a body to
    ground with a spring (its force changes when the whole drill moves), or a nonlinear link to ground."""
    grounded = [link for link in simulation.dynamic_chain.links
                if link.body_a is None and (not link.linear or link.stiffness_n_per_m != 0.0)]
    if not grounded:
        return None
    names = ", ".join(link.name for link in grounded)
    return (f"scene '{simulation.name}': the link(s) {names} hold the drill string to ground, so the drill's "
            "shape relative to the advancing bottom cannot repeat (the ground spring's force grows with the "
            "depth): there is no periodic orbit relative to the bottom; use solver.steady_state: time")
