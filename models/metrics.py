"""Summary figures of a run over whole impact periods after the transient.

Window: blows ``transient_blows`` .. N of the run (N whole periods that fit), cut into
blocks of ``block_blows`` blows (a trailing partial block is dropped).
Penetration rate = (x_n(end) - x_n(start)) / window length; its spread is the standard
deviation of the block rates.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import trapezoid

from models.energy import EnergyAccount, energy_account
from models.results import SimulationResult


def _held(time_s: np.ndarray, values: np.ndarray, at: np.ndarray) -> np.ndarray:
    """Value of a step-held history at the given times (last stored value at or before)."""
    index = np.searchsorted(time_s, at + 1e-12, side="right") - 1
    return values[np.clip(index, 0, len(values) - 1)]


def _interp(energy: np.ndarray, time_s: np.ndarray, at: float) -> float:
    return float(np.interp(at, time_s, energy))


def summary_metrics(result: SimulationResult, energy: EnergyAccount | None = None) -> dict[str, float]:
    """Penetration, velocity, force and energy figures of one run (SI units in the keys)."""
    scene, t = result.scene, result.time_s
    energy = energy or energy_account(result)
    period = scene.impact.period_s
    blows_run = math.floor(t[-1] / period + 1e-9)
    first = scene.metrics.transient_blows
    n_blocks = (blows_run - first) // scene.metrics.block_blows
    last = first + n_blocks * scene.metrics.block_blows
    boundaries = np.arange(first, last + 1) * period
    bottom_at = _held(t, result.bottom_m, boundaries)
    per_blow = np.diff(bottom_at)
    block_rates = per_blow.reshape(n_blocks, -1).sum(axis=1) / (scene.metrics.block_blows * period)
    window = (t >= boundaries[0] - 1e-12) & (t <= boundaries[-1] + 1e-12)
    tw, v_bit = t[window], result.bit_velocity_m_per_s[window]
    v_collar = result.velocity_m_per_s[window, 1]
    duration = boundaries[-1] - boundaries[0]

    def window_work(cumulative: np.ndarray) -> float:
        return _interp(cumulative, t, boundaries[-1]) - _interp(cumulative, t, boundaries[0])

    impact_work = window_work(energy.impact_work_j)
    crushing_work = window_work(energy.crushing_work_j)
    return {
        "penetration_rate_m_per_s": float((bottom_at[-1] - bottom_at[0]) / duration),
        "penetration_rate_block_std_m_per_s": float(np.std(block_rates, ddof=1)) if n_blocks > 1 else 0.0,
        "penetration_rate_block_min_m_per_s": float(block_rates.min()),
        "penetration_rate_block_max_m_per_s": float(block_rates.max()),
        "advance_per_blow_m": float(per_blow.mean()),
        "advance_per_blow_std_m": float(per_blow.std(ddof=1)) if len(per_blow) > 1 else 0.0,
        "borehole_bottom_final_m": float(result.bottom_m[-1]),
        "bit_velocity_peak_m_per_s": float(np.max(np.abs(v_bit))),
        "bit_velocity_rms_m_per_s": float(math.sqrt(trapezoid(v_bit**2, tw) / duration)),
        "collar_velocity_peak_m_per_s": float(np.max(np.abs(v_collar))),
        "collar_velocity_rms_m_per_s": float(math.sqrt(trapezoid(v_collar**2, tw) / duration)),
        "rock_force_max_n": float(np.max(result.rock_force_n[window])),
        "impact_energy_j": impact_work,
        "feed_energy_j": window_work(energy.feed_work_j),
        "crushing_work_j": crushing_work,
        "energy_transfer_efficiency": crushing_work / impact_work if impact_work > 0 else float("nan"),
        "energy_balance_relative_error": energy.relative_residual(),
        "window_start_s": float(boundaries[0]),
        "window_end_s": float(boundaries[-1]),
        "window_blows": int(last - first),
        "cpu_time_s": float(result.cpu_time_s),
    }
