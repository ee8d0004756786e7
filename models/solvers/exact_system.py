"""The exact formulation's linear system (models.solvers.exact_model, its module doc): the augmented state's
layout, the generated matrix A of every (modes, phase) key with its exit rows, entry resets and power
forms (:class:`Model`), LAPACK's balancing, and the sub-step h the balanced norms choose
(:func:`sub_step`), and which scenes it cannot run (:func:`unsupported`). NumPy and LAPACK only, no
compiled kernels: checking a study's points and estimating their cost (models.solvers.cost) need these, not
the event loop, and do not load numba."""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np
from scipy.linalg.lapack import dgebal

from ...rocklaw.base import VELOCITY
from ...rocklaw.modes import Affine
from ..definition.links import RATE
from ..drill.chain import torsion_first_order_matrix
from ..drill.piecewise import Element, elements, undeclared
from ..drill.piston import CONTACT
from ..drill.pulse import phase_generator, phase_row
from .simulation import Simulation

MAX_ENUMERATED_MODES = 256  # mode combinations whose norms are all measured to choose h
Modes = tuple[str, ...]


@dataclass(frozen=True)
class Layout:
    """Indices into w = (x, v, rock states, [phi, phi'], 1, u1, u2) for ``n`` bodies."""

    n: int
    rock_states: int
    torsion: bool

    @property
    def angle(self) -> int:
        """phi (phi' follows); only with torsion."""
        return 2 * self.n + self.rock_states

    @property
    def one(self) -> int:
        return self.size - 3

    @property
    def size(self) -> int:
        return 2 * self.n + self.rock_states + 2 * self.torsion + 3


def balance(matrix: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(D^-1 A D, diagonal of D): LAPACK's diagonal balancing (``scipy.linalg.matrix_balance`` without
    permutation). Its 1-norm bounds the growth of the Taylor terms; it is the better conditioned
    argument of expm."""
    balanced, _, _, scale, info = dgebal(matrix, scale=1, permute=0)
    if info < 0:
        raise ValueError(f"dgebal: illegal argument {-info}")
    return balanced, scale


class Model:
    """The generated matrices, rows and resets of one simulation (module doc)."""

    def __init__(self, simulation: Simulation) -> None:
        chain, rock = simulation.dynamic_chain, simulation.rock
        self.simulation, self.impact = simulation, simulation.impact
        self.layout = layout = Layout(chain.size, len(rock.state_names), simulation.torsion is not None)
        self.pieces: tuple[Element, ...] = elements(chain, rock, layout.size)
        self.masses_kg = np.array([b.mass_kg for b in chain.bodies])
        n, m, one = layout.n, layout.size, layout.one
        base = np.zeros((m, m))
        linear = chain.first_order_matrix()
        base[:2 * n, :2 * n], base[:2 * n, one] = linear[:, :-1], linear[:, -1]
        if simulation.torsion is not None:
            torsion = torsion_first_order_matrix(simulation.torsion)
            phi = layout.angle
            base[phi:phi + 2, phi:phi + 2], base[phi:phi + 2, one] = torsion[:, :2], torsion[:, 2]
        self.base = base
        self.max_exits = sum(max(len(mode.exits) for mode in element.table.values()) for element in self.pieces)
        self.max_resets = max((len(mode.entry) for e in self.pieces for mode in e.table.values()), default=0) or 1

    def row(self, element: Element, affine: Affine) -> np.ndarray:
        """An affine function of an element's local variables as a row over w (constant on ``one``)."""
        row, constant = element.row(affine)
        row[self.layout.one] += constant
        return row

    def rock_force_row(self, modes: Modes) -> np.ndarray:
        rock = self.pieces[0]
        return self.row(rock, rock.table[modes[0]].force)

    def matrix(self, modes: Modes, phase: str) -> np.ndarray:
        """A of (modes, phase): base + each element's force along its load and its state rates + the pulse."""
        n, one = self.layout.n, self.layout.one
        matrix = self.base.copy()
        for element, mode in zip(self.pieces, modes, strict=True):
            declared = element.table[mode]
            matrix[n:2 * n] += np.outer(element.load / self.masses_kg, self.row(element, declared.force))
            for state, affine in declared.rates.items():
                matrix[element.states[state]] += self.row(element, affine)
        matrix[n + self.simulation.chain.impact_body, one:] += phase_row(self.impact, phase) \
            / self.masses_kg[self.simulation.chain.impact_body]
        matrix[one:, one:] = phase_generator(self.impact, phase)
        return matrix

    def power_forms(self, modes: Modes, phase: str) -> np.ndarray:
        """(Q_impact, Q_internal) with power = w^T Q w: the piston's F_d v_shank, and the power every link,
        the rock and the torsion line absorb, sum of F u over them (F the force row of the element in its
        mode, u its stretch rate: a link's delta', the rock's v_bit, the torsion line's omega)."""
        layout, chain = self.layout, self.simulation.dynamic_chain
        n, size = layout.n, layout.size
        string = self.simulation.chain.size  # the drill string's bodies; a piston's follow (models.drill.piston)
        pairs = []  # (force row, rate row) over w
        for link in chain.linear_links():
            if link.body_b >= string:  # the piston's own springs: not the string's
                continue
            stretch, rate = np.zeros(size), np.zeros(size)
            stretch[link.body_b], rate[n + link.body_b] = 1.0, 1.0
            if link.body_a is not None:
                stretch[link.body_a], rate[n + link.body_a] = -1.0, -1.0
            pairs.append((link.stiffness_n_per_m * stretch + link.damping_n_s_per_m * rate, rate))
        contact = None
        for element, mode in zip(self.pieces, modes, strict=True):
            if element.name == CONTACT:
                contact = self.row(element, element.table[mode].force)
                continue
            velocity = element.variables[VELOCITY if element is self.pieces[0] else RATE]
            pairs.append((self.row(element, element.table[mode].force), velocity))
        if self.simulation.torsion is not None:
            torsion, force, rate = self.simulation.torsion, np.zeros(size), np.zeros(size)
            force[layout.angle] = torsion.stiffness_n_m_per_rad
            force[layout.angle + 1], rate[layout.angle + 1] = torsion.damping_n_m_s_per_rad, 1.0
            pairs.append((force, rate))
        impact = np.zeros(size)
        impact[layout.one:] = phase_row(self.impact, phase)
        if contact is not None:  # the piston's contact pushes the impact body with -F (F > 0 pulls)
            impact = -contact
        shank = np.zeros(size)
        shank[n + chain.impact_body] = 1.0
        forces, rates = (np.array(rows) for rows in zip(*pairs, strict=True))
        internal = forces.T @ rates  # sum over the pairs of F u^T
        return 0.5 * np.stack([np.outer(impact, shank) + np.outer(shank, impact), internal + internal.T])

    def exits(self, modes: Modes) -> list[tuple[np.ndarray, int, Modes, list[tuple[int, np.ndarray]]]]:
        """(row, direction, next modes, entry resets (target index, row)) of every exit of ``modes``."""
        out = []
        for index, (element, mode) in enumerate(zip(self.pieces, modes, strict=True)):
            for switch in element.table[mode].exits:
                following = modes[:index] + (switch.next_mode,) + modes[index + 1:]
                resets = [(element.states[state], self.row(element, affine))
                          for state, affine in element.table[switch.next_mode].entry.items()]
                out.append((self.row(element, switch.surface), switch.direction, following, resets))
        return out

    def norm_candidates(self, phases: list[str]) -> list[np.ndarray]:
        """The matrices whose balanced norms choose the sub-step: every mode combination when they are
        few, else every mode of each element with the others in their first mode."""
        tables = [list(element.table) for element in self.pieces]
        if math.prod(len(t) for t in tables) <= MAX_ENUMERATED_MODES:
            combinations = list(itertools.product(*tables))
        else:
            first = tuple(t[0] for t in tables)
            combinations = [first[:i] + (mode,) + first[i + 1:] for i, t in enumerate(tables) for mode in t]
        return [self.matrix(modes, phase) for modes in combinations for phase in dict.fromkeys(phases)]


def sub_step(simulation: Simulation, phases: list[str], model: Model | None = None) -> tuple[float, int, float]:
    """(||A_bal||_1, sub-steps per sample, sub-step h) of the global sub-grid (module doc): the
    largest balanced 1-norm over the modes and the pulse ``phases``, and h = sample interval / ceil(
    sample interval x norm)."""
    model = model or Model(simulation)
    norm = max(np.linalg.norm(balance(matrix)[0], 1) for matrix in model.norm_candidates(phases))
    per_sample = max(1, math.ceil(simulation.settings.sample_interval_s * norm))
    return norm, per_sample, simulation.settings.sample_interval_s / per_sample


def unsupported(simulation: Simulation) -> str | None:
    """Why the exact formulation cannot run ``simulation``, or None: a law that declares no modes (its
    switching and matrices come from them), or an indexing share taken from the torsion line blow by
    blow into a law whose mode rows carry it (Jenkins: the crushing rates), so that its matrices would
    change at every blow."""
    undeclared_laws = undeclared(simulation.chain, simulation.rock)
    if undeclared_laws:
        return undeclared_laws
    indexing = simulation.indexing
    if indexing is not None and indexing.speed_rpm is None and simulation.rock.modes_follow_fresh_fraction:
        return (f"the {simulation.rock.name} law's crushing rates carry the indexing share of each blow, which "
                "comes from the torsion angle and changes from blow to blow, so the matrices would change at "
                "every blow; give rotation.speed_rpm (a constant share) or use the ode or exudyn formulation")
    return None
