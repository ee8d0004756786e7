"""The paper's rock law (Eq. 1 and 2): a spring k_n in series with a dry-friction slider.

The borehole bottom x_n is the slider position. With penetration d = x_bit - x_n:

* d <= 0: the bit is off the bottom, no force (the rock never pulls);
* 0 < k_n d < F_th: elastic contact, F = k_n d (+ rock damping, see below);
* k_n d >= F_th: crushing, F = F_th and the bottom advances with the bit (x_n' = x_bit').

Rock damping c_n (the paper's Eq. 4 writes c_n x_bit' in the bit equation) is offered two ways:

* ``contact`` (default): c_n acts only while the bit touches the rock and the total force is
  clipped at zero, F = max(F_spring + c_n v, 0). A rock that is not touched cannot damp the bit,
  and a damper cannot pull the bit into the rock; this is the physically consistent reading.
* ``always``: Eq. 4 taken literally, F = F_spring + c_n v at all times, also off the bottom
  and also pulling (for the cross-check against the paper's equations as printed).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Literal

from rocklaw.backends import NUMERIC, Backend

DampingMode = Literal["contact", "always"]


@dataclass(frozen=True)
class JenkinsRock:
    """Parameters of the paper's visco-elastic-plastic rock (Eq. 1, 2)."""

    stiffness_n_per_m: float
    damping_n_s_per_m: float
    threshold_n: float
    damping_mode: DampingMode = "contact"

    name = "jenkins"

    def __post_init__(self) -> None:
        if self.stiffness_n_per_m <= 0 or self.threshold_n <= 0 or self.damping_n_s_per_m < 0:
            raise ValueError(f"invalid rock parameters {self}")

    @property
    def crushing_penetration_m(self) -> float:
        """Penetration F_th / k_n at which the rock starts to crush."""
        return self.threshold_n / self.stiffness_n_per_m

    @property
    def crushes(self) -> bool:
        """False for an elastic rock (F_th infinite): no slider, no return mapping."""
        return math.isfinite(self.threshold_n)

    def spring_force(self, penetration_m: Any, backend: Backend = NUMERIC) -> Any:
        """Eq. 1: clip(k_n d, 0, F_th), the force carried by the spring-slider pair."""
        elastic = self.stiffness_n_per_m * penetration_m
        capped = backend.minimum(elastic, self.threshold_n) if self.crushes else elastic
        return backend.where(elastic > 0, capped, 0.0)

    def force(self, penetration_m: Any, bit_velocity_m_per_s: Any, backend: Backend = NUMERIC) -> Any:
        """Total rock force on the bit [N], positive pushing the bit back out of the hole.

        Terms of zero parameters (no damping, no crushing) are left out of the expression.
        """
        elastic = self.stiffness_n_per_m * penetration_m
        spring = backend.minimum(elastic, self.threshold_n) if self.crushes else elastic
        if self.damping_n_s_per_m == 0.0:
            return backend.where(elastic > 0, spring, 0.0)
        damping = self.damping_n_s_per_m * bit_velocity_m_per_s
        if self.damping_mode == "always":
            return backend.where(elastic > 0, spring, 0.0) + damping
        return backend.where(elastic > 0, backend.maximum(spring + damping, 0.0), 0.0)

    def return_map(self, bit_position_m: float, bottom_m: float) -> float:
        """Eq. 2 integrated over a step: x_n <- max(x_n, x_bit - F_th / k_n)."""
        return max(bottom_m, bit_position_m - self.crushing_penetration_m)


def force_and_bottom(
    rock: JenkinsRock, bit_position_m: float, bit_velocity_m_per_s: float, bottom_m: float
) -> tuple[float, float]:
    """Pure law: (rock force [N], updated borehole bottom [m]) for a bit state and bottom x_n."""
    new_bottom = rock.return_map(bit_position_m, bottom_m)
    return rock.force(bit_position_m - new_bottom, bit_velocity_m_per_s), new_bottom
