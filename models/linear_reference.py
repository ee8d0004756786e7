"""Matrix-exponential solution of the chain while it is linear: the bit always on an elastic rock.

With plasticity off (no crushing) and the bit never leaving the rock, Eq. 4 is linear with
constant coefficients, the rock a spring k_n (and damper c_n if its effect is on) on the bit.
With the augmented state w = (x, v, 1, u1, u2), u1 = sin(pi s / tau), u2 = cos(pi s / tau)
(s: time since the blow's start) the half-sine piston force is I u1 and

    w' = A_phase w,   phase ``on`` (0 <= s < tau) or ``off`` (pulse over, F_d = 0),

so w(t) = expm(A (t - t_0)) w(t_0) between the pulse switches, from the scene's start (rest, or
the static equilibrium under the feed: ``start: preloaded``): the exact solution to round-off,
a reference of known accuracy for measuring convergence orders (tests/test_accuracy.py). The
caller must make sure the bit stays in contact (the result reports the smallest penetration).
"""

from __future__ import annotations

import itertools
import math

import numpy as np
from rpdrill.models.chain import axial_chain, initial_positions_m
from rpdrill.models.pulse import pulse_switch_times
from rpdrill.models.results import SimulationResult
from rpdrill.models.scene import Scene
from scipy.linalg import expm


def _matrix(scene: Scene, pulse_on: bool) -> np.ndarray:
    chain = axial_chain(scene)
    n = chain.size
    stiffness, damping = chain.stiffness_matrix(), chain.damping_matrix()
    law = scene.rock_law()  # elastic: rock_plasticity is off
    stiffness[chain.bit_body, chain.bit_body] += law.loading_stiffness_n_per_m
    damping[chain.bit_body, chain.bit_body] += law.damping_n_s_per_m
    inverse_mass = np.linalg.inv(chain.mass_matrix())
    one, u1, u2 = 2 * n, 2 * n + 1, 2 * n + 2
    a = np.zeros((2 * n + 3, 2 * n + 3))
    a[:n, n:2 * n] = np.eye(n)
    a[n:2 * n, :n] = -inverse_mass @ stiffness
    a[n:2 * n, n:2 * n] = -inverse_mass @ damping
    a[n:2 * n, one] = inverse_mass @ chain.constant_forces()
    if pulse_on:
        omega = math.pi / scene.impact.duration_s
        a[n + chain.impact_body, u1] = scene.impact.amplitude_n / chain.bodies[chain.impact_body].mass_kg
        a[u1, u2], a[u2, u1] = omega, -omega
    return a


def linear_reference(scene: Scene, times_s: np.ndarray) -> SimulationResult:
    """The exact solution of ``scene``'s linear chain from its start (rest or preloaded) at ``times_s``
    (sorted, >= 0).

    Needs a half-sine pulse and an elastic rock (``rock_plasticity`` off); ``info['min_penetration_m']``
    is the smallest x_bit over the samples after t = 0 (must be positive for the bit to stay in contact).
    """
    if scene.impact.shape != "half_sine" or scene.effects.rock_plasticity:
        raise ValueError("linear_reference needs a half_sine pulse and rock_plasticity off")
    chain = axial_chain(scene)
    n = chain.size
    matrices = {True: _matrix(scene, True), False: _matrix(scene, False)}
    times_s = np.asarray(times_s, float)
    end = float(times_s[-1])
    switches = np.unique([0.0, *pulse_switch_times(scene.impact, end), end])
    period, tau = scene.impact.period_s, scene.impact.duration_s
    w = np.zeros(2 * n + 3)
    w[:n] = initial_positions_m(scene)  # zero from rest, the static equilibrium when preloaded
    w[2 * n] = 1.0
    states = np.empty((len(times_s), 2 * n + 3))
    for start, stop in itertools.pairwise(switches):
        local = start - math.floor(start / period + 1e-9) * period
        pulse_on = local < tau * (1 - 1e-9)
        if pulse_on and local < 1e-12:  # a blow starts: the pulse generator restarts
            w[2 * n + 1], w[2 * n + 2] = 0.0, 1.0
        inside = (times_s >= start) & (times_s <= stop) if start == 0.0 else (times_s > start) & (times_s <= stop)
        a = matrices[pulse_on]
        if inside.any():
            states[inside] = (expm((times_s[inside] - start)[:, None, None] * a) @ w)
        w = expm((stop - start) * a) @ w
    bit = chain.bit_body
    return SimulationResult(
        scene=scene, chain=chain, formulation="linear_reference", time_s=times_s,
        position_m=states[:, :n], velocity_m_per_s=states[:, n:2 * n], bottom_m=np.zeros(len(times_s)),
        cpu_time_s=math.nan, info={"min_penetration_m": float(states[times_s > 0, bit].min(initial=math.inf))},
    )
