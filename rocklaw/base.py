"""The interface of a bit-rock contact law, which every formulation codes against.

A law has internal states (``state_names``; one of them, ``bottom_index``, is the borehole
bottom x_n, never decreasing) and gives the force on the bit from the bit position x, velocity v
and the state:

* pure functions, written once against :mod:`rocklaw.backends` (branching with
  ``backend.where`` only, so that Exudyn can record them): :meth:`RockLaw.force` (total, >= 0
  pushing the bit out of the hole, unless a law's damping says otherwise) and
  :meth:`RockLaw.spring_force` (its rate-independent part);
* the time-discrete state update of the Exudyn element, :meth:`RockLaw.return_map`, applied once
  per accepted step before the step; it also gives the state consistent with a static preload,
  ``return_map(x_bit0, initial_state())``;
* the piecewise-linear declaration (:mod:`rocklaw.modes`) of a law that is linear between
  switches: :meth:`RockLaw.modes` over the local variables ``position``, ``velocity``, the state
  names and ``one``, and :meth:`RockLaw.initial_mode`. The ODE and the exact formulations
  generate their events, state rates, resets and matrices from it;
* blows: ``fresh_fraction`` eta is the share of a blow's footprint on fresh rock (1 without an
  indexing model, models.drill.indexing; a law per blow when it changes, ``modes_follow_fresh_fraction``
  says whether the mode rows carry it); :meth:`RockLaw.start_blow` gives the state a blow meets, and
  ``resets_at_blows`` whether it changes anything (the formulations apply it at every blow start
  only then);
* energy: the rock stores F_spring^2 / (2 k_unload) and dissipates the plastic (crushing) work
  W_p = int F_spring d(x_n) (:meth:`RockLaw.plastic_work_j`);
* optional, ``step_update(bit_position_m, bit_velocity_m_per_s, state, step_s)``: the state after one
  Exudyn step of ``step_s`` from the bit's state at its start, for a law whose state moves at a finite
  rate (a visco-plastic slider, which ``return_map`` - no time passing - leaves where it is); the Exudyn
  element calls it instead of ``return_map`` when the law has it.

What each formulation needs (:data:`MEMBERS`, :func:`missing_members`): the Exudyn formulation everything
but the mode table; the exact and ODE formulations the mode table too (``modes``, ``initial_mode``).
A law of one's own subclasses :class:`RockLaw`; a scene names it by the name its package registers or by its
import path (``rock.law: module:Class``) where its module is allowed for the run (docs/extending.md).

Implementations: :class:`rocklaw.jenkins.JenkinsRock` (the paper's Eq. 1, 2) and
:class:`rocklaw.bilinear.BilinearRock`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any, Protocol, runtime_checkable

import numpy as np

from .backends import NUMERIC, Backend
from .modes import ModeTable

#: The internal state of a rock law: a tuple of floats, one per name of ``state_names``.
State = tuple[float, ...]
POSITION, VELOCITY = "position", "velocity"  # the bit's local variables in a law's mode table


@runtime_checkable
class RockLaw(Protocol):
    """The interface of a bit-rock contact law (module doc), which every formulation codes against.

    Lengths in m, forces in N. A law's class subclasses it (``class MyLaw(RockLaw)``; the built-in laws do): a
    scene names no other class as its ``rock.law`` (models.definition.rock). Its values are declared as
    attributes, so that a dataclass's fields, a class attribute or a property of the law give them; a method a
    law does not define stays this protocol's stub, which :func:`missing_members` counts as missing. A worked
    law of one's own: ``examples/rate_dependent_rock.py`` (docs/extending.md, "A rock law of one's own").

    Attributes
    ----------
    name : str
        The law's name (``rock.law``).
    state_names : tuple of str
        Its internal states; ``bottom_index`` is the one of the borehole bottom x_n, never decreasing.
    bottom_index : int
        The index of x_n in ``state_names``.
    crushes : bool
        Whether the rock ever gives way (False: elastic).
    loading_stiffness_n_per_m, unloading_stiffness_n_per_m : float
        k_l and k_u (equal for the Jenkins law): the energy the rock stores is F_spring^2 / (2 k_u).
    threshold_n : float
        F_th, the force at which the rock crushes (inf where it does not apply).
    damping_n_s_per_m : float
        c_n, the rock's damping (0 for none).
    crushing_penetration_m : float
        The penetration from the bottom at which crushing starts (Jenkins F_th / k_n; 0 for a law that
        indents from the first contact; inf if elastic).
    fresh_fraction : float
        eta, the share of a blow's footprint on fresh rock (1 without an indexing model).
    modes_follow_fresh_fraction, resets_at_blows : bool
        Whether the mode rows carry eta; whether :meth:`start_blow` changes the state.

    See Also
    --------
    rpdrill.rocklaw.JenkinsRock, rpdrill.rocklaw.BilinearRock : the built-in laws.

    Examples
    --------
    >>> from rpdrill import RockLaw
    >>> from rpdrill.rocklaw import JenkinsRock
    >>> law = JenkinsRock(stiffness_n_per_m=5.1e8, damping_n_s_per_m=4.9e3, threshold_n=210e3)
    >>> isinstance(law, RockLaw), law.state_names, law.initial_state()
    (True, ('bottom_m',), (0.0,))
    >>> law.force(1e-4, 0.0, law.initial_state())  # k_n x below the threshold [N]
    51000.0
    """

    name: str
    state_names: tuple[str, ...]
    bottom_index: int
    crushes: bool
    loading_stiffness_n_per_m: float
    unloading_stiffness_n_per_m: float
    threshold_n: float
    damping_n_s_per_m: float
    # Penetration from the bottom at which crushing starts: the law's length scale (Jenkins F_th / k_n; 0 for a
    # law that indents from the first contact; inf if elastic)
    crushing_penetration_m: float

    def initial_state(self) -> State:
        """The state of an untouched rock with its surface at x = 0."""
        ...

    def force(self, bit_position_m: Any, bit_velocity_m_per_s: Any, state: Sequence[Any], backend: Backend,
              fresh_fraction: Any = None) -> Any:
        """Total rock force on the bit [N], positive pushing the bit out of the hole (``fresh_fraction``:
        eta as a symbolic variable where the closed form carries it; default the law's)."""
        ...

    def spring_force(self, bit_position_m: Any, state: Sequence[Any], backend: Backend,
                     fresh_fraction: Any = None) -> Any:
        """The rate-independent part of :meth:`force` [N]."""
        ...

    def return_map(self, bit_position_m: float, state: State) -> State:
        """The state after the bit reached ``bit_position_m`` (once per step, before the step)."""
        ...

    # eta, the share of the blow's footprint on fresh rock (0 < eta <= 1)
    fresh_fraction: float
    # whether the mode rows carry eta (a new table when eta changes)
    modes_follow_fresh_fraction: bool
    # whether :meth:`start_blow` changes the state (else no formulation calls it)
    resets_at_blows: bool

    def start_blow(self, bit_position_m: float, state: State) -> State:
        """The state a blow starting now meets (applied at every blow start)."""
        ...

    def plastic_work_j(self, spring_force_n: np.ndarray, bottom_m: np.ndarray) -> np.ndarray:
        """Cumulative plastic work int F_spring d(x_n) [J] along sampled histories."""
        ...

    def modes(self) -> ModeTable:
        """The mode table (rocklaw.modes) over position, velocity, the states and one."""
        ...

    def initial_mode(self, values: Mapping[str, float]) -> str:
        """The mode of a start at these values of position, velocity and the states."""
        ...


# what every formulation needs of a law (the Exudyn element, the energy account, the metrics), and what the
# exact and ODE formulations need besides (their switching and matrices come from the mode table)
MEMBERS = ("name", "state_names", "bottom_index", "crushes", "loading_stiffness_n_per_m",
           "unloading_stiffness_n_per_m", "threshold_n", "damping_n_s_per_m", "crushing_penetration_m",
           "initial_state", "force", "spring_force", "return_map", "fresh_fraction", "modes_follow_fresh_fraction",
           "resets_at_blows", "start_blow", "plastic_work_j")
PIECEWISE_MEMBERS = ("modes", "initial_mode")


def missing_members(law: object, members: tuple[str, ...] = MEMBERS) -> list[str]:
    """The names of ``members`` that ``law`` lacks (an attribute that raises counts as missing)."""
    missing = []
    for name in members:
        try:
            found = getattr(type(law), name, None)
            getattr(law, name)
        except Exception:  # noqa: BLE001 - a property that fails is as good as absent
            missing.append(name)
            continue
        if found is not None and found is RockLaw.__dict__.get(name):  # the protocol's stub, inherited
            missing.append(name)
    return missing


def is_rock_law_class(target: object) -> bool:
    """Whether ``target`` is a class that subclasses :class:`RockLaw` (by name, not by its shape: checked
    before anything of it is constructed)."""
    return isinstance(target, type) and RockLaw in target.__mro__ and target is not RockLaw


def local_values(law: RockLaw, bit_position_m: float, bit_velocity_m_per_s: float,
                 state: Sequence[float]) -> dict[str, float]:
    """The law's local variables (position, velocity, states) as a mapping for its mode table."""
    return {POSITION: bit_position_m, VELOCITY: bit_velocity_m_per_s, **dict(zip(law.state_names, state, strict=True))}


def force_and_state(law: RockLaw, bit_position_m: float, bit_velocity_m_per_s: float,
                    state: State, backend: Backend = NUMERIC) -> tuple[float, State]:
    """One step of the time-discrete law, as the Exudyn element takes it: the state, then the force.

    state <- ``law.return_map(x, state)``, then F = ``law.force(x, v, state)``.

    Parameters
    ----------
    law : RockLaw
        The rock law.
    bit_position_m : float
        The bit position x, positive into the rock from the untouched surface.
    bit_velocity_m_per_s : float
        The bit velocity v.
    state : State
        The law's state before the step.
    backend : Backend, default NUMERIC
        How the force is evaluated (floats by default; rocklaw.backends).

    Returns
    -------
    tuple of (float, State)
        The force on the bit [N], positive pushing the bit out of the hole, and the new state.

    Examples
    --------
    >>> from rpdrill.rocklaw import TABLE_1, JenkinsRock, force_and_state
    >>> rock = TABLE_1["sandstone"]
    >>> law = JenkinsRock(rock.stiffness_n_per_m, rock.damping_n_s_per_m, rock.threshold_n)
    >>> force_n, (bottom_m,) = force_and_state(law, 1e-3, 0.0, law.initial_state())
    >>> force_n, round(bottom_m * 1e3, 4)  # crushing: F = F_th, the bottom 1 mm - F_th / k_n
    (210000.0, 0.5882)
    """
    new_state = law.return_map(bit_position_m, state)
    return law.force(bit_position_m, bit_velocity_m_per_s, new_state, backend), new_state


def cumulative_trapezoid(values: np.ndarray, x: np.ndarray) -> np.ndarray:
    """int values dx from x[0] to every x[i] by the trapezoidal rule (0 at the start), as SciPy's
    ``cumulative_trapezoid(..., initial=0)``; NumPy only, so that a worker does not import
    scipy.integrate (half a second) for it."""
    return np.concatenate(([0.0], np.cumsum(0.5 * (values[1:] + values[:-1]) * np.diff(x))))


def trapezoidal_plastic_work_j(spring_force_n: np.ndarray, bottom_m: np.ndarray) -> np.ndarray:
    """W_p = int F_spring d(x_n), trapezoidal over the samples (exact where F is linear in x_n)."""
    return cumulative_trapezoid(spring_force_n, bottom_m)
