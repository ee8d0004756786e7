"""The works of a run with wave rods, integrated exactly over every piece of every step.

Each power is a quadratic form of the augmented state, p = w^T Q w (models.waves.system); along the exact
solution over a piece of length s its integral is w0^T G(s) w0 with G(s) = int_0^s expm(A^T u) Q expm(A u) du.
:func:`step_grams` computes G by Van Loan's block exponential over s / 2^j with ||A|| s / 2^j <= 1/2 (the
block's expm(-A^T u) would overflow on a stiff mode: a rigid unloading, a stiff contact), doubled j times,
G(2 s) = G(s) + expm(A s)^T G(s) expm(A s); cached per key for a whole step.

The forms (:func:`power_forms`): the impact power F_d v_impact; what the string's links, rock, torsion line
and rods absorb (F u over each: a link's force and stretch rate, the rock's force and the bit's velocity,
Z (v - 2 a) v into a rod); the rock's power F_r v_bit.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.linalg import expm

from ..drill.piston import CONTACT
from .system import Key

FORMS = 3  # impact, internal, rock


def step_grams(stepper, key: Key, span_s: float) -> np.ndarray:
    """G_q(span) of the three forms of ``key`` (module doc)."""
    whole = abs(span_s - stepper.step_s) <= 1e-12 * stepper.step_s
    if whole and "grams" in key.cache:
        return key.cache["grams"]
    forms = key.cache.get("forms")
    if forms is None:
        forms = key.cache["forms"] = power_forms(stepper, key)
    matrix = key.matrix
    m = matrix.shape[0]
    doublings = max(0, math.ceil(math.log2(max(np.linalg.norm(matrix, 1) * span_s / 0.5, 1.0))))
    small = span_s / 2**doublings
    block = np.zeros(((FORMS + 1) * m, (FORMS + 1) * m))
    block[:m, :m] = -matrix.T
    for q in range(FORMS):
        block[:m, m * (q + 1):m * (q + 2)] = forms[q]
        block[m * (q + 1):m * (q + 2), m * (q + 1):m * (q + 2)] = matrix
    exponential = expm(block * small)
    step = exponential[m:2 * m, m:2 * m]  # expm(A s / 2^j)
    grams = np.array([step.T @ exponential[:m, m * (q + 1):m * (q + 2)] for q in range(FORMS)])
    for _ in range(doublings):
        grams = grams + step.T @ grams @ step
        step = step @ step
    if whole:
        key.cache["grams"] = grams
    return grams


def power_forms(stepper, key: Key) -> np.ndarray:
    """(Q_impact, Q_internal, Q_rock) of ``key`` (module doc)."""
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
    for p in np.intersect1d(stepper.string_ports, stepper.own_ports):  # a body's ports: the Exudyn element's works
        port = stepper.ports[p]
        arriving = np.zeros(m)
        arriving[layout.inputs + 2 * p] = 2.0
        internal += port.impedance_n_s_per_m * pair(velocity[port.node] - arriving, velocity[port.node])
    impact = pair(stepper.impact_row(key), velocity[chain.impact_body])
    return np.array([impact, internal, rock])
