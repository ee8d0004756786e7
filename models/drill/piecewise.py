"""The piecewise-linear elements of a run placed in the state: the rock law and every nonlinear
connector, with their local variables as rows over y = (x (n bodies), v (n bodies), rock states).

Both the ODE and the exact formulation generate their switching from these rows and the laws'
mode tables (rocklaw.modes): an element in mode m leaves it when an exit surface . z(y) crosses
zero in its direction, its states move at rates . z(y), on entering a mode its states take the
entry values (a never-decreasing state, the borehole bottom, keeps the larger of old and new:
the event location's round-off cannot move it back), and its force F = force . z(y) acts on the
bodies along ``load`` (the rock: -e_bit; a link: e_a - e_b, F > 0 pulling its ends together).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ...rocklaw import RockLaw
from ...rocklaw.base import POSITION, VELOCITY
from ...rocklaw.modes import ONE, Affine, ModeTable, Piecewise, evaluate, global_row
from ..definition.links import RATE, STRETCH, Link
from .chain import AxialChain


@dataclass(frozen=True)
class Element:
    """A law with modes, placed in the state (module doc)."""

    name: str
    law: Piecewise
    table: ModeTable
    variables: Mapping[str, np.ndarray]  # local variable -> row over y ("one" excluded)
    states: Mapping[str, int]  # the law's state names -> index in y
    monotone: int | None  # index in y of the never-decreasing state
    load: np.ndarray  # how F acts on the n bodies

    def values(self, y: np.ndarray) -> dict[str, float]:
        """The local variables at state y."""
        return {name: float(row @ y) for name, row in self.variables.items()}

    def row(self, affine: Affine) -> tuple[np.ndarray, float]:
        """(row over y, constant) of an affine function of the local variables."""
        return global_row({k: v for k, v in affine.items() if k != ONE}, self.variables), affine.get(ONE, 0.0)

    def initial_mode(self, y: np.ndarray) -> str:
        return self.law.initial_mode(self.values(y))

    def enter(self, mode: str, y: np.ndarray) -> np.ndarray:
        """y with the entry values of ``mode`` (module doc)."""
        entry = self.table[mode].entry
        if not entry:
            return y
        values, y = self.values(y), y.copy()
        for state, affine in entry.items():
            index, value = self.states[state], evaluate(affine, values)
            y[index] = max(y[index], value) if index == self.monotone else value
        return y


def _unit(size: int, index: int) -> np.ndarray:
    row = np.zeros(size)
    row[index] = 1.0
    return row


def rock_element(chain: AxialChain, rock: RockLaw, size: int) -> Element:
    """The rock law on the bit; its states follow the 2n positions and velocities in y."""
    n, bit = chain.size, chain.bit_body
    states = {name: 2 * n + i for i, name in enumerate(rock.state_names)}
    variables = {POSITION: _unit(size, bit), VELOCITY: _unit(size, n + bit),
                 **{name: _unit(size, index) for name, index in states.items()}}
    load = -_unit(n, bit)
    return Element("rock", rock, rock.modes(), variables, states, states[rock.state_names[rock.bottom_index]], load)


def link_element(chain: AxialChain, link: Link, size: int) -> Element:
    """A nonlinear connector: stretch x_b - x_a and its rate."""
    n = chain.size
    ends = _unit(size, link.body_b) - (0.0 if link.body_a is None else _unit(size, link.body_a))
    rates = _unit(size, n + link.body_b) - (0.0 if link.body_a is None else _unit(size, n + link.body_a))
    load = (0.0 if link.body_a is None else _unit(n, link.body_a)) - _unit(n, link.body_b)
    more, states = link.placed(n, size)
    return Element(link.name, link, link.modes(), {STRETCH: ends, RATE: rates, **more}, states, None, load)


def undeclared(chain: AxialChain, rock: RockLaw) -> str | None:
    """Why the piecewise elements cannot be placed: the laws that declare no modes, or None."""
    missing = []
    for name, law in (("rock law " + rock.name, rock), *((f"connector {link.name}", link) for link in chain.nonlinear_links())):
        try:
            law.modes()
        except (NotImplementedError, AttributeError):
            missing.append(name)
            continue
        if not callable(getattr(law, "initial_mode", None)):
            missing.append(name)
    return (f"{', '.join(missing)} declare no modes (the mode table: modes() and initial_mode(values), "
            "rocklaw.modes; docs/extending.md)") if missing else None


def elements(chain: AxialChain, rock: RockLaw, size: int) -> tuple[Element, ...]:
    """The rock and every nonlinear link of the chain, rows over a state of ``size`` entries."""
    return (rock_element(chain, rock, size), *(link_element(chain, link, size) for link in chain.nonlinear_links()))
