"""Named rocks of the paper's Table 1 (threshold F_th, stiffness k, damping c)."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class RockProperties:
    """One row of the paper's Table 1, SI units.

    Parameters
    ----------
    description : str
        The rock in words.
    threshold_n : float
        F_th, the crushing threshold.
    stiffness_n_per_m : float
        k_n, the rock's stiffness.
    damping_n_s_per_m : float
        c_n, the rock's damping.

    Examples
    --------
    >>> from rpdrill.rocklaw import TABLE_1
    >>> TABLE_1["sandstone"].threshold_n, TABLE_1["sandstone"].stiffness_n_per_m
    (210000.0, 510000000.0)
    """

    description: str
    threshold_n: float
    stiffness_n_per_m: float
    damping_n_s_per_m: float


#: The paper's Table 1 by the names a scene's ``rock.name`` takes: ``conglomerate``, ``sandstone``,
#: ``soft_limestone`` (:class:`RockProperties`). ``TABLE_1["sandstone"].threshold_n`` is 210e3 N.
TABLE_1: dict[str, RockProperties] = {
    "conglomerate": RockProperties("Conglomerate rock, very hard", 286e3, 8.4e8, 2.3e4),
    "sandstone": RockProperties("Sandstone rock, hard", 210e3, 5.1e8, 4.9e3),
    "soft_limestone": RockProperties("Soft limestone, medium", 138e3, 2.1e8, 1.98e3),
}
