"""The outputs a scene can ask for, and what each needs built.

Each metric and time history names the effects it depends on (``torsion``, ``rock_plasticity``),
the bodies of the drill string it reads (``collar``; any body's ``<body>_velocity_peak_m_per_s``) and the data it needs recorded: ``forces`` (rock and impact force sensors) or ``energy``
(the works integrated: Exudyn stores every solver step, the exact formulation integrates them from
its propagators). Asking for an output pulls in
what it needs; asking for nothing more builds nothing more.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Need:
    effects: frozenset[str] = frozenset()
    data: frozenset[str] = frozenset()
    bodies: frozenset[str] = frozenset()


def _need(effects: tuple[str, ...] = (), data: tuple[str, ...] = (), bodies: tuple[str, ...] = ()) -> Need:
    return Need(frozenset(effects), frozenset(data), frozenset(bodies))


PENETRATION = _need(("rock_plasticity",))
PLAIN = _need()
COLLAR = _need(bodies=("collar",))
FORCES = _need(data=("forces",))
ENERGY = _need(data=("forces", "energy"))
# a piston scene's piston histories (models.drill.piston); an output that needs them needs impact.piston
PISTON = _need(data=("forces", "piston"))
# the rods' figures per blow (models.evaluation.rod_outputs): every step stored, forces; a default output only of a
# scene with rods (a drill without rods, the paper's, keeps its outputs)
RODS = _need(data=("forces", "energy", "rods"))

METRICS: dict[str, Need] = {
    "penetration_rate_m_per_s": PENETRATION,
    "penetration_rate_block_std_m_per_s": PENETRATION,
    "penetration_rate_block_min_m_per_s": PENETRATION,
    "penetration_rate_block_max_m_per_s": PENETRATION,
    # advance over the window / impact work over the window (m per joule of impact energy)
    "penetration_per_impact_energy_m_per_j": _need(("rock_plasticity",), ("forces", "energy")),
    "advance_per_blow_m": PENETRATION,
    "advance_per_blow_std_m": PENETRATION,
    "borehole_bottom_final_m": PENETRATION,
    "bit_velocity_peak_m_per_s": PLAIN,
    "bit_velocity_rms_m_per_s": PLAIN,
    "collar_velocity_peak_m_per_s": COLLAR,
    "collar_velocity_rms_m_per_s": COLLAR,
    "rock_force_max_n": FORCES,
    "impact_energy_j": ENERGY,
    "feed_energy_j": ENERGY,
    "crushing_work_j": _need(("rock_plasticity",), ("forces", "energy")),
    "energy_transfer_efficiency": _need(("rock_plasticity",), ("forces", "energy")),
    "energy_balance_relative_error": ENERGY,
    "piston_rebound_energy_j": PISTON,
    # rods (models.evaluation.rod_outputs): the largest stress at any rod's end in the window's blows (compression
    # or tension), the rock's energy per blow int F_r v_bit dt and its share of the energy the blows put in
    "rod_stress_max_pa": RODS,
    "rock_energy_per_blow_j": RODS,
    "rock_transfer_efficiency": RODS,
    # advance over the window / the blow energy of its blows (= penetration rate / hammer power E_blow f)
    "penetration_per_blow_energy_m_per_j": _need(("rock_plasticity",), ("piston",)),
    "window_start_s": PLAIN,
    "window_end_s": PLAIN,
    "window_blows": PLAIN,
    "cpu_time_s": PLAIN,
}

# Histories besides time and each body's position and velocity (always recorded).
SERIES: dict[str, Need] = {
    "borehole_bottom_m": PENETRATION,
    "rock_force_n": FORCES,
    "impact_force_n": FORCES,
    "torsion_angle_rad": _need(("torsion",)),
    "torsion_rate_rad_per_s": _need(("torsion",)),
    "piston_contact_force_n": PISTON,
    "piston_velocity_m_per_s": PISTON,
}


# Outputs of one part, named "<part><suffix>". Metrics of any body of the drill string by name (a rod's
# name: its last segment; a segment by its own name, ``rod[0]``): ``collar_velocity_peak_m_per_s`` above is one.
BODY_METRICS: dict[str, Need] = {"_velocity_peak_m_per_s": PLAIN, "_velocity_rms_m_per_s": PLAIN,
                                  # a rod's (models.evaluation.rod_outputs): the largest stress at its ends in the
                                  # window's blows, and the energy per blow through its top and bottom along +x
                                  "_compressive_stress_max_pa": RODS, "_tensile_stress_max_pa": RODS,
                                  "_energy_in_per_blow_j": RODS, "_energy_out_per_blow_j": RODS}
# Histories of every rod's ends (stress, compression positive), besides the links' (always there).
ROD_SERIES = ("_top_stress_pa", "_bottom_stress_pa")
# Histories every link of the chain (the scene's connectors, a rod's inner links ``rod[0-1]``) always has, from
# the bodies' positions and velocities (models.evaluation.parts): its force, positive in compression, and its compression
# x_a - x_b (ground: x = 0); a coupling also the opening of its gap.
LINK_SERIES = ("_force_n", "_compression_m")
COUPLING_SERIES = ("_gap_opening_m",)


def body_metric(name: str) -> tuple[str, str] | None:
    """(body, suffix) of a per-body metric name (BODY_METRICS), None for another name."""
    for suffix in BODY_METRICS:
        if name.endswith(suffix) and len(name) > len(suffix):
            return name.removesuffix(suffix), suffix
    return None


def metric_need(name: str) -> Need:
    """What the metric ``name`` needs (KeyError for an unknown name)."""
    if name in METRICS:
        return METRICS[name]
    part = body_metric(name)
    if part is None:
        raise KeyError(name)
    return Need(BODY_METRICS[part[1]].effects, BODY_METRICS[part[1]].data, frozenset({part[0]}))


def needs(metrics: list[str], series: list[str]) -> Need:
    """Union of what the requested outputs need."""
    wanted = [metric_need(m) for m in metrics] + [SERIES[s] for s in series]
    return Need(*(frozenset().union(*(getattr(w, part) for w in wanted)) for part in ("effects", "data", "bodies")))
