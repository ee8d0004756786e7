"""Connector laws of the drill string: the force a link transmits between two bodies.

A link joins ``body_a`` (None: ground) to ``body_b``; delta = x_b - x_a is its stretch and delta'
the stretch rate. Its force F > 0 pulls the two bodies together (on body_b it acts along -x).
Each law is written once against the backends of :mod:`rocklaw.backends`: the Exudyn builder
records it as a symbolic spring-force function, the ODE formulation and the energy account
evaluate it with NumPy. A ``linear`` law is assembled into the matrices K and C instead; a
nonlinear one lists its ``kinks`` (functions of delta whose zero crossings are where the law
changes branch), at which the ODE formulation restarts its integrator.

A new connector type is a subclass with its own ``spring_force_n``, ``force_n`` and ``kinks``,
registered in :data:`LINK_TYPES` (docs/extending.md); its extra dataclass fields are the
parameters a scene's connector may give.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, fields
from typing import Any, ClassVar

from rpdrill.rocklaw.backends import NUMERIC, Backend


@dataclass(frozen=True)
class Link:
    """The bonded spring-damper, base of every connector type: F = k delta + c delta'."""

    name: str
    body_a: int | None
    body_b: int
    stiffness_n_per_m: float
    damping_n_s_per_m: float

    linear: ClassVar[bool] = True

    def stretch(self, values: Any) -> Any:
        """delta = x_b - x_a (x_a = 0 for ground) from a state's positions, or its rate from velocities."""
        return values[self.body_b] - (0.0 if self.body_a is None else values[self.body_a])

    def spring_force_n(self, stretch_m: Any, backend: Backend = NUMERIC) -> Any:
        """Rate-independent part; the stored energy is F_spring^2 / (2 k)."""
        return self.stiffness_n_per_m * stretch_m

    def force_n(self, stretch_m: Any, rate_m_per_s: Any, backend: Backend = NUMERIC) -> Any:
        return self.stiffness_n_per_m * stretch_m + self.damping_n_s_per_m * rate_m_per_s

    def kinks(self) -> tuple[Callable[[float], float], ...]:
        return ()

    @classmethod
    def parameters(cls) -> tuple[str, ...]:
        """Scene keys beyond stiffness and damping that this type takes."""
        return tuple(f.name for f in fields(cls))[5:]


@dataclass(frozen=True)
class Coupling(Link):
    """A coupling that transmits compression only, once its gap g has closed:
    F = min(k (delta + g) + c delta', 0) while delta + g < 0, else 0 (never pulls)."""

    gap_m: float = 0.0

    linear: ClassVar[bool] = False

    def spring_force_n(self, stretch_m: Any, backend: Backend = NUMERIC) -> Any:
        closure = stretch_m + self.gap_m
        return backend.where(closure < 0, self.stiffness_n_per_m * closure, 0.0)

    def force_n(self, stretch_m: Any, rate_m_per_s: Any, backend: Backend = NUMERIC) -> Any:
        closure = stretch_m + self.gap_m
        total = backend.minimum(self.stiffness_n_per_m * closure + self.damping_n_s_per_m * rate_m_per_s, 0.0)
        return backend.where(closure < 0, total, 0.0)

    def kinks(self) -> tuple[Callable[[float], float], ...]:
        return (lambda stretch_m: stretch_m + self.gap_m,)


LINK_TYPES: dict[str, type[Link]] = {"spring_damper": Link, "coupling": Coupling}
