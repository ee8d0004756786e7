"""Connector laws of the drill string: the force a link transmits between two bodies.

A link joins ``body_a`` (None: ground) to ``body_b``; delta = x_b - x_a is its stretch and delta'
the stretch rate. Its force F > 0 pulls the two bodies together (on body_b it acts along -x).
Each law is written once against the backends of :mod:`rocklaw.backends`: the Exudyn builder
records it as a symbolic spring-force function, the ODE formulation and the energy account
evaluate it with NumPy. A ``linear`` law is assembled into the matrices K and C instead; a
nonlinear one that is linear between switches declares its modes once (:mod:`rocklaw.modes`,
local variables ``stretch``, ``rate`` and ``one``), from which the ODE formulation takes its
events and the exact formulation its matrices and exit rows.

A new connector type is a subclass with its own ``spring_force_n``, ``force_n``, ``modes`` and
``initial_mode``, registered in :data:`LINK_TYPES` (docs/extending.md); its extra dataclass
fields are the parameters a scene's connector may give.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, fields
from typing import Any, ClassVar

import numpy as np

from ...rocklaw.backends import NUMERIC, Backend
from ...rocklaw.modes import ONE, Mode, ModeTable, Switch

STRETCH, RATE = "stretch", "rate"  # a link's local variables in its mode table
BONDED, OPEN, CLOSED, CLIPPED = "bonded", "open", "closed", "clipped"


@dataclass(frozen=True)
class Link:
    """The bonded spring-damper, base of every connector type: F = k delta + c delta'."""

    name: str
    body_a: int | None
    body_b: int
    stiffness_n_per_m: float
    damping_n_s_per_m: float

    linear: ClassVar[bool] = True

    @property
    def rigid(self) -> bool:
        """Infinitely stiff (rigid faces joined without a stiffness: models.waves): a constraint, not a spring."""
        return self.stiffness_n_per_m == float("inf")

    def stretch(self, values: Any) -> Any:
        """delta = x_b - x_a (x_a = 0 for ground) from a state's positions, or its rate from velocities."""
        return values[self.body_b] - (0.0 if self.body_a is None else values[self.body_a])

    def spring_force_n(self, stretch_m: Any, backend: Backend = NUMERIC) -> Any:
        """Rate-independent part; the stored energy is F_spring^2 / (2 k)."""
        return self.stiffness_n_per_m * stretch_m

    def force_n(self, stretch_m: Any, rate_m_per_s: Any, backend: Backend = NUMERIC) -> Any:
        return self.stiffness_n_per_m * stretch_m + self.damping_n_s_per_m * rate_m_per_s

    def modes(self) -> ModeTable:
        """One mode: F = k delta + c delta'. A nonlinear type must declare its own (NotImplementedError
        otherwise: inheriting the bonded mode would run the wrong law)."""
        if not self.linear:
            raise NotImplementedError(f"connector type {type(self).__name__} declares no modes (rocklaw.modes)")
        return {BONDED: Mode({STRETCH: self.stiffness_n_per_m, RATE: self.damping_n_s_per_m}, ())}

    def initial_mode(self, values: Mapping[str, float]) -> str:
        return BONDED

    def placed(self, bodies: int, size: int) -> tuple[dict[str, np.ndarray], dict[str, int]]:
        """Local variables beyond the stretch and its rate (rows over a state (x, v, ...) of ``bodies``
        bodies and ``size`` entries) and states (name -> index) that the modes read or reset: none for a
        connector; the piston's contact reads and resets the piston (models.drill.piston.PistonContact)."""
        return {}, {}

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

    def gap_opening_m(self, stretch_m: Any, backend: Backend = NUMERIC) -> Any:
        """The open gap, delta + g while positive (0 once it has closed)."""
        return backend.maximum(stretch_m + self.gap_m, 0.0)

    def modes(self) -> ModeTable:
        """open (F = 0) until the closure delta + g falls through 0; closed, F = k (delta + g) + c delta',
        until it rises through 0 again or F rises through 0 (the damper would pull: clipped, F = 0)."""
        k, c = self.stiffness_n_per_m, self.damping_n_s_per_m
        closure = {STRETCH: 1.0, ONE: self.gap_m}
        total = {STRETCH: k, RATE: c, ONE: k * self.gap_m}
        closed_exits = [Switch(closure, 1, OPEN)] + ([Switch(total, 1, CLIPPED)] if c > 0 else [])
        table = {OPEN: Mode({}, (Switch(closure, -1, CLOSED),)), CLOSED: Mode(total, tuple(closed_exits))}
        if c > 0:
            table[CLIPPED] = Mode({}, (Switch(total, -1, CLOSED), Switch(closure, 1, OPEN)))
        return table

    def initial_mode(self, values: Mapping[str, float]) -> str:
        closure = values[STRETCH] + self.gap_m
        if closure >= 0:
            return OPEN
        total = self.stiffness_n_per_m * closure + self.damping_n_s_per_m * values[RATE]
        return CLIPPED if self.damping_n_s_per_m > 0 and total >= 0 else CLOSED


LINK_TYPES: dict[str, type[Link]] = {"spring_damper": Link, "coupling": Coupling}
