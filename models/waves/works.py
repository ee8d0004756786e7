"""The works of a run with wave rods, integrated exactly over every piece of every step.

Each power is a quadratic form of the augmented state, p = w^T Q w (models.waves.system); along the exact
solution over a piece of length s its integral is w0^T G(s) w0 with G(s) = int_0^s expm(A^T u) Q expm(A u) du
(models.waves.levels computes G on dyadic fractions of the step).

The forms (:func:`power_forms`): the impact power F_d v_impact; what the string's links, rock, torsion line
and rods absorb (F u over each: a link's force and stretch rate, the rock's force and the bit's velocity,
Z (v - 2 a) v into a rod); the rock's power F_r v_bit; the power into the string's rods and into a wave
piston (their waves' energy at a sample inside a step).
"""

from __future__ import annotations

import numpy as np

from ..drill.piston import CONTACT
from .system import Key


def power_forms(stepper, key: Key) -> np.ndarray:
    """(Q_impact, Q_internal, Q_rock, Q_string_rods, Q_piston_rod, Q_body_ports) of ``key`` (module doc; the last
    three so that a sample inside a step has the waves' energy and the bodies' ports' work)."""
    system, layout, velocity, chain = stepper.system, stepper.layout, key.velocity, stepper.chain
    m = layout.size

    def pair(force: np.ndarray, rate: np.ndarray) -> np.ndarray:
        return 0.5 * (np.outer(force, rate) + np.outer(rate, force))

    def stretch_rate(link) -> np.ndarray:
        return velocity[link.body_b] - (0.0 if link.body_a is None else velocity[link.body_a])
    rock = pair(key.rock_force, velocity[chain.bit_body])
    internal = rock.copy()
    for link in system.springs:
        if link.body_b < stepper.string_size:
            rate = stretch_rate(link)
            internal += pair(key.link_forces[link.name] + link.damping_n_s_per_m * rate, rate)
    for index, piece in enumerate(system.pieces[1:], start=1):
        row = key.element_forces[index]
        if row is not None and piece.name != CONTACT:
            internal += pair(row, stretch_rate(piece.law))
    if layout.torsion:
        torsion, force, rate = stepper.simulation.torsion, np.zeros(m), np.zeros(m)
        force[layout.angle], force[layout.angle + 1] = torsion.stiffness_n_m_per_rad, torsion.damping_n_m_s_per_rad
        rate[layout.angle + 1] = 1.0
        internal += pair(force, rate)
    rods, piston, bodies = np.zeros((m, m)), np.zeros((m, m)), np.zeros((m, m))
    for p, port in enumerate(stepper.ports):
        arriving = np.zeros(m)
        arriving[layout.inputs + 2 * p] = 2.0
        power = port.impedance_n_s_per_m * pair(velocity[port.node] - arriving, velocity[port.node])
        if port.node >= stepper.string_size:
            piston += power
        else:
            rods += power
            if p in stepper.own_ports:  # a body's ports: the Exudyn element's works
                internal += power
            else:
                bodies += power
    impact = np.zeros((m, m)) if stepper.pulse_outside else pair(stepper.impact_row(key), velocity[chain.impact_body])
    if not len(stepper.kinematic):  # no Exudyn bodies: no sixth form (a sixth Gram series per level)
        return np.array([impact, internal, rock, rods, piston])
    return np.array([impact, internal, rock, rods, piston, bodies])
