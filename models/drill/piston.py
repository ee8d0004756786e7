"""The hammer's piston as a body striking the impact body (issue #31), beside the paper's prescribed
force pulse (models.drill.pulse), for every formulation.

The piston (scene ``impact.piston``: a rigid mass or a segmented rod, models.definition.scene.Piston) is a set
of lumped bodies outside the drill string proper, appended after the string's bodies in the
*dynamic chain* the formulations integrate (:meth:`PistonSetup.dynamic_chain`): a rod piston's
segments joined by springs E A N / L like the string's rods, its front segment joined to the
impact body by a compression-only coupling (PistonContact, a models.definition.links.Coupling: gap 0, undamped) of stiffness
k: the faces' contact stiffness k_c in series with the half-segments behind the two faces
(:func:`contact_coupling_n_per_m`; a rod's faces are massless, its masses at the segments' centres, so
a contact far stiffer than a segment does not trap the face's mass between two stiff springs). The
contact force on the impact body is F_c = k max(x_front - x_impact, 0).

Each blow is two state jumps at located times, the same in every formulation:

* strike, at every blow start t_k = k / f: every piston segment placed just touching the impact
  body (x_i = x_impact, unstressed) and moving at the strike speed v_p (the blow energy
  E_blow = m_p v_p^2 / 2 put in);
* catch, when the contact is open and the piston moves back (its mean velocity below 0): the hammer
  catches it and holds it away (x_i = x_impact - PARK_M, v_i = 0) until the next strike; the energy
  it still has (kinetic and strain; the contact spring is relaxed) is the blow's rebound energy, its
  velocity v_after. A piston that goes on forward after a separation strikes again, as a free piston
  would (the struck face may run ahead of it for a moment); a piston still out at the next
  blow start is reset there (its energy counted as rebound). (PistonContact: the catch as a mode.)

Energy: the piston subsystem (its bodies, its springs, the contact spring) has the energy
E_p = sum m_i v_i^2 / 2 + sum k_i (x_i+1 - x_i)^2 / 2 + k max(x_front - x_impact, 0)^2 / 2; the jumps
put in E_blow - E_p(before) at a strike and take out E_p at a catch; what it gives the string is the
contact's work int F_c v_impact dt (the string's W_impact, models.evaluation.energy), so that

    input(t) = sum of the jumps' energies up to t = int F_c v_impact dt + E_p(t) - E_p(0).

Closed forms it is checked against (tests/test_piston.py, benchmarks/bench_piston.py): a rigid
piston on a long rod of impedance Z = A sqrt(E rho) sends F = Z v_p exp(-Z t / m_p); a rod piston of
the rod's cross-section and material sends a rectangular pulse Z v_p / 2 for 2 L_p / c and keeps no
energy (de Saint-Venant; Lundberg).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace

import numpy as np

from ...rocklaw.modes import ONE, Mode, ModeTable, Switch
from ..definition.drill_string import Body
from ..definition.links import CLOSED, OPEN, STRETCH, Coupling, Link
from ..definition.scene import Piston, Scene
from .chain import AxialChain, ChainBody

PISTON = "piston"
CONTACT = "piston_contact"
# where a caught piston is held: this far behind the impact body (no drill string moves back a metre
# within one blow period, so it never touches the shank before the next strike)
PARK_M = 1.0


CAUGHT = "caught"
PISTON_VELOCITY, IMPACT_POSITION = "piston_velocity", "impact_position"  # the contact's extra local variables


@dataclass(frozen=True)
class PistonContact(Coupling):
    """The piston's contact (an undamped coupling, gap 0) with the catch as its third mode, for the
    formulations that take their switching from mode tables (the ODE, the exact solver):

    * ``open``: F = 0 until the closure x_impact - x_front falls through 0 (``closed``), or the piston's
      mean velocity falls through 0 (``caught``; entered open while moving back, it is caught at once);
    * ``closed``: F = k_c (x_impact - x_front) until the closure rises through 0;
    * ``caught``: F = 0, no exit; on entry every piston body x_i = x_impact - PARK_M, v_i = 0.

    The strike (a blow start) puts it back to ``closed`` (models.drill.piston.PistonSetup.strike)."""

    piston_bodies: tuple[int, ...] = ()
    park_m: float = PARK_M

    def placed(self, bodies: int, size: int) -> tuple[dict[str, np.ndarray], dict[str, int]]:
        """The piston's mean velocity and the impact body's position; the piston's coordinates as states."""
        velocity, position = np.zeros(size), np.zeros(size)
        velocity[[bodies + i for i in self.piston_bodies]] = 1.0 / len(self.piston_bodies)
        position[self.body_b] = 1.0
        states = {f"x{j}": i for j, i in enumerate(self.piston_bodies)}
        states.update({f"v{j}": bodies + i for j, i in enumerate(self.piston_bodies)})
        return {PISTON_VELOCITY: velocity, IMPACT_POSITION: position}, states

    def modes(self) -> ModeTable:
        closure = {STRETCH: 1.0}
        parked = {f"x{j}": {IMPACT_POSITION: 1.0, ONE: -self.park_m} for j in range(len(self.piston_bodies))}
        parked.update({f"v{j}": {} for j in range(len(self.piston_bodies))})
        return {OPEN: Mode({}, (Switch(closure, -1, CLOSED), Switch({PISTON_VELOCITY: 1.0}, -1, CAUGHT))),
                CLOSED: Mode({STRETCH: self.stiffness_n_per_m}, (Switch(closure, 1, OPEN),)),
                CAUGHT: Mode({}, (), entry=parked)}

    def initial_mode(self, values: Mapping[str, float]) -> str:
        """Closed in compression, caught when held away (half the parking distance or more), else open."""
        closure = values[STRETCH]
        return CLOSED if closure < 0 else CAUGHT if closure >= 0.5 * self.park_m else OPEN


def contact_coupling_n_per_m(piston: Piston, struck: Body) -> float | None:
    """The spring between the two lumped bodies either side of the contact: the faces' contact
    stiffness k_c (``piston.contact_stiffness_n_per_m``; rigid faces when not given) in series with the
    half-segments behind the faces (a rod's lumped masses sit at its segments' centres, its faces are
    massless): 1/k = 1/k_c + L_p / (2 E_p A_p N_p) + L_s / (2 E_s A_s N_s) (a rigid body adds no
    half-segment). None when nothing is compliant (a rigid piston on a rigid body, k_c not given)."""
    compliance = piston.half_segment_compliance_m_per_n() + struck.half_segment_compliance_m_per_n()
    if piston.contact_stiffness_n_per_m is not None:
        compliance += 1.0 / piston.contact_stiffness_n_per_m
    return 1.0 / compliance if compliance > 0 else None


def impedance_n_s_per_m(body: Body) -> float:
    """Z = A sqrt(E rho) of a rod."""
    return body.area_m2 * math.sqrt(body.youngs_modulus_pa * body.density_kg_per_m3)


def rigid_piston_pulse_n(time_s: np.ndarray, mass_kg: float, velocity_m_per_s: float, impedance_n_s_per_m: float,
                         contact_stiffness_n_per_m: float = math.inf) -> np.ndarray:
    """The force a rigid piston m_p striking at v_p sends into a long rod of impedance Z through a contact
    spring k: F'' + (k / Z) F' + (k / m_p) F = 0, F(0) = 0, F'(0) = k v_p (overdamped for k > 4 Z^2 / m_p);
    without a contact spring (k infinite) de Saint-Venant's F = Z v_p exp(-Z t / m_p)."""
    z, m = impedance_n_s_per_m, mass_kg
    if math.isinf(contact_stiffness_n_per_m):
        return z * velocity_m_per_s * np.exp(-z * np.asarray(time_s) / m)
    a, b = contact_stiffness_n_per_m / z, contact_stiffness_n_per_m / m
    if a * a <= 4 * b:
        raise ValueError(f"contact stiffness {contact_stiffness_n_per_m:g} N/m: not overdamped (needs > 4 Z^2 / m_p)")
    root = math.sqrt(a * a - 4 * b)
    fast, slow = (-a - root) / 2, (-a + root) / 2
    return contact_stiffness_n_per_m * velocity_m_per_s * (np.exp(slow * time_s) - np.exp(fast * time_s)) / root


@dataclass(frozen=True)
class PistonSetup:
    """The piston of a run (module doc): its lumped bodies, appended at ``first`` .. ``first + segments
    - 1`` of the dynamic chain (the front last), its internal spring, the contact and the strike."""

    scene_piston: Piston
    first: int  # the piston's first (rear) body in the dynamic chain = the drill string's size
    impact_body: int  # the struck body (the impact body's first segment)
    segment_mass_kg: float
    segment_stiffness_n_per_m: float  # E A N / L between the segments (unused for a rigid piston)
    contact_stiffness_n_per_m: float  # the coupling across the contact (contact_coupling_n_per_m)
    strike_velocity_m_per_s: float
    pulse_duration_s: float  # the contact time the step of a fixed-step solver must resolve (estimate)

    @property
    def segments(self) -> int:
        return self.scene_piston.segments

    @property
    def mass_kg(self) -> float:
        return self.segment_mass_kg * self.segments

    @property
    def blow_energy_j(self) -> float:
        """E_blow = m_p v_p^2 / 2."""
        return 0.5 * self.mass_kg * self.strike_velocity_m_per_s**2

    @property
    def bodies(self) -> slice:
        """The piston's bodies in the dynamic chain's state vectors."""
        return slice(self.first, self.first + self.segments)

    @property
    def front(self) -> int:
        return self.first + self.segments - 1

    def contact_link(self) -> PistonContact:
        """The compression-only contact: stretch x_impact - x_front, closed below 0."""
        return PistonContact(CONTACT, self.front, self.impact_body, self.contact_stiffness_n_per_m, 0.0, gap_m=0.0,
                             piston_bodies=tuple(range(self.first, self.front + 1)))

    def internal_links(self) -> tuple[Link, ...]:
        return tuple(Link(f"{PISTON}[{i}-{i + 1}]", self.first + i, self.first + i + 1,
                          self.segment_stiffness_n_per_m, 0.0) for i in range(self.segments - 1))

    def dynamic_chain(self, chain: AxialChain) -> AxialChain:
        """The drill string's chain with the piston's bodies appended (no feed on them), its springs and
        the contact: what the formulations integrate."""
        names = [PISTON] if self.segments == 1 else [f"{PISTON}[{i}]" for i in range(self.segments)]
        bodies = chain.bodies + tuple(ChainBody(name, self.segment_mass_kg, 0.0) for name in names)
        return replace(chain, bodies=bodies, links=chain.links + self.internal_links() + (self.contact_link(),),
                       groups={**chain.groups, PISTON: (self.first, self.front)})

    def contact_force_n(self, position_m: np.ndarray) -> np.ndarray:
        """F_c = k_c max(x_front - x_impact, 0) for (..., bodies) positions of the dynamic chain."""
        closure = position_m[..., self.front] - position_m[..., self.impact_body]
        return self.contact_stiffness_n_per_m * np.maximum(closure, 0.0)

    def mean_velocity_m_per_s(self, velocity_m_per_s: np.ndarray) -> np.ndarray:
        """The piston's momentum over its mass (its centre of mass' velocity)."""
        return np.mean(velocity_m_per_s[..., self.bodies], axis=-1)

    def energy_j(self, position_m: np.ndarray, velocity_m_per_s: np.ndarray) -> np.ndarray:
        """E_p: the piston's kinetic and strain energy and the contact spring's (module doc)."""
        kinetic = 0.5 * self.segment_mass_kg * np.sum(velocity_m_per_s[..., self.bodies] ** 2, axis=-1)
        strain = 0.5 * self.segment_stiffness_n_per_m * np.sum(np.diff(position_m[..., self.bodies], axis=-1) ** 2,
                                                                axis=-1)
        contact = self.contact_force_n(position_m) ** 2 / (2.0 * self.contact_stiffness_n_per_m)
        return kinetic + strain + contact

    def strike(self, position_m: np.ndarray, velocity_m_per_s: np.ndarray) -> None:
        """The strike (module doc), in place on a state of the dynamic chain."""
        position_m[self.bodies] = position_m[self.impact_body]
        velocity_m_per_s[self.bodies] = self.strike_velocity_m_per_s

    def caught(self, position_m: np.ndarray, velocity_m_per_s: np.ndarray) -> bool:
        """Whether the hammer catches the piston now: the contact open and the piston moving back."""
        return bool(position_m[self.front] < position_m[self.impact_body]
                    and self.mean_velocity_m_per_s(velocity_m_per_s) < 0.0)

    def catch(self, position_m: np.ndarray, velocity_m_per_s: np.ndarray) -> None:
        """The catch (module doc), in place on a state of the dynamic chain."""
        position_m[self.bodies] = position_m[self.impact_body] - PARK_M
        velocity_m_per_s[self.bodies] = 0.0

    def parked(self, position_m: np.ndarray) -> np.ndarray:
        """Positions of the dynamic chain with the piston held away from the string's ``position_m``."""
        return np.concatenate([position_m, np.full(self.segments, position_m[self.impact_body] - PARK_M)])


def piston_setup(scene: Scene, chain: AxialChain) -> PistonSetup | None:
    """The piston of ``scene`` (None for a prescribed pulse); ValueError when the contact stiffness
    cannot be derived (a rigid piston on a rigid impact body)."""
    piston = scene.impact.piston
    if piston is None:
        return None
    struck = scene.drill_string.bodies[scene.drill_string.impact_body]
    stiffness = contact_coupling_n_per_m(piston, struck)
    if stiffness is None:
        raise ValueError("a rigid piston striking a rigid impact body: give impact.piston.contact_stiffness_n_per_m "
                         "(without it the faces are rigid and only a rod's half-segments are compliant)")
    n = piston.segments
    if piston.is_rod:
        duration = 2.0 * piston.length_m / piston.wave_speed_m_per_s
        segment_stiffness = piston.youngs_modulus_pa * piston.area_m2 * n / piston.length_m
    elif struck.is_rod:
        duration, segment_stiffness = piston.total_mass_kg / impedance_n_s_per_m(struck), 0.0
    else:  # a mass on a mass through the contact spring: half a period of the pair
        shank = chain.bodies[chain.impact_body].mass_kg
        reduced = piston.total_mass_kg * shank / (piston.total_mass_kg + shank)
        duration, segment_stiffness = math.pi * math.sqrt(reduced / stiffness), 0.0
    return PistonSetup(piston, chain.size, chain.impact_body, piston.total_mass_kg / n, segment_stiffness, stiffness,
                       piston.strike_velocity_m_per_s, duration)


@dataclass
class PistonJumps:
    """The strikes and catches of one run (module doc), logged as (time, kind, the piston's energy E_p
    and mean velocity just before the jump) in any order (the exact formulation adds its catches after
    the run): ``events`` (time, energy put in: E_blow - E_p at a strike, -E_p at a catch) and
    ``rebounds`` (blow start, rebound energy, the piston's velocity v_after when the blow ended) of every
    blow that ended, a blow ending at its catch or, uncaught, at the next strike."""

    setup: PistonSetup
    log: list[tuple[float, str, float, float]] = field(default_factory=list)
    rows: list[int] = field(default_factory=list)  # per log entry, the first sample after it (if known)
    caught: bool = True  # no blow before the first strike

    def _note(self, time_s: float, kind: str, position_m: np.ndarray, velocity_m_per_s: np.ndarray,
              row: int | None) -> None:
        self.log.append((time_s, kind, float(self.setup.energy_j(position_m, velocity_m_per_s)),
                         float(self.setup.mean_velocity_m_per_s(velocity_m_per_s))))
        if row is not None:
            self.rows.append(row)

    def strike(self, time_s: float, position_m: np.ndarray, velocity_m_per_s: np.ndarray,
               row: int | None = None) -> None:
        """The strike at a blow start, in place on a state of the dynamic chain; ``row`` the first sample
        after it, where the formulation knows it (:meth:`input_by_row`)."""
        self._note(time_s, "strike", position_m, velocity_m_per_s, row)
        self.setup.strike(position_m, velocity_m_per_s)
        self.caught = False

    def noted_catch(self, time_s: float, position_m: np.ndarray, velocity_m_per_s: np.ndarray,
                    row: int | None = None) -> None:
        """A catch that the formulation applies itself (the contact's mode table: PistonContact)."""
        self._note(time_s, "catch", position_m, velocity_m_per_s, row)
        self.caught = True

    def catch(self, time_s: float, position_m: np.ndarray, velocity_m_per_s: np.ndarray) -> None:
        """The catch, in place on a state of the dynamic chain."""
        self.noted_catch(time_s, position_m, velocity_m_per_s)
        self.setup.catch(position_m, velocity_m_per_s)

    def _ordered(self) -> list[tuple[float, str, float, float]]:
        return sorted(self.log, key=lambda entry: entry[0])

    @property
    def events(self) -> list[tuple[float, float]]:
        blow = self.setup.blow_energy_j
        return [(t, blow - energy if kind == "strike" else -energy) for t, kind, energy, _ in self._ordered()]

    @property
    def rebounds(self) -> list[tuple[float, float, float]]:
        rows, start = [], None
        for t, kind, energy, velocity in self._ordered():
            if start is not None:  # the blow in progress ends here
                rows.append((start, energy, velocity))
            start = t if kind == "strike" else None
        return rows

    def input_by_row(self, samples: int) -> np.ndarray:
        """The energy the jumps put in up to each of ``samples`` samples, from the first sample after each
        jump (every jump noted with its ``row``)."""
        blow = self.setup.blow_energy_j
        put_in = np.zeros(samples + 1)
        for (_, kind, energy, _), row in zip(self.log, self.rows, strict=True):
            put_in[row] += blow - energy if kind == "strike" else -energy
        return np.cumsum(put_in[:samples])

    def input_j(self, time_s: np.ndarray, after: np.ndarray) -> np.ndarray:
        """The energy the jumps put in up to each sample: ``after[i]`` True where sample i lies after
        the jumps at its own time (a formulation that records both sides of a jump)."""
        if not self.log:
            return np.zeros(len(time_s))
        times, energies = np.array(self.events).T
        cumulative = np.concatenate([[0.0], np.cumsum(energies)])
        before = np.searchsorted(times, time_s, side="left")
        upto = np.searchsorted(times, time_s, side="right")
        return cumulative[np.where(after, upto, before)]


@dataclass
class PistonHistory:
    """What a run of a piston scene records of the piston, at the result's samples: its bodies'
    positions and velocities, the contact force on the impact body, the energy the strikes and catches
    put in up to each sample (:meth:`PistonJumps.input_j`), and (blow start, rebound energy, v_after)
    rows."""

    setup: PistonSetup
    position_m: np.ndarray
    velocity_m_per_s: np.ndarray
    contact_force_n: np.ndarray
    input_j: np.ndarray
    rebounds: np.ndarray

    @property
    def mean_velocity_m_per_s(self) -> np.ndarray:
        return np.mean(self.velocity_m_per_s, axis=1)


def piston_history(setup: PistonSetup, jumps: PistonJumps, time_s: np.ndarray, position_m: np.ndarray,
                   velocity_m_per_s: np.ndarray, after: np.ndarray | None) -> PistonHistory:
    """The piston's history from the dynamic chain's sampled states (samples x bodies); ``after`` for
    :meth:`PistonJumps.input_j`, None when every jump was noted with its row."""
    put_in = jumps.input_by_row(len(time_s)) if after is None else jumps.input_j(time_s, after)
    return PistonHistory(setup, position_m[:, setup.bodies], velocity_m_per_s[:, setup.bodies],
                         setup.contact_force_n(position_m), put_in,
                         np.array(jumps.rebounds).reshape(-1, 3))


def piston_energy_j(history: PistonHistory, impact_position_m: np.ndarray) -> np.ndarray:
    """E_p at the samples of a history (module doc), from the piston's states and the impact body's
    position."""
    setup = history.setup
    positions = np.column_stack([np.zeros((len(impact_position_m), setup.first)), history.position_m])
    positions[:, setup.impact_body] = impact_position_m
    velocities = np.column_stack([np.zeros((len(impact_position_m), setup.first)), history.velocity_m_per_s])
    return setup.energy_j(positions, velocities)
