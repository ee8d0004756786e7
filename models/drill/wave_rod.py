"""A uniform rod as an exact 1-D wave element (d'Alembert), written once for every formulation.

A rod of axial stiffness E A and mass per length mu (rho A for a plain rod) carries the wave equation
without dispersion: its displacement is f(t - x / c) + g(t + x / c), c = sqrt(E A / mu), and its
impedance is Z = sqrt(E A mu) = A sqrt(E rho). At either end (a *port*) the particle velocity v is the
sum of the wave arriving there (``incoming``, a velocity) and the wave leaving (``outgoing``):

    v = incoming + outgoing,     outgoing(t) = v(t) - incoming(t),

and a wave arrives at one end as it left the other one transit time T = L / c before:

    incoming_top(t) = outgoing_bottom(t - T),   incoming_bottom(t) = outgoing_top(t - T).

The rod pushes the body (or face) at its end with F = Z (2 incoming - v) along +x (into the rock), at
either end: the end is a dashpot Z to a point moving at twice the incoming wave. Its compression at
the end is P = sigma Z (v - 2 incoming) = sigma Z (outgoing - incoming) (sigma = +1 at the top end,
-1 at the bottom end), the energy entering the rod there is int Z (outgoing^2 - incoming^2) dt, and the
energy it holds is Z int (d^2 + u^2) over the waves in flight (kinetic and strain energy in equal parts
for a single wave). Two rods joined end to end (an impedance step Z1 -> Z2) transmit
2 Z2 / (Z1 + Z2) and reflect (Z2 - Z1) / (Z2 + Z1) of an arriving force wave
(:func:`transmitted_force_share`, :func:`reflected_force_share`): it is this port relation on both sides
of a massless joint, not a separate rule.

A formulation integrates the ends (the bodies or massless faces joined to them) and carries the
waves between them (models.waves: history, stepping): the rod itself has no state.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..definition.drill_string import Body

TOP, BOTTOM = "top", "bottom"  # a rod's two ends: towards the hammer (x = 0), towards the rock (x = L)
SIGMA = {TOP: 1.0, BOTTOM: -1.0}  # compression = sigma Z (outgoing - incoming)


@dataclass(frozen=True)
class WaveRod:
    """A rod of the drill as a wave element between two nodes of the chain (its end faces)."""

    name: str
    top: int  # chain index of the node at its top end (x = 0)
    bottom: int  # chain index of the node at its bottom end (x = L)
    impedance_n_s_per_m: float  # Z = sqrt(E A mu)
    transit_time_s: float  # T = L / c
    area_m2: float
    length_m: float

    @property
    def mass_kg(self) -> float:
        """mu L = Z T."""
        return self.impedance_n_s_per_m * self.transit_time_s

    @property
    def stiffness_n_per_m(self) -> float:
        """E A / L = Z / T: the rod as a static spring (a preload)."""
        return self.impedance_n_s_per_m / self.transit_time_s

    def node(self, end: str) -> int:
        return self.top if end == TOP else self.bottom


def wave_rod(name: str, body: Body, top: int, bottom: int) -> WaveRod:
    """The wave element of a scene rod (a body with ``model: waves``): Z = sqrt(E A mu), T = L sqrt(mu / (E A)),
    mu = its mass per length (rho A, or the pipe's weight per metre)."""
    axial = body.youngs_modulus_pa * body.area_m2
    per_length = body.total_mass_kg / body.length_m
    return WaveRod(name, top, bottom, math.sqrt(axial * per_length), body.length_m * math.sqrt(per_length / axial),
                   body.area_m2, body.length_m)


def port_force_n(impedance_n_s_per_m: float, incoming_m_per_s: float, velocity_m_per_s: float) -> float:
    """F = Z (2 incoming - v): the rod's push on its end, along +x (module doc)."""
    return impedance_n_s_per_m * (2.0 * incoming_m_per_s - velocity_m_per_s)


def compression_n(end: str, impedance_n_s_per_m: float, outgoing: object, incoming: object) -> object:
    """P = sigma Z (outgoing - incoming), the rod's compression at ``end`` (arrays or floats)."""
    return SIGMA[end] * impedance_n_s_per_m * (outgoing - incoming)


def transmitted_force_share(from_impedance: float, to_impedance: float) -> float:
    """2 Z2 / (Z1 + Z2): the share of a force wave that crosses an impedance step Z1 -> Z2."""
    return 2.0 * to_impedance / (from_impedance + to_impedance)


def reflected_force_share(from_impedance: float, to_impedance: float) -> float:
    """(Z2 - Z1) / (Z2 + Z1): the share of a force wave reflected at an impedance step Z1 -> Z2."""
    return (to_impedance - from_impedance) / (from_impedance + to_impedance)
