"""Energy account of a run, from the histories at every solver step.

Balance (all terms cumulative from t = 0):
    W_impact + W_feed = dE_kinetic + dE_elastic + D_damping + W_crushing
with W_impact = int F_d v_shank dt, W_feed = sum_i F_i (x_i - x_i(0)) (+ (M_x - M_c) dphi),
E_elastic including what the rock stores, F_spring^2 / (2 k_unload) (rocklaw.base.RockLaw),
D_damping = int of every damper's power (joints, shock absorber, the rock damper, c_x), and
W_crushing the rock law's plastic work int F_spring d(x_n) (Jenkins: F_th (x_n - x_n(0))).
With wave rods (models.waves) E_elastic includes the energy of their waves in flight (kinetic and strain).
With a piston (models.drill.piston) F_d is its contact force, and the balance takes the work in from the
blows instead: W_piston = what the strikes and catches put in (blow energies less rebound energies)
less the piston's energy E_piston held at the time, from its value at the start, in place of W_impact (the two agree
when the contact's work is computed right: the balance then covers the piston too).
Items a user added to an Exudyn model enter with what they hold, dissipate and put in
(``SimulationResult.user_energy``, models.solvers.exudyn_user_items: Exudyn's masses, spring-dampers and
constant loads automatically, other items by the energy terms an extension declares); where an item is
not accounted for, the balance is not a number.
The powers are integrated by the trapezoidal rule over every stored solver step, unless the
formulation integrated the works exactly (``SimulationResult.works_j``, the exact formulation): then
W_impact is its impact work and D_damping what the links, the rock and the torsion line absorb less
what they store and crush; the balance then states that the bodies' kinetic energy changes by the
work of every force on them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...rocklaw.base import cumulative_trapezoid
from ..drill.piston import piston_energy_j
from .results import SimulationResult, UserEnergy


@dataclass
class EnergyAccount:
    """A run's energy account (``Result.energy``): cumulative works and energies [J] at every stored step.

    W_impact + W_feed = dE_kinetic + dE_elastic + D_damping + W_crushing (the module's doc says what each holds;
    with a piston W_piston in place of W_impact, with items of one's own their terms).

    Parameters
    ----------
    time_s : numpy.ndarray
        The stored steps' times.
    impact_work_j, feed_work_j : numpy.ndarray
        W_impact = int F_d v_impact dt and W_feed = sum_i F_i (x_i - x_i(0)), cumulative.
    kinetic_j, elastic_j : numpy.ndarray
        The energy held: the bodies' kinetic energy; the springs', the rock's and the waves' in flight.
    damping_j, crushing_work_j : numpy.ndarray
        What the dampers have dissipated and the rock law's plastic work, cumulative.
    piston_work_j : numpy.ndarray or None
        With a piston: what its strikes put in, less the energy it holds.
    user : UserEnergy or None
        The items of one's own of an Exudyn model: what they put in, hold and dissipate.

    Examples
    --------
    >>> import rpdrill
    >>> account = rpdrill.simulate(rpdrill.load_scene("paper_base").with_({"solver.formulation": "exact"})).energy
    >>> account.relative_residual() < 1e-6, bool(account.crushing_work_j[-1] > 0)
    (True, True)
    """

    time_s: np.ndarray
    impact_work_j: np.ndarray
    feed_work_j: np.ndarray
    kinetic_j: np.ndarray
    elastic_j: np.ndarray
    damping_j: np.ndarray
    crushing_work_j: np.ndarray
    piston_work_j: np.ndarray | None = None  # W_piston (module doc), with a piston
    user: UserEnergy | None = None  # the items a user added to an Exudyn model (module doc)

    @property
    def complete(self) -> bool:
        """Whether every item of the run is accounted for (module doc: items of one's own)."""
        return self.user is None or not self.user.unaccounted

    @property
    def residual_j(self) -> np.ndarray:
        """Work in minus energy accounted for; zero for an exact solution."""
        stored = (self.kinetic_j - self.kinetic_j[0]) + (self.elastic_j - self.elastic_j[0])
        work_in = self.impact_work_j if self.piston_work_j is None else self.piston_work_j
        residual = work_in + self.feed_work_j - stored - self.damping_j - self.crushing_work_j
        if self.user is not None:
            residual = residual + self.user.work_in_j - (self.user.stored_j - self.user.stored_j[0]) \
                - self.user.dissipated_j
        return residual

    def relative_residual(self) -> float:
        """max_t abs(``residual_j``) over the run divided by the total impact work; not a number when an item
        of one's own is not accounted for (``Result.raw.user_energy.unaccounted`` names it)."""
        if not self.complete:
            return float("nan")
        return float(np.max(np.abs(self.residual_j)) / max(self.impact_work_j[-1], 1e-300))


def impact_work_j(result: SimulationResult) -> np.ndarray:
    """W_impact = int F_d v_impact dt, cumulative at every stored step: the formulation's exact work when
    it has one, else the trapezoidal rule."""
    if result.works_j is not None:
        return result.works_j["impact"]
    return cumulative_trapezoid(result.impact_force_n * result.velocity_m_per_s[:, result.chain.impact_body],
                                result.time_s)


def energy_account(result: SimulationResult) -> EnergyAccount:
    simulation, t = result.simulation, result.time_s
    chain, rock = simulation.chain, simulation.rock
    x, v = result.position_m, result.velocity_m_per_s
    masses = np.array([b.mass_kg for b in chain.bodies])

    kinetic = 0.5 * (v**2) @ masses
    spring_force = rock.spring_force(result.bit_position_m, result.rock_states())
    link_elastic, link_damping = chain.link_energy(x, v)
    elastic = link_elastic + 0.5 * spring_force**2 / rock.unloading_stiffness_n_per_m
    if result.waves is not None:
        elastic = elastic + result.waves.energy_j
    # what the rock force does beyond its spring-slider part is dissipated in the rock damper
    damping_power = link_damping + (result.rock_force_n - spring_force) * result.bit_velocity_m_per_s
    feed = (x - x[0]) @ chain.constant_forces()
    if result.torsion_angle_rad is not None:
        tor = simulation.scene.torsion
        phi, omega = result.torsion_angle_rad, result.torsion_rate_rad_per_s
        kinetic = kinetic + 0.5 * tor.inertia_kg_m2 * omega**2
        elastic = elastic + 0.5 * tor.stiffness_n_m_per_rad * phi**2
        damping_power = damping_power + tor.damping_n_m_s_per_rad * omega**2
        feed = feed + (tor.drive_torque_n_m - tor.resisting_torque_n_m) * (phi - phi[0])
    crushing = rock.plastic_work_j(spring_force, result.bottom_m)
    if result.works_j is None:
        damping = cumulative_trapezoid(damping_power, t)
    else:  # integrated exactly by the formulation: the dampers take what the internal forces absorb and
        # neither store nor crush
        damping = result.works_j["internal"] - (elastic - elastic[0]) - (crushing - crushing[0])
    piston = None
    if result.piston is not None:
        net = result.piston.input_j - piston_energy_j(result.piston, x[:, chain.impact_body])
        piston = net - net[0]
    return EnergyAccount(time_s=t, impact_work_j=impact_work_j(result), feed_work_j=feed, kinetic_j=kinetic,
                         elastic_j=elastic, damping_j=damping, crushing_work_j=crushing, piston_work_j=piston,
                         user=result.user_energy)
