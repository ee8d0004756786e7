"""Piston impact force F_d(t): one pulse of duration tau at the start of every period 1/f; every
representation of it lives here.

With s = t mod (1/f), for s < tau:
half_sine   F = I sin(pi s / tau)          (impulse per blow 2 I tau / pi)
rectangular F = I                          (impulse I tau)
triangular  F = I (1 - |2 s / tau - 1|)    (impulse I tau / 2)
and F = 0 for s >= tau.

* :func:`impact_force`: the closed form, written once against a backend (NumPy, floats, or
  recorded as an Exudyn symbolic expression);
* :func:`phase_pieces`: the pieces of [0, end] on which F_d has one formula (phases ``on``, or
  ``rising`` and ``falling`` for the triangle, and ``off``), the breakpoints of event-located solvers;
* the oscillator augmentation that makes F_d linear and autonomous on each piece: with the
  generator states (u1, u2) (half-sine: u1 = sin(pi s/tau), u2 = cos(pi s/tau); triangle: u1 = s;
  rectangle: none), F_d = :func:`phase_row` . (1, u1, u2) and (1, u1, u2)' = :func:`phase_generator`
  (1, u1, u2); :func:`generator_states` gives (u1, u2) at the start of a piece.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..rocklaw.backends import NUMERIC, Backend
from .scene import Impact

OFF, ON, RISING, FALLING = PHASES = ("off", "on", "rising", "falling")


def impact_force(impact: Impact, t: Any, backend: Backend = NUMERIC) -> Any:
    """F_d(t) [N] on the shank (none with a piston: models.piston)."""
    if impact.piston is not None:
        return 0.0 * backend.mod(t, impact.period_s)
    tau = impact.duration_s
    s = backend.mod(t, impact.period_s)
    if impact.shape == "half_sine":
        pulse = impact.amplitude_n * backend.sin((math.pi / tau) * s)
    elif impact.shape == "rectangular":
        pulse = impact.amplitude_n + 0.0 * s
    else:
        rising = (2.0 * impact.amplitude_n / tau) * s
        pulse = backend.minimum(rising, 2.0 * impact.amplitude_n - rising)
    return backend.where(s < tau, pulse, 0.0)


def impulse_per_blow_n_s(impact: Impact) -> float:
    """Integral of F_d over one pulse [N s]; with a piston its momentum m_p v_p (the most a blow gives)."""
    if impact.piston is not None:
        return impact.piston.total_mass_kg * impact.piston.strike_velocity_m_per_s
    factor = {"half_sine": 2.0 / math.pi, "rectangular": 1.0, "triangular": 0.5}[impact.shape]
    return factor * impact.amplitude_n * impact.duration_s


def _pieces_of_a_period(impact: Impact) -> tuple[tuple[float, float, str], ...]:
    """(start, end, phase) within one period, times after the blow's start (a piston: no pulse phase)."""
    if impact.piston is not None:
        return ((0.0, impact.period_s, OFF),)
    tau = impact.duration_s
    inner = ((0.0, 0.5 * tau, RISING), (0.5 * tau, tau, FALLING)) if impact.shape == "triangular" else ((0.0, tau, ON),)
    return (*inner, (tau, impact.period_s, OFF))


def phase_pieces(impact: Impact, end_time_s: float) -> tuple[np.ndarray, list[str]]:
    """((start, end) rows, phase) of the pieces of F_d covering [0, end_time_s]."""
    pieces = _pieces_of_a_period(impact)
    starts = blow_start_times(impact, end_time_s)[:, None]
    times = np.stack([starts + [low for low, _, _ in pieces], starts + [high for _, high, _ in pieces]], axis=-1)
    times = times.reshape(-1, 2)
    keep = times[:, 0] < end_time_s
    times[:, 1] = np.minimum(times[:, 1], end_time_s)
    return times[keep], [phase for phase, kept in zip([p[2] for p in pieces] * len(starts), keep) if kept]


def switch_times(impact: Impact, end_time_s: float) -> np.ndarray:
    """0, every time F_d changes formula in (0, end_time_s), and end_time_s, sorted and unique."""
    times, _ = phase_pieces(impact, end_time_s)
    return np.unique(np.concatenate([[0.0, end_time_s], times.ravel()]))


def blow_start_times(impact: Impact, end_time_s: float) -> np.ndarray:
    """The start of every blow in [0, end_time_s): k / f (the same floats as the pieces' starts)."""
    return np.arange(math.ceil(end_time_s / impact.period_s)) * impact.period_s


def generator_states(impact: Impact, local_s: np.ndarray) -> np.ndarray:
    """(u1, u2) at times ``local_s`` after the blow's start (rows): (sin, cos)(pi s / tau) for the
    half-sine, (s, 0) for the triangle, zeros for the rectangle."""
    states = np.zeros((len(local_s), 2))
    if impact.shape == "half_sine":
        states[:, 0] = np.sin(np.pi * local_s / impact.duration_s)
        states[:, 1] = np.cos(np.pi * local_s / impact.duration_s)
    elif impact.shape == "triangular":
        states[:, 0] = local_s
    return states


def phase_row(impact: Impact, phase: str) -> np.ndarray:
    """F_d = row . (1, u1, u2) in ``phase``."""
    if phase == OFF:
        return np.zeros(3)
    amplitude, slope = impact.amplitude_n, 2.0 * impact.amplitude_n / impact.duration_s
    if impact.shape == "half_sine":
        return np.array([0.0, amplitude, 0.0])
    if impact.shape == "rectangular":
        return np.array([amplitude, 0.0, 0.0])
    return np.array([0.0, slope, 0.0]) if phase == RISING else np.array([2.0 * amplitude, -slope, 0.0])


def phase_generator(impact: Impact, phase: str) -> np.ndarray:
    """G with (1, u1, u2)' = G (1, u1, u2): the oscillator of the half-sine, the ramp s' = 1."""
    generator = np.zeros((3, 3))
    if phase == OFF:
        return generator
    if impact.shape == "half_sine":
        omega = math.pi / impact.duration_s
        generator[1, 2], generator[2, 1] = omega, -omega
    elif impact.shape == "triangular":
        generator[1, 0] = 1.0
    return generator
