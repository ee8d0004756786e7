"""What the steady-state solver answers for a scene (models.steady.regimes finds it): its regime, the stable
orbit, the unstable orbits met, and why none was found."""

from __future__ import annotations

from dataclasses import dataclass, field

from .shooting import Orbit

PERIOD_1, NONE_FOUND = "period-1", "no periodic orbit found"
IRREGULAR = "irregular"  # where the drill goes from its start when that is no period up to 6 blows


@dataclass(frozen=True)
class StartCheck:
    """Where the drill goes from its scene's start (models.steady.start_check): ``regime`` the attractor it reaches
    (``period-n``, or ``irregular``), ``reaches_orbit`` whether that is the orbit found, ``advance_per_blow_m``
    the other orbit's (NaN: none), after ``blows`` blows, ``cpu_time_s`` the check's cost."""

    regime: str
    reaches_orbit: bool
    blows: int
    advance_per_blow_m: float
    cpu_time_s: float


class SteadyStateUnavailable(ValueError):
    """The scene has no orbit relative to the bottom (models.steady.section.drift_problem)."""


@dataclass(frozen=True)
class SteadyState:
    """The regime found (module doc): ``orbit`` the stable orbit (None when none was found),
    ``unstable`` the unstable orbits met on the way, ``note`` what was tried when none was found."""

    regime: str
    orbit: Orbit | None
    unstable: tuple[Orbit, ...] = ()
    note: str = ""
    map_runs: int = 0
    cpu_time_s: float = 0.0
    exact_guide: Orbit | None = field(default=None, compare=False)  # the exact model's orbit (other formulations)
    # where the drill goes from its scene's start beside the orbit (models.steady.start_check; None: not checked)
    start: StartCheck | None = field(default=None, compare=False)

    @property
    def period_blows(self) -> int | None:
        return None if self.orbit is None else self.orbit.periods

    @property
    def floquet_max_abs(self) -> float:
        """max |mu| of the stable orbit, else of the least unstable orbit met (NaN: none)."""
        if self.orbit is not None:
            return self.orbit.floquet_max_abs
        return min((o.floquet_max_abs for o in self.unstable), default=float("nan"))


def regime_name(periods: int) -> str:
    return f"period-{periods}"
