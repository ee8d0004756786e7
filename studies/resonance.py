"""The resonance estimate of a scene: models.modal's rock mode of its drill string on its rock.

The glue between a scene dict and :func:`models.modal.rock_mode_frequency_hz` (the chain's lumped
masses, K and C from models.chain.axial_chain, the rock's loading stiffness and damping as built).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from rpdrill.models.chain import axial_chain
from rpdrill.models.modal import rock_mode_frequency_hz
from rpdrill.models.scene import Scene


def rock_mode_hz(scene_data: dict[str, Any]) -> float:
    """Damped frequency of the rock mode of a scene dict (validated here; ValidationError if invalid)."""
    scene = Scene.model_validate(scene_data)
    chain, law = axial_chain(scene), scene.rock_law()
    return rock_mode_frequency_hz(np.diag(chain.mass_matrix()), chain.stiffness_matrix(), chain.damping_matrix(),
                                  chain.bit_body, law.loading_stiffness_n_per_m, law.damping_n_s_per_m)
