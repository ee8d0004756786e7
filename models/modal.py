"""The main resonance of a drill on the rock: the rock mode of the linearised in-contact chain.

With the bit in contact, the rock acts as a spring k_n and a damper c_n on the bit, so the
chain moves as M q'' + C_r q' + K_r q = 0 with K_r = K + k_n e_b e_b^T, C_r = C + c_n e_b e_b^T
(e_b the unit vector of the bit). Its modes are the eigenpairs of the first-order system

    A = [[0, I], [-M^-1 K_r, -M^-1 C_r]],   A (phi, lambda phi) = lambda (phi, lambda phi),

lambda = -zeta omega +- i omega_d. The rock mode is the one whose strain energy lies most in the
rock spring, share = k_n |phi_b|^2 / (phi^H K_r phi): the mode in which the drill rides on the
rock, the resonance the paper's frequency optima sit at.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg


def rock_mode_frequency_hz(mass_kg: np.ndarray, stiffness_n_per_m: np.ndarray, damping_n_s_per_m: np.ndarray,
                           bit_index: int, rock_stiffness_n_per_m: float, rock_damping_n_s_per_m: float) -> float:
    """Damped natural frequency omega_d / (2 pi) of the rock mode (module docstring); 0.0 when that
    mode is overdamped.

    ``mass_kg``: the (n,) lumped masses; ``stiffness_n_per_m``, ``damping_n_s_per_m``: the chain's
    (n, n) matrices K and C without the rock; ``bit_index``: the body touching the rock.
    """
    masses = np.asarray(mass_kg, dtype=float)
    size = len(masses)
    stiffness = np.array(stiffness_n_per_m, dtype=float)
    damping = np.array(damping_n_s_per_m, dtype=float)
    if stiffness.shape != (size, size) or damping.shape != (size, size) or not 0 <= bit_index < size:
        raise ValueError(f"need (n,) masses, (n, n) stiffness and damping and 0 <= bit_index < n; got n = "
                         f"{size}, {stiffness.shape}, {damping.shape}, bit_index {bit_index}")
    stiffness[bit_index, bit_index] += rock_stiffness_n_per_m
    damping[bit_index, bit_index] += rock_damping_n_s_per_m
    system = np.block([[np.zeros((size, size)), np.eye(size)],
                       [-stiffness / masses[:, None], -damping / masses[:, None]]])
    eigenvalues, eigenvectors = scipy.linalg.eig(system)
    shapes = eigenvectors[:size]
    strain = np.real(np.einsum("im,ij,jm->m", shapes.conj(), stiffness, shapes))
    share = rock_stiffness_n_per_m * np.abs(shapes[bit_index]) ** 2 / strain
    return float(abs(eigenvalues[int(np.argmax(share))].imag) / (2 * np.pi))
