"""The exact formulation of a scene with wave rods: the characteristics at the run's wave step
(models.waves.stepping) with every body, face and element integrated exactly between the grid times,
as a :class:`~rpdrill.models.evaluation.results.SimulationResult`.

The works (impact work and what the string's links, rock, torsion line and rods absorb) are integrated
over every piece of every step by the trapezoidal rule on its ends (second order in the step); the
energy account (models.evaluation.energy) takes them, with the energy of the waves in flight as stored
energy.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np
from threadpoolctl import ThreadpoolController

from ..drill.piston import PistonHistory
from ..evaluation.results import SimulationResult
from ..evaluation.run_record import WaveSolverRecord
from .history import transit_errors
from .record import WaveRecord
from .stepping import Stepper

BLAS = ThreadpoolController()


def simulate(simulation, progress: Callable[[float], None] | None = None) -> SimulationResult:
    """Run ``simulation`` (a prepared scene with wave rods) in the exact formulation (module doc)."""
    settings = simulation.settings
    start = time.process_time()
    with BLAS.limit(limits=1, user_api="blas"):  # small matrices: threads cost more than they save
        stepper = Stepper(simulation, settings.wave_step_s, settings.sample_interval_s)
        stepper.run()
    cpu = time.process_time() - start
    if progress is not None:
        progress(settings.end_time_s)
    return result(stepper, "exact", cpu)


def result(stepper: Stepper, formulation: str, cpu_s: float, coordinates: int | None = None) -> SimulationResult:
    """The run's result from the stepper's samples (module doc)."""
    simulation, layout, samples = stepper.simulation, stepper.layout, stepper.samples
    order = samples.order()  # a blow's peaks are recorded once it is done (models.waves.recording)
    time_s = np.array(samples.time_s)[order]
    states, velocity = np.array(samples.states)[order], np.array(samples.velocity)[order]
    forces, works = np.array(samples.forces)[order], np.array(samples.works)[order]
    string = simulation.chain.size
    rock_states = states[:, layout.rock:layout.rock + layout.rock_states]
    piston = None if stepper.setup is None else _piston(stepper, time_s, states, velocity, forces[:, 1])
    chain = stepper.chain
    record = WaveRecord(
        rods=chain.waves, ports=tuple((chain.waves[p.rod].name, p.end) for p in stepper.ports),
        step_s=stepper.step_s, transit_errors=transit_errors(chain.waves, stepper.step_s),
        compression_n=np.array(samples.compression).reshape(len(time_s), len(stepper.ports))[order],
        **{f"blow_{name}": value for name, value in stepper.statistics.arrays(len(stepper.ports)).items()},
        envelopes=stepper.statistics.envelopes, gauges=stepper.statistics.gauges,
        energy_j=np.array(samples.waves_j)[order], kept=np.flatnonzero(np.array(samples.kept, dtype=bool)[order]),
        joint_force_n={name: forces[:, 2 + i] for i, name in enumerate(stepper.rigid_names)})
    return SimulationResult(
        simulation=simulation, formulation=formulation, time_s=time_s,
        position_m=states[:, :string], velocity_m_per_s=velocity[:, :string],
        bottom_m=rock_states[:, simulation.rock.bottom_index], rock_state_m=rock_states,
        rock_force_n=forces[:, 0], impact_force_n=forces[:, 1],
        torsion_angle_rad=states[:, layout.angle] if layout.torsion else None,
        torsion_rate_rad_per_s=states[:, layout.angle + 1] if layout.torsion else None,
        cpu_time_s=cpu_s, works_j={"impact": works[:, 0], "internal": works[:, 1]},
        solver=WaveSolverRecord(samples=len(time_s), mode_switches=len(stepper.switch_times),
                                switch_times_s=np.array(stepper.switch_times), wave_step_s=stepper.step_s,
                                transit_time_errors=record.transit_errors, keys=len(stepper.system.keys),
                                coordinates=coordinates,
                                fresh_fractions=tuple(stepper.blows.fresh_fractions) if stepper.blows else ()),
        piston=piston, waves=record)


def _piston(stepper: Stepper, time_s: np.ndarray, states: np.ndarray, velocity: np.ndarray,
            contact_force_n: np.ndarray) -> PistonHistory:
    setup, jumps = stepper.setup, stepper.jumps
    order = stepper.samples.order()
    after = np.array(stepper.samples.after)[order]  # a strike at a blow start comes after the sample there
    energy = None
    if stepper.piston_rod is not None:
        energy = np.array(stepper.samples.piston_j)[order]
    return PistonHistory(setup, states[:, setup.bodies], velocity[:, setup.bodies], contact_force_n,
                         jumps.input_j(time_s, after), np.array(jumps.rebounds).reshape(-1, 3), energy)
