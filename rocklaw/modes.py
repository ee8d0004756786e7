"""Piecewise-linear laws declared once: modes with affine force rows, state rates, entry values and
switching surfaces.

A rock law or a connector type that is linear between switches declares a table of modes over
its *local variables* (a rock law: ``position`` and ``velocity`` of the bit and its state names;
a connector: its ``stretch`` and stretch ``rate``; every law: ``one``, the constant 1). In a mode

    F = force . z,    state_j' = rates[j] . z   (states not listed do not move),

and the mode is left at the first zero crossing, in its direction, of one of its ``exits``
(surface . z); on entering a mode its ``entry`` rows give new values of the states listed
(state_j = entry[j] . z at the switch). Every formulation generates what it needs from this one
declaration: the ODE its event functions, state rates and resets; the exact solver its matrices
and exit rows. The law's closed form (``force`` with a backend) must agree with the mode rows in
each mode; :func:`check_mode_forces` tests that.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

Affine = Mapping[str, float]  # coefficients over local variable names; "one" is the constant
ONE = "one"


@dataclass(frozen=True)
class Switch:
    """Leave the mode when ``surface`` . z crosses zero in ``direction`` (+1 rising, -1 falling)."""

    surface: Affine
    direction: int
    next_mode: str


@dataclass(frozen=True)
class Mode:
    """A piece of a piecewise-linear law (module doc)."""

    force: Affine
    exits: tuple[Switch, ...]
    rates: Mapping[str, Affine] = field(default_factory=dict)
    entry: Mapping[str, Affine] = field(default_factory=dict)


ModeTable = Mapping[str, Mode]


class Piecewise(Protocol):
    """A law that declares its modes (rock laws, connector types)."""

    def modes(self) -> ModeTable: ...

    def initial_mode(self, values: Mapping[str, float]) -> str:
        """The mode of a start at these local-variable values."""
        ...


def evaluate(affine: Affine, values: Mapping[str, float]) -> float:
    """affine . z at the local-variable values (``one`` is 1)."""
    return sum(coefficient * (1.0 if name == ONE else values[name]) for name, coefficient in affine.items())


def global_row(affine: Affine, rows: Mapping[str, np.ndarray]) -> np.ndarray:
    """The affine function as a row over a formulation's state: sum of coefficient x ``rows[name]``,
    where ``rows`` maps every local variable (``one`` included) to its row in that state."""
    return sum((coefficient * rows[name] for name, coefficient in affine.items()),
               np.zeros_like(next(iter(rows.values()))))


def check_mode_forces(law: Piecewise, samples: Sequence[Mapping[str, float]],
                      closed_form: Callable[[Mapping[str, float]], float]) -> list[str]:
    """Problems where a mode's force row disagrees with the closed form at a sample point that lies
    in that mode (``law.initial_mode``); an empty list when the declaration is consistent."""
    problems = []
    for values in samples:
        mode = law.initial_mode(values)
        declared, closed = evaluate(law.modes()[mode].force, values), closed_form(values)
        if abs(declared - closed) > 1e-9 * max(1.0, abs(closed)):
            problems.append(f"mode {mode!r} at {dict(values)}: row gives {declared:g}, closed form {closed:g}")
    return problems
