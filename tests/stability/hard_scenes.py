"""The hard scenes of the stability suite: stiff, impulsive, undamped, overdamped, chattering."""

from __future__ import annotations

from typing import Any

from scenes import CRUSHING, scene_dict

from rpdrill import Scene


def _links(stiffness: tuple[float, float, float], damping: tuple[float, float, float]) -> dict[str, Any]:
    names = ("shock_absorber", "shank_collar_joint", "collar_bit_joint")
    return {f"drill_string.connectors.{n}.{key}": value
            for n, k, c in zip(names, stiffness, damping, strict=True)
            for key, value in (("stiffness_n_per_m", k), ("damping_n_s_per_m", c))}


BASE_K = (1e7, 2e9, 5e9)
SHORT = {"solver.end_time_s": 0.3, "metrics.transient_blows": 5, "metrics.block_blows": 4}

# name: (overrides on paper_base, simulated seconds kept short unless the case is about length)
HARD_SCENES: dict[str, dict[str, Any]] = {
    "stiffest_rock_stiff_joints": {
        **CRUSHING, "rock": {"name": "conglomerate"}, "impact.amplitude_n": 1e6,
        **_links((1e7, 2e9, 2e9), (2e4, 1e3, 1e3)),
    },
    "short_strong_pulse": {"impact.amplitude_n": 1e6, "impact.duration_s": 50e-6, "solver.end_time_s": 0.12,
                           "metrics.transient_blows": 3, "metrics.block_blows": 2},
    "far_above_resonance": {**CRUSHING, "impact.frequency_hz": 500.0, "metrics.transient_blows": 50,
                            "metrics.block_blows": 20},
    "no_damping": {**CRUSHING, **_links(BASE_K, (0.0, 0.0, 0.0)), "rock.damping_n_s_per_m": 0.0},
    # c = 2 sqrt(k m) with the lighter neighbour's mass: damping ratios near 1
    "critical_damping": {**CRUSHING, **_links(BASE_K, (3.2e4, 4.5e5, 7.7e5)), "rock.damping_n_s_per_m": 2.4e5},
    # a light bit on a soft joint, little feed, no damping at the bit: several contacts per blow
    "chattering_bit": {**CRUSHING, "drill_string.bodies.bit.mass_kg": 0.5, "rock": {"name": "conglomerate", "damping_n_s_per_m": 0.0},
                       "feed.force_n": 1e3, **_links((1e7, 2e9, 1e9), (2e4, 0.0, 0.0))},
    "crushes_on_every_contact": {"rock.threshold_n": 5e3},
    "never_crushes": {**CRUSHING, "rock.threshold_n": 1e9},
    "very_soft_rock": {**CRUSHING, "rock.stiffness_n_per_m": 1e6},
}
# 650 blows that each crush and lift off (the exact formulation: 653 switches into crushing, 650 lift-offs; at the
# CRUSHING threshold of 138 kN the drill crushed in its second blow only, and the rates compared were 0 and 0)
LONG_RUN = {**CRUSHING, "impact.frequency_hz": 65.0, "rock.threshold_n": 100e3, "solver.end_time_s": 10.0,
            "metrics.transient_blows": 50, "metrics.block_blows": 50}


def hard_scene(overrides: dict[str, Any], solver: dict[str, Any] | None = None) -> Scene:
    """The test drill with a hard scene's ``overrides``, short unless they say otherwise, with the
    ``solver`` options (default: the scene's default, the standard preset)."""
    data = scene_dict(**(SHORT | overrides))
    data["solver"] = {"end_time_s": data["solver"]["end_time_s"]} | (solver or {})
    return Scene.model_validate(data)
