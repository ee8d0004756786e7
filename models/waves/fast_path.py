"""The stepper's whole steps without events through the compiled kernel (models.waves.kernels): the
arrays of a key it needs (propagator, Gram matrices, exits and their slopes, the ports' velocity rows,
the kinematic bodies' force rows and impulse integral), and one call up to a stop."""

from __future__ import annotations

import numpy as np

from ..definition.links import CLOSED, OPEN
from .kernels import CATCH, PISTON_CLOSED, PISTON_NONE, PISTON_OPEN, STEPS_DONE, SWITCH, run_steps
from .levels import key_levels
from .outgoing import Segment
from .recording import Snapshot
from .system import Key


def key_arrays(stepper, key: Key) -> tuple[np.ndarray, ...]:
    """(propagator, grams, exit rows, exit slopes, port velocity rows, impulse integral, body force rows,
    impact row, each port velocity row's nonzero columns and their count) of ``key`` for a whole step, cached."""
    if "kernel" not in key.cache:
        m = key.matrix.shape[0]
        levels = key_levels(stepper, key)
        propagator, integral = levels.steps[0], levels.integral(0) if levels.impulses else None
        rows = np.array([direction * row for row, direction, *_ in key.exits]).reshape(len(key.exits), m)
        key.cache["kernel"] = (
            np.ascontiguousarray(propagator), np.ascontiguousarray(levels.gram(0)[:3]),
            np.ascontiguousarray(rows), np.ascontiguousarray(rows @ key.matrix),
            np.ascontiguousarray(key.velocity[stepper.port_nodes]).reshape(len(stepper.ports), m),
            np.zeros((m, m)) if integral is None else np.ascontiguousarray(integral),
            np.ascontiguousarray(key.body_forces), np.ascontiguousarray(stepper.impact_row(key)))
        velocity = key.cache["kernel"][4]
        counts = np.count_nonzero(velocity, axis=1).astype(np.int64)
        columns = np.zeros((len(velocity), max(int(counts.max(initial=0)), 1)), dtype=np.int64)
        for p, row in enumerate(velocity):
            columns[p, :counts[p]] = np.flatnonzero(row)
        key.cache["kernel"] = (*key.cache["kernel"], columns, counts)
    return key.cache["kernel"]


def run_constants(stepper) -> tuple[np.ndarray, np.ndarray, float, float, float]:
    """(the stepper's own ports as a mask over its ports, a wave piston's two ports, its impedance, the momentum
    and force tolerances of its rest), fixed for a run once the ports are shared out (cached on the stepper)."""
    cached = stepper.kernel_constants
    if cached is not None and cached[0] is stepper.own_ports:
        return cached[1]
    own = np.zeros(len(stepper.ports), dtype=np.bool_)
    own[stepper.own_ports] = True
    pistons, impedance = np.zeros(2, dtype=np.int64), 0.0
    if stepper.piston_rod is not None:
        pistons[:] = (2 * stepper.piston_rod, 2 * stepper.piston_rod + 1)
        impedance = stepper.chain.waves[stepper.piston_rod].impedance_n_s_per_m
    setup = stepper.setup
    momentum_tolerance = 1e-9 * setup.momentum_n_s if setup is not None else 0.0
    force_tolerance = 1e-9 * impedance * (setup.strike_velocity_m_per_s if setup is not None else 0.0)
    constants = (own, pistons, impedance, momentum_tolerance, force_tolerance)
    stepper.kernel_constants = (stepper.own_ports, constants)  # kept while the ports' shares stay
    return constants


def run_fast(stepper, stop: int) -> tuple[int, int]:
    """Whole steps from the stepper's step index up to ``stop`` (exclusive) in the kernel; (status, the
    step reached). The caller makes sure no blow start, phase change or sample falls before ``stop``."""
    key, lines, stats = stepper.key(), stepper.lines, stepper.statistics
    propagator, grams, rows, slopes, velocity, integral, forces, impact, columns, counts = key_arrays(stepper, key)
    own, pistons, impedance, momentum_tolerance, force_tolerance = run_constants(stepper)
    mode = PISTON_NONE
    if stepper.piston_rod is not None:
        contact = stepper.modes[stepper.contact]
        mode = PISTON_OPEN if contact == OPEN else PISTON_CLOSED if contact == CLOSED else PISTON_NONE
    rock = np.zeros(1)
    loads = np.zeros((2, len(forces)))
    status, reached = run_steps(
        stepper.w, stepper.step_index, stop, stepper.step_s, stepper.layout.inputs, propagator, grams, rows, slopes,
        stepper.port_nodes, velocity, columns, counts, lines.port_delays, stepper.port_signs, stepper.port_impedances,
        stepper.port_down, own, lines.left, lines.right, lines.start, lines.broken, lines.square, lines.mean,
        lines.square_sum, lines.mean_sum,
        lines.ring, stepper.works, rock, stats.compression_n[-1], stats.tension_n[-1], stats.energy_j[-1],
        stats.arriving_j[-1], integral,
        forces, loads, mode, pistons, impact, momentum_tolerance, force_tolerance, impedance, stepper.energy_weights,
        stepper.peak_states, stepper.peak_extras, stepper.peak_sides)
    for port, kind in zip(*np.nonzero(stepper.peak_sides), strict=True):  # the blow's peaks raised in these steps
        extras = stepper.peak_extras[port, kind]
        stepper.peaks.offer(int(port), int(kind), Snapshot(
            float(extras[0]), stepper.peak_states[port, kind].copy(), key, bool(stepper.peak_sides[port, kind] == 1),
            np.array([extras[1], extras[2]]), float(extras[3]), float(extras[4])))
    stepper.peak_sides[:] = 0
    stats.rock_work_j[-1] += rock[0]
    if reached > stepper.step_index and len(forces):
        stepper.body_loads = loads
    stepper.step_index = reached
    if reached > 0 and len(stepper.ports):  # the last step's arriving waves (the Exudyn bodies' ports close with them)
        a0, a1 = lines.incoming(reached - 1)[0], stepper.w[stepper.layout.inputs::2].copy()
        stepper.last_inputs = (a0, a1)
        nothing = np.zeros(len(stepper.ports))
        stepper.last_segments = [Segment(0.0, 1.0, nothing, nothing, nothing, nothing, a0, a1, nothing, nothing, False)]
    if status == CATCH and reached % stepper.period_steps == 0:  # the strike there resets the piston itself
        status = STEPS_DONE
    if status == CATCH:
        stepper.catch_wave_piston(reached)
    return status, reached


__all__ = ["SWITCH", "key_arrays", "run_constants", "run_fast"]
