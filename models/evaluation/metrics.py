"""Summary figures of a run over whole impact periods after the transient.

Window: blows ``transient_blows`` .. N of the run (N whole periods that fit), cut into
blocks of ``block_blows`` blows (a trailing partial block is dropped).
Penetration rate = (x_n(end) - x_n(start)) / window length; its spread is the standard
deviation of the block rates. Penetration per impact energy = (x_n(end) - x_n(start)) / W_impact
over the window (= penetration rate / mean impact power; W_impact = int F_d v dt, models.evaluation.energy,
without the rest of the energy account). A body's metrics by its name: peak and RMS velocity
(``<body>_velocity_peak_m_per_s``). Only the metrics the scene's outputs ask for are computed.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from functools import cached_property

import numpy as np

from ..definition.outputs import body_metric
from .energy import EnergyAccount, energy_account, impact_work_j
from .results import SimulationResult
from .rod_outputs import BOTTOM, TOP, blow_figures, rock_energy_per_blow_j, rods


class _Window:
    """The averaging window of a run and the quantities several metrics share (computed once)."""

    def __init__(self, result: SimulationResult, energy: EnergyAccount | None) -> None:
        self.result, self._energy = result, energy
        scene, t = result.scene, result.time_s
        self.period = scene.impact.period_s
        blows_run = math.floor(t[-1] / self.period + 1e-9)
        self.first = scene.metrics.transient_blows
        self.n_blocks = (blows_run - self.first) // scene.metrics.block_blows
        self.blows = self.n_blocks * scene.metrics.block_blows
        self.boundaries = np.arange(self.first, self.first + self.blows + 1) * self.period
        self.duration = self.boundaries[-1] - self.boundaries[0]
        self.mask = (t >= self.boundaries[0] - 1e-12) & (t <= self.boundaries[-1] + 1e-12)

    @cached_property
    def per_blow(self) -> np.ndarray:
        return np.diff(self.result.bottom_at(self.boundaries))

    @cached_property
    def block_rates(self) -> np.ndarray:
        blocks = self.per_blow.reshape(self.n_blocks, -1).sum(axis=1)
        return blocks / (self.result.scene.metrics.block_blows * self.period)

    @cached_property
    def energy(self) -> EnergyAccount:
        return self._energy or energy_account(self.result)

    @cached_property
    def impact_work(self) -> float:
        """W_impact over the window, from the energy account when there is one."""
        return self.work(self._energy.impact_work_j if self._energy else impact_work_j(self.result))

    def advance_per_impact_work(self) -> float:
        return float(self.per_blow.sum() / self.impact_work) if self.impact_work > 0 else float("nan")

    def work(self, cumulative: np.ndarray) -> float:
        """Increase of a cumulative energy over the window."""
        t = self.result.time_s
        return float(np.interp(self.boundaries[-1], t, cumulative) - np.interp(self.boundaries[0], t, cumulative))

    def peak(self, values: np.ndarray) -> float:
        return float(np.max(np.abs(values[self.mask])))

    def rms(self, values: np.ndarray) -> float:
        return float(math.sqrt(np.trapezoid(values[self.mask] ** 2, self.result.time_s[self.mask]) / self.duration))

    def window_blows(self, per_blow: np.ndarray) -> np.ndarray:
        """The window's blows of a per-blow array (blows that started in the run)."""
        return per_blow[self.first:self.first + self.blows]

    def rod_stress(self, rod: str, kind: str) -> float:
        """The largest compression or tension (``kind``) at the rod's ends in the window's blows over its area."""
        area = self.result.scene.drill_string.bodies[rod].area_m2
        return max(float(np.max(self.window_blows(getattr(blow_figures(self.result, rod, end), kind)), initial=0.0))
                   for end in (TOP, BOTTOM)) / area

    def rod_energy(self, rod: str, end: str) -> float:
        """The mean energy per blow through the rod's end along +x over the window's blows."""
        return float(np.mean(self.window_blows(blow_figures(self.result, rod, end).energy_j)))

    @cached_property
    def rock_energy(self) -> np.ndarray:
        return self.window_blows(rock_energy_per_blow_j(self.result))

    def rock_transfer(self) -> float:
        """The rock's energy over the energy the window's blows put in: the piston's blow energies, or the
        pulse's impact work."""
        piston = self.result.simulation.piston
        put_in = self.blows * piston.blow_energy_j if piston is not None else self.impact_work
        return float(np.sum(self.rock_energy) / put_in) if put_in > 0 else float("nan")

    def efficiency(self) -> float:
        """Crushing work / work put in by the impacts and the feed over the window."""
        put_in = self.impact_work + self.work(self.energy.feed_work_j)
        return self.work(self.energy.crushing_work_j) / put_in if put_in > 0 else float("nan")


def _rebound_energy(w: _Window) -> float:
    """The mean rebound energy of the blows that start in the window (models.drill.piston)."""
    rebounds = w.result.piston.rebounds
    starts = rebounds[:, 0] if len(rebounds) else np.empty(0)
    inside = (starts >= w.boundaries[0] - 1e-9 * w.period) & (starts < w.boundaries[-1] - 1e-9 * w.period)
    return float(np.mean(rebounds[inside, 1])) if inside.any() else float("nan")


def _spread(values: np.ndarray) -> float:
    return float(np.std(values, ddof=1)) if len(values) > 1 else 0.0


METRIC_FUNCTIONS: dict[str, Callable[[_Window], float]] = {
    "penetration_rate_m_per_s": lambda w: float(w.per_blow.sum() / w.duration),
    "penetration_rate_block_std_m_per_s": lambda w: _spread(w.block_rates),
    "penetration_rate_block_min_m_per_s": lambda w: float(w.block_rates.min()),
    "penetration_rate_block_max_m_per_s": lambda w: float(w.block_rates.max()),
    "penetration_per_impact_energy_m_per_j": lambda w: w.advance_per_impact_work(),
    "advance_per_blow_m": lambda w: float(w.per_blow.mean()),
    "advance_per_blow_std_m": lambda w: _spread(w.per_blow),
    "borehole_bottom_final_m": lambda w: float(w.result.bottom_at(w.result.time_s[-1:])[0]),
    "bit_velocity_peak_m_per_s": lambda w: w.peak(w.result.bit_velocity_m_per_s),
    "bit_velocity_rms_m_per_s": lambda w: w.rms(w.result.bit_velocity_m_per_s),
    "rock_force_max_n": lambda w: float(np.max(w.result.rock_force_n[w.mask])),
    "impact_energy_j": lambda w: w.impact_work,
    "feed_energy_j": lambda w: w.work(w.energy.feed_work_j),
    "crushing_work_j": lambda w: w.work(w.energy.crushing_work_j),
    "energy_transfer_efficiency": lambda w: w.efficiency(),
    "energy_balance_relative_error": lambda w: w.energy.relative_residual(),
    "piston_rebound_energy_j": _rebound_energy,
    "rod_stress_max_pa": lambda w: max(w.rod_stress(rod, kind) for rod in rods(w.result.scene)
                                       for kind in ("compression_n", "tension_n")),
    "rock_energy_per_blow_j": lambda w: float(np.mean(w.rock_energy)),
    "rock_transfer_efficiency": lambda w: w.rock_transfer(),
    "penetration_per_blow_energy_m_per_j": lambda w: float(
        w.per_blow.sum() / (w.blows * w.result.simulation.piston.blow_energy_j)),
    "window_start_s": lambda w: float(w.boundaries[0]),
    "window_end_s": lambda w: float(w.boundaries[-1]),
    "window_blows": lambda w: w.blows,
    "cpu_time_s": lambda w: float(w.result.cpu_time_s),
}


# a body's metrics by name (models.definition.outputs.BODY_METRICS), "<body>_velocity_peak_m_per_s": collar_... among them
BODY_METRIC_FUNCTIONS: dict[str, Callable[[_Window, str], float]] = {
    "_velocity_peak_m_per_s": lambda w, body: w.peak(w.result.body_velocity_m_per_s(body)),
    "_velocity_rms_m_per_s": lambda w, body: w.rms(w.result.body_velocity_m_per_s(body)),
    "_compressive_stress_max_pa": lambda w, rod: w.rod_stress(rod, "compression_n"),
    "_tensile_stress_max_pa": lambda w, rod: w.rod_stress(rod, "tension_n"),
    "_energy_in_per_blow_j": lambda w, rod: w.rod_energy(rod, TOP),
    "_energy_out_per_blow_j": lambda w, rod: w.rod_energy(rod, BOTTOM),
}


def _metric(window: _Window, name: str) -> float:
    if name in METRIC_FUNCTIONS:
        return METRIC_FUNCTIONS[name](window)
    body, suffix = body_metric(name)
    return BODY_METRIC_FUNCTIONS[suffix](window, body)


def summary_metrics(result: SimulationResult, energy: EnergyAccount | None = None) -> dict[str, float]:
    """The metrics the scene's outputs ask for (SI units in the keys), in their order."""
    window = _Window(result, energy)
    return {name: _metric(window, name) for name in result.simulation.outputs.metrics}


def block_rates_m_per_s(result: SimulationResult) -> np.ndarray:
    """The penetration rate of each block of the averaging window (module doc)."""
    return _Window(result, None).block_rates
