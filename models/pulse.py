"""Piston impact force F_d(t): one pulse of duration tau at the start of every period 1/f.

With s = t mod (1/f), for s < tau:
half_sine   F = I sin(pi s / tau)          (impulse per blow 2 I tau / pi)
rectangular F = I                          (impulse I tau)
triangular  F = I (1 - |2 s / tau - 1|)    (impulse I tau / 2)
and F = 0 for s >= tau. Written once against a backend, evaluated numerically or symbolically.
"""

from __future__ import annotations

import math
from typing import Any

from rpdrill.models.scene import Impact
from rpdrill.rocklaw.backends import NUMERIC, Backend


def impact_force(impact: Impact, t: Any, backend: Backend = NUMERIC) -> Any:
    """F_d(t) [N] on the shank."""
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


def pulse_switch_times(impact: Impact, end_time_s: float) -> list[float]:
    """Times at which F_d switches on or off in [0, end_time_s] (for event-located solvers)."""
    times = []
    for blow in range(math.floor(end_time_s * impact.frequency_hz) + 1):
        start = blow * impact.period_s
        times += [t for t in (start, start + impact.duration_s) if t <= end_time_s]
    return times


def impulse_per_blow_n_s(impact: Impact) -> float:
    """Integral of F_d over one pulse [N s]."""
    factor = {"half_sine": 2.0 / math.pi, "rectangular": 1.0, "triangular": 0.5}[impact.shape]
    return factor * impact.amplitude_n * impact.duration_s
