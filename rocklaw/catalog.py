"""Named rocks of the paper's Table 1 (threshold F_th, stiffness k, damping c)."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class RockProperties:
    """One row of Table 1, SI units."""

    description: str
    threshold_n: float
    stiffness_n_per_m: float
    damping_n_s_per_m: float


TABLE_1: dict[str, RockProperties] = {
    "conglomerate": RockProperties("Conglomerate rock, very hard", 286e3, 8.4e8, 2.3e4),
    "sandstone": RockProperties("Sandstone rock, hard", 210e3, 5.1e8, 4.9e3),
    "soft_limestone": RockProperties("Soft limestone, medium", 138e3, 2.1e8, 1.98e3),
}
