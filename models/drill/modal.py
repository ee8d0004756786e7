"""The main resonance of a drill on the rock: the rock mode of the linearised in-contact chain.

With the bit in contact, the rock acts as a spring k_n and a damper c_n on the bit, so the
chain moves as M q'' + C_r q' + K_r q = 0 with K_r = K + k_n e_b e_b^T, C_r = C + c_n e_b e_b^T
(e_b the unit vector of the bit; every link at its full stiffness). Its modes are the eigenpairs
of the chain's first-order matrix (models.drill.chain.AxialChain.first_order_matrix)

    A = [[0, I], [-M^-1 K_r, -M^-1 C_r]],   A (phi, lambda phi) = lambda (phi, lambda phi),

lambda = -zeta omega +- i omega_d. The rock mode is the one whose strain energy lies most in the
rock spring, share = k_n |phi_b|^2 / (phi^H K_r phi): the mode in which the drill rides on the
rock, the resonance the paper's frequency optima sit at.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from ...rocklaw import RockLaw
from .chain import AxialChain


def rock_mode_frequency_hz(chain: AxialChain, rock: RockLaw) -> float:
    """Damped natural frequency omega_d / (2 pi) of the rock mode (module docstring) with the rock's
    loading stiffness and damping; 0.0 when that mode is overdamped, or when the chain has rods carried as
    waves (their faces are massless: a rod's modes are not those of a mass matrix, and none is computed)."""
    if chain.waves:
        return 0.0
    rock_stiffness = rock.loading_stiffness_n_per_m
    size, bit = chain.size, chain.bit_body
    system = chain.first_order_matrix(chain.links, rock_stiffness, rock.damping_n_s_per_m)[:, :-1]
    eigenvalues, eigenvectors = scipy.linalg.eig(system)
    shapes = eigenvectors[:size]
    stiffness = chain.with_rock(chain.stiffness_matrix(), rock_stiffness)
    strain = np.real(np.einsum("im,ij,jm->m", shapes.conj(), stiffness, shapes))
    share = rock_stiffness * np.abs(shapes[bit]) ** 2 / strain
    return float(abs(eigenvalues[int(np.argmax(share))].imag) / (2 * np.pi))
