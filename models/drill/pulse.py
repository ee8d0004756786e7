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

Each shape is one entry of SHAPES (a :class:`Shape`: its closed form, impulse, pieces, generator states,
rows and generator); the functions above look the scene's shape up there. A new shape is a new entry.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...rocklaw.backends import NUMERIC, Backend
from ..definition.scene import Impact

OFF, ON, RISING, FALLING = PHASES = ("off", "on", "rising", "falling")
ZERO_ROW, ZERO_GENERATOR = np.zeros(3), np.zeros((3, 3))


@dataclass(frozen=True)
class Shape:
    """One pulse shape, everything of it in one place: F(s) for 0 <= s < tau of amplitude I (``force``,
    against a backend), the impulse per blow / (I tau) (``impulse_factor``), the pieces of [0, tau]
    with one formula (``pieces``: fractions of tau and the phase), the generator states (u1, u2) at s
    (``states``), and per phase the row r with F = r . (1, u1, u2) and the generator G with
    (1, u1, u2)' = G (1, u1, u2) (``row``, ``generator``: functions of (I, tau))."""

    force: Callable[[float, float, Any, Backend], Any]
    impulse_factor: float
    pieces: tuple[tuple[float, float, str], ...]
    states: Callable[[np.ndarray, float], tuple[np.ndarray, np.ndarray]]
    row: Callable[[str, float, float], np.ndarray]
    generator: Callable[[str, float], np.ndarray]


def _no_states(local_s: np.ndarray, tau: float) -> tuple[np.ndarray, np.ndarray]:
    return np.zeros_like(local_s), np.zeros_like(local_s)


def _oscillator(tau: float) -> np.ndarray:
    """u1 = sin(omega s), u2 = cos(omega s), omega = pi / tau: u1' = omega u2, u2' = -omega u1."""
    generator = np.zeros((3, 3))
    generator[1, 2], generator[2, 1] = math.pi / tau, -math.pi / tau
    return generator


def _ramp(tau: float) -> np.ndarray:
    """u1 = s: u1' = 1."""
    generator = np.zeros((3, 3))
    generator[1, 0] = 1.0
    return generator


SHAPES: dict[str, Shape] = {
    "half_sine": Shape(
        force=lambda amplitude, tau, s, backend: amplitude * backend.sin((math.pi / tau) * s),
        impulse_factor=2.0 / math.pi,
        pieces=((0.0, 1.0, ON),),
        states=lambda s, tau: (np.sin(np.pi * s / tau), np.cos(np.pi * s / tau)),
        row=lambda phase, amplitude, tau: np.array([0.0, amplitude, 0.0]),
        generator=lambda phase, tau: _oscillator(tau)),
    "rectangular": Shape(
        force=lambda amplitude, tau, s, backend: amplitude + 0.0 * s,
        impulse_factor=1.0,
        pieces=((0.0, 1.0, ON),),
        states=_no_states,
        row=lambda phase, amplitude, tau: np.array([amplitude, 0.0, 0.0]),
        generator=lambda phase, tau: np.zeros((3, 3))),
    "triangular": Shape(
        force=lambda amplitude, tau, s, backend: backend.minimum((2.0 * amplitude / tau) * s,
                                                                 2.0 * amplitude - (2.0 * amplitude / tau) * s),
        impulse_factor=0.5,
        pieces=((0.0, 0.5, RISING), (0.5, 1.0, FALLING)),
        states=lambda s, tau: (s, np.zeros_like(s)),
        row=lambda phase, amplitude, tau: (np.array([0.0, 2.0 * amplitude / tau, 0.0]) if phase == RISING
                                           else np.array([2.0 * amplitude, -2.0 * amplitude / tau, 0.0])),
        generator=lambda phase, tau: _ramp(tau)),
}


def impact_force(impact: Impact, t: Any, backend: Backend = NUMERIC) -> Any:
    """F_d(t) [N] on the shank (none with a piston: models.drill.piston)."""
    if impact.piston is not None:
        return 0.0 * backend.mod(t, impact.period_s)
    tau = impact.duration_s
    s = backend.mod(t, impact.period_s)
    pulse = SHAPES[impact.shape].force(impact.amplitude_n, tau, s, backend)
    return backend.where(s < tau, pulse, 0.0)


def impulse_per_blow_n_s(impact: Impact) -> float:
    """Integral of F_d over one pulse [N s]; with a piston its momentum m_p v_p (the most a blow gives)."""
    if impact.piston is not None:
        return impact.piston.total_mass_kg * impact.piston.strike_velocity_m_per_s
    return SHAPES[impact.shape].impulse_factor * impact.amplitude_n * impact.duration_s


def _pieces_of_a_period(impact: Impact) -> tuple[tuple[float, float, str], ...]:
    """(start, end, phase) within one period, times after the blow's start (a piston: no pulse phase)."""
    if impact.piston is not None:
        return ((0.0, impact.period_s, OFF),)
    tau = impact.duration_s
    inner = tuple((low * tau, high * tau, phase) for low, high, phase in SHAPES[impact.shape].pieces)
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
    local_s = np.asarray(local_s, dtype=float)
    if impact.piston is not None:  # no prescribed pulse: no generator
        return np.zeros((len(local_s), 2))
    return np.column_stack(SHAPES[impact.shape].states(local_s, impact.duration_s)).reshape(len(local_s), 2)


def phase_row(impact: Impact, phase: str) -> np.ndarray:
    """F_d = row . (1, u1, u2) in ``phase``."""
    if phase == OFF:
        return ZERO_ROW.copy()
    return SHAPES[impact.shape].row(phase, impact.amplitude_n, impact.duration_s)


def phase_generator(impact: Impact, phase: str) -> np.ndarray:
    """G with (1, u1, u2)' = G (1, u1, u2): the oscillator of the half-sine, the ramp s' = 1."""
    if phase == OFF:
        return ZERO_GENERATOR.copy()
    return SHAPES[impact.shape].generator(phase, impact.duration_s)
