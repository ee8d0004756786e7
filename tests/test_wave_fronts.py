"""Wave rods at every front (issue 45): the independent characteristics solution of tests/wave_reference.py
against the closed forms, then the model (both formulations, through the public API) against it: contacts
that open or close between grid times, re-strikes within a step, rod pistons, bits, feeds, preloads."""

from __future__ import annotations

import math

import numpy as np
import pytest
import wave_reference as ref

E_PA, RHO = 2.1e11, 7850.0
C = math.sqrt(E_PA / RHO)


def impedance(diameter_m: float) -> float:
    return math.pi * diameter_m**2 / 4 * math.sqrt(E_PA * RHO)


# ---- the reference against the closed forms ----------------------------------------------------------------

def test_the_reference_sends_de_saint_venants_pulse_from_a_rigid_piston():
    """A rigid piston m_p at v_p on a rod: F = Z v_p exp(-Z t / m_p) until the rock's reflection is back."""
    z, transit, mass, speed = impedance(0.038), 1.2 / C, 3.0, 10.0
    piston = ref.RigidPiston(0, z, mass, speed)
    foot = ref.RockFoot(1, z, ref.Bilinear(2e8, 2e9))
    solution = ref.Solution([ref.Rod(z, transit)], [piston, foot], 5 * transit, 2 * transit,
                            [np.zeros(4), np.zeros(6)], z * speed).run()
    t = np.linspace(0.0, 2 * transit - 1e-9, 400)
    closed = z * speed * np.exp(-z * t / mass)
    assert np.max(np.abs(ref.compression(solution, 0, t) - closed)) < 1e-9 * z * speed


@pytest.mark.parametrize("piston_d, rod_d", [(0.055, 0.045), (0.045, 0.038)])
def test_the_reference_gives_the_rod_pistons_staircase(piston_d, rod_d):
    """A rod piston Z_p on a rod Z (Z_p > Z): F_k = F_1 r^k over each 2 L_p / c, F_1 = Z_p Z v_p / (Z_p + Z),
    r = (Z_p - Z) / (Z_p + Z), as long as the rock's reflection is away."""
    zp, z, speed = impedance(piston_d), impedance(rod_d), 8.0
    tp, transit = 0.3 / C, 4.0 / C
    contact = ref.RodPistonContact(1, 2, (zp, z), zp * tp, speed)
    solution = ref.Solution([ref.Rod(zp, tp), ref.Rod(z, transit)],
                            [ref.FreeEnd(0, zp), contact, ref.RockFoot(3, z, ref.Bilinear(2e8, 2e9))],
                            3 * transit, 2 * transit, [np.zeros(0), np.zeros(3), np.zeros(6)], z * speed).run()
    first, ratio = zp * z * speed / (zp + z), (zp - z) / (zp + z)
    for k in range(4):
        t = np.linspace(2 * k * tp + 0.05 * tp, 2 * (k + 1) * tp - 0.05 * tp, 20)
        assert np.allclose(ref.compression(solution, 2, t), first * ratio**k, rtol=1e-9, atol=1e-9 * first)


def rectangular_pulse(z1: float, z2: float, joint: dict, speed: float = 6.0, pulse_s: float = 100e-6):
    """An equal-impedance rod piston's rectangular pulse Z1 v_p / 2 of ``pulse_s`` down rod 1, across a joint
    into rod 2; both rods long enough that nothing comes back before 3 pulse lengths past the joint."""
    tp, transit = pulse_s / 2, 3 * pulse_s
    contact = ref.RodPistonContact(1, 2, (z1, z1), z1 * tp, speed)
    junctions = [ref.FreeEnd(0, z1), contact, ref.Joint(3, 4, (z1, z2), **joint),
                 ref.RockFoot(5, z2, ref.Bilinear(2e8, 2e9))]
    rods = [ref.Rod(z1, tp), ref.Rod(z1, transit), ref.Rod(z2, transit)]
    return ref.Solution(rods, junctions, 10 * transit, 2 * transit - 1e-9,
                        [np.zeros(0), np.zeros(3), np.zeros(3), np.zeros(6)], z1 * speed).run()


def test_the_reference_transmits_two_z2_over_z1_plus_z2_at_an_impedance_step():
    z1, z2, speed = impedance(0.045), impedance(0.055), 6.0
    solution = rectangular_pulse(z1, z2, {}, speed)
    transit = 300e-6
    t = np.linspace(transit + 5e-6, transit + 95e-6, 30)
    assert np.allclose(ref.compression(solution, 4, t), 2 * z2 / (z1 + z2) * z1 * speed / 2, rtol=1e-10)


def test_the_reference_transmits_a_rectangular_pulse_through_a_spring_as_its_closed_form():
    """A spring k between two rods of one impedance: C' = (2 k / Z)(F_0 - C) while the pulse F_0 lasts, then
    C decays at 2 k / Z: C = F_0 (1 - exp(-2 k t / Z)), then C(tau) exp(-2 k (t - tau) / Z)."""
    z, speed, pulse, k = impedance(0.045), 6.0, 100e-6, 2e9
    solution = rectangular_pulse(z, z, {"spring": k}, speed, pulse)
    transit, force, rate = 300e-6, z * speed / 2, 2 * k / z
    s = np.linspace(1e-7, 2 * pulse, 200)
    closed = np.where(s < pulse, force * (1 - np.exp(-rate * s)),
                      force * (1 - np.exp(-rate * pulse)) * np.exp(-rate * (s - pulse)))
    assert np.max(np.abs(ref.compression(solution, 4, transit + s) - closed)) < 1e-9 * force


@pytest.mark.parametrize("alpha", [0.3, 1.256, 4.0])
def test_the_reference_meets_lundbergs_efficiency(alpha):
    """An equal-impedance rod piston's rectangular pulse tau into a rod on a bilinear rock, k_l = alpha Z / tau,
    k_u = 10 k_l: the rock takes 2 (1 - exp(-alpha))^2 / alpha (1 - k_l / k_u) of the blow."""
    z, speed, pulse = impedance(0.045), 6.0, 200e-6
    tp, transit = pulse / 2, 7.5 * pulse
    rock = ref.Bilinear(alpha * z / pulse, 10 * alpha * z / pulse)
    foot = ref.RockFoot(3, z, rock)
    solution = ref.Solution([ref.Rod(z, tp), ref.Rod(z, transit)],
                            [ref.FreeEnd(0, z), ref.RodPistonContact(1, 2, (z, z), z * tp, speed), foot],
                            20 * pulse, 14 * pulse, [np.zeros(0), np.zeros(3), np.zeros(6)], z * speed).run()
    blow = 0.5 * z * tp * speed**2
    eta = 2 * (1 - math.exp(-alpha)) ** 2 / alpha * 0.9
    assert solution.states[2][5] / blow == pytest.approx(eta, abs=1e-9)
