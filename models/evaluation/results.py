"""What a simulation returns, whichever formulation produced it: histories at every solver step."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..definition.scene import Scene
from ..drill.chain import AxialChain
from .parts import link_series
from .rod_outputs import stress_columns
from .run_record import ExudynModelRecord, SolverRecord, SteadyStateRecord
from .wave_readings import WaveReadings, wave_readings

if TYPE_CHECKING:
    from ..drill.piston import PistonHistory
    from .prepared_run import PreparedRun


@dataclass(frozen=True)
class UserEnergy:
    """The energy of the items a user added to an Exudyn model (models.solvers.exudyn_user_items), at the
    stored steps: ``stored_j`` held (kinetic and elastic), ``dissipated_j`` and ``work_in_j`` cumulative
    from the start; ``unaccounted`` the items it has no way to account for (the balance is then not a
    number), ``accounted`` those it took in, ``declared`` the terms extensions declared."""

    stored_j: np.ndarray
    dissipated_j: np.ndarray
    work_in_j: np.ndarray
    unaccounted: tuple[str, ...] = ()
    accounted: tuple[str, ...] = ()
    declared: tuple[str, ...] = ()

    @property
    def note(self) -> str:
        """Why the energy balance is not a number, when items have no account (else empty)."""
        if not self.unaccounted:
            return ""
        return ("energy_balance_relative_error is not a number: these items of one's own have no energy account "
                "(declare their energy with model.add_energy_term, docs/extending.md)")


@dataclass
class SimulationResult:
    """State histories at the stored solver steps (rows) of one run.

    Positions and velocities are along the drilling axis, positive into the rock, one column
    per body of the simulation's chain. ``bottom_m`` is the borehole bottom x_n. ``solver``: what the
    formulation's solver did; ``steady_state``: the regime of the run (a time run unless the scene asked
    for its periodic orbit: models.runs.scene_run).
    """

    simulation: PreparedRun
    formulation: str
    time_s: np.ndarray
    position_m: np.ndarray
    velocity_m_per_s: np.ndarray
    bottom_m: np.ndarray
    solver: SolverRecord
    rock_force_n: np.ndarray | None = None  # None when no output needs forces
    impact_force_n: np.ndarray | None = None
    torsion_angle_rad: np.ndarray | None = None
    torsion_rate_rad_per_s: np.ndarray | None = None
    cpu_time_s: float = float("nan")
    steady_state: SteadyStateRecord = field(default_factory=SteadyStateRecord)
    # (time, x_n) at every change of the bottom, when the formulation records it (exact x_n
    # between stored samples); None: bottom_m is stored at every solver step
    bottom_events: tuple[np.ndarray, np.ndarray] | None = None
    # the rock law's states (samples x states, rocklaw.base.RockLaw.state_names) at the stored
    # steps; None: the formulation stored only the bottom (enough for a one-state law, Jenkins)
    rock_state_m: np.ndarray | None = None
    # cumulative works at the stored steps integrated exactly by the formulation (exact: "impact",
    # int F_d v_shank dt, and "internal", what the links, the rock and the torsion line absorb); None:
    # the energy account integrates the sampled powers
    works_j: dict[str, np.ndarray] | None = None
    # a piston scene: the piston's states, contact force (also impact_force_n), jumps and rebounds (models.drill.piston)
    piston: PistonHistory | None = None
    # an Exudyn model with items of one's own: their energy, and the user's sensors by name at the stored steps
    user_energy: UserEnergy | None = None
    user_series: dict[str, np.ndarray] = field(default_factory=dict)
    # a scene with wave rods: the rods' ends at the samples, per-blow section figures, rigid joints' forces
    # (models.waves.record.WaveRecord)
    waves: Any = None
    # the ODE2 coordinates an Exudyn model's extensions add, where a steady-state run follows them
    # (Simulation.extension_coordinates): samples x (their positions, then their velocities)
    extension_state: np.ndarray | None = None
    # an Exudyn model run with items of one's own (or by a scene of another formulation)
    exudyn_model: ExudynModelRecord | None = None
    # Exudyn's coordinates solution file written during the run (simulate(..., solution_file=...))
    solution_file: Path | None = None

    @property
    def scene(self) -> Scene:
        return self.simulation.scene

    @property
    def wave_readings(self) -> WaveReadings | None:
        """The readings along a string of wave rods (models.evaluation.wave_readings); None without wave rods."""
        return wave_readings(self)

    @property
    def chain(self) -> AxialChain:
        return self.simulation.chain

    def rock_states(self) -> tuple[np.ndarray, ...]:
        """The rock law's states as one sample array per state (the bottom alone for a one-state law)."""
        if self.rock_state_m is not None:
            return tuple(self.rock_state_m.T)
        if len(self.simulation.rock.state_names) != 1:
            raise ValueError(f"{self.formulation} result has no rock_state_m for the {self.scene.rock.law} law")
        return (self.bottom_m,)

    def bottom_at(self, times_s: np.ndarray) -> np.ndarray:
        """Borehole bottom x_n at the given times: the rock state held since its last recorded change,
        taken on by the law's return map to the bit position there (linear between stored samples). A
        crushing bit carries the bottom on between the formulation's records (Exudyn: its steps); at a
        recorded time the return map leaves the state as it is."""
        times = np.asarray(times_s, dtype=float)
        event_t, event_x = self.bottom_events or (self.time_s, self.bottom_m)
        held = event_x[np.clip(np.searchsorted(event_t, times + 1e-12, side="right") - 1, 0, len(event_x) - 1)]
        sample = np.clip(np.searchsorted(self.time_s, times + 1e-12, side="right") - 1, 0, len(self.time_s) - 1)
        law = self.simulation.rock
        states = np.column_stack(self.rock_states())[sample]
        states[:, law.bottom_index] = held
        bit = np.interp(times, self.time_s, self.bit_position_m)
        return np.array([law.return_map(float(x), tuple(map(float, state)))[law.bottom_index]
                         for x, state in zip(bit, states, strict=True)])

    @property
    def bit_position_m(self) -> np.ndarray:
        return self.position_m[:, self.chain.bit_body]

    @property
    def bit_velocity_m_per_s(self) -> np.ndarray:
        return self.velocity_m_per_s[:, self.chain.bit_body]

    def body_velocity_m_per_s(self, name: str) -> np.ndarray:
        """Velocity of the body ``name`` (the last segment of a segmented rod; a segment by its name, ``rod[0]``)."""
        return self.velocity_m_per_s[:, self.chain.index(name)]

    def body_position_m(self, name: str) -> np.ndarray:
        """Position of the body ``name`` (as :meth:`body_velocity_m_per_s`)."""
        return self.position_m[:, self.chain.index(name)]

    def columns(self) -> dict[str, np.ndarray]:
        """Named histories the scene asked for, units in the names: time, every body's position and
        velocity and every link's force and compression always (models.evaluation.parts), and the sensors
        of one's own of an Exudyn model by their names (``sensor <name>`` where a column has that name)."""
        out = {"time_s": self.time_s}
        for i, body in enumerate(self.chain.bodies):
            out[f"{body.name}_position_m"] = self.position_m[:, i]
            out[f"{body.name}_velocity_m_per_s"] = self.velocity_m_per_s[:, i]
        out.update(link_series(self.chain, self.position_m, self.velocity_m_per_s,
                               None if self.waves is None else self.waves.joint_force_n))
        out.update(stress_columns(self))
        optional = {
            "borehole_bottom_m": self.bottom_m,
            "rock_force_n": self.rock_force_n,
            "impact_force_n": self.impact_force_n,
            "torsion_angle_rad": self.torsion_angle_rad,
            "torsion_rate_rad_per_s": self.torsion_rate_rad_per_s,
        }
        if self.piston is not None:
            optional.update(piston_contact_force_n=self.piston.contact_force_n,
                            piston_velocity_m_per_s=self.piston.mean_velocity_m_per_s)
        wanted = self.simulation.outputs.timeseries
        out.update({name: values for name, values in optional.items() if name in wanted and values is not None})
        out.update({name if name not in out else f"sensor {name}": values for name, values in self.user_series.items()})
        return out

    def resampled(self, interval_s: float) -> dict[str, np.ndarray]:
        """Histories on a uniform grid of ``interval_s`` (x_n held, the rest interpolated), with wave rods also
        the samples on both sides of every front and at every blow's peaks (models.waves.recording), as recorded."""
        grid = np.arange(0.0, self.time_s[-1] + 0.5 * interval_s, interval_s)
        grid = grid[grid <= self.time_s[-1] + 1e-12]
        kept = self.waves.kept if self.waves is not None else np.zeros(0, dtype=int)
        order = np.argsort(np.concatenate([grid, self.time_s[kept]]), kind="stable")
        out = {}
        for name, values in self.columns().items():
            on_grid = self.bottom_at(grid) if name == "borehole_bottom_m" else np.interp(grid, self.time_s, values)
            out[name] = np.concatenate([on_grid, values[kept]])[order]
        out["time_s"] = np.concatenate([grid, self.time_s[kept]])[order]
        return out
