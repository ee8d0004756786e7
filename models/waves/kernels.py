"""The compiled fast path of the characteristics (models.waves.stepping): whole steps of one key in which
no element switches, on plain float arrays (numba, cached on disk).

A step is what :meth:`models.waves.stepping.Stepper.advance` does without events: the arriving waves
set as (a, b) of every port, w <- expm(A h) w, the works w^T G w, the outgoing waves stored (end value,
mean-keeping start and exact start value) with the running sums of the waves in flight, the blow's section
figures of the ports the element closes itself (from the exact values at the step's ends), and, for
kinematic bodies, the impulse and end value of their loads. The kernel returns before committing a step
into which a wave arrives with a break (models.waves.history), in which an exit function is on its
crossed side at the start or the end or crosses and returns (the slopes), and after a step whose end a
wave piston's catch condition holds; the stepper handles those in Python. Status: STEPS_DONE (reached
``stop``), SWITCH, CATCH.
"""

from __future__ import annotations

import numpy as np
from numba import njit

STEPS_DONE, SWITCH, CATCH = 0, 1, 2
PISTON_NONE, PISTON_OPEN, PISTON_CLOSED = 0, 1, 2


@njit(cache=True)
def run_steps(w, step, stop, h, inputs, propagator, grams, exits, slopes, port_nodes, port_velocity, velocity_columns,
              velocity_counts, port_delays,
              port_signs, port_impedances, port_down, own, left, right, start, broken, square, mean, square_sum,
              mean_sum, ring, works, rock_work, compression, tension, energy, arriving_energy, integral, body_forces, loads,
              piston_mode, piston_ports, impact_row, momentum_tolerance, force_tolerance, rod_impedance,
              energy_weights, peak_states, peak_extras, peak_sides):
    """Advance ``w`` from ``step`` up to ``stop`` (module doc); returns (status, the step reached). Where a port's
    largest compression or tension of the blow is raised, the state there is kept: ``peak_states`` (port, kind,
    state), ``peak_extras`` (port, kind: time, the two works, the string's and a wave piston's waves' energy,
    by ``energy_weights`` (2, ports)), ``peak_sides`` 1 at a step's start (after its arriving jump), 2 at its end."""
    m = w.shape[0]
    ports = port_nodes.shape[0]
    a0 = np.empty(ports)
    x0 = np.empty(ports)
    s0 = np.empty(ports)
    w1 = np.empty(m)
    w0 = np.empty(m)
    start_extra = np.empty(5)
    end_raised = np.zeros((ports, 2), dtype=np.bool_)
    while step < stop:
        for p in range(ports):
            if broken[p ^ 1, (step - port_delays[p]) % ring]:
                return SWITCH, step
        for p in range(ports):
            j = (step - port_delays[p]) % ring
            source = p ^ 1
            a = left[source, j]
            a0[p] = a
            w[inputs + 2 * p] = a
            w[inputs + 2 * p + 1] = (right[source, j] - a) / h
            x0[p] = w[port_nodes[p]]
        for p in range(ports):  # the exact outgoing wave at the step's start (a port's velocity row is sparse)
            velocity = 0.0
            for q in range(velocity_counts[p]):
                velocity += port_velocity[p, velocity_columns[p, q]] * w[velocity_columns[p, q]]
            s0[p] = velocity - a0[p]
        for i in range(m):
            w0[i] = w[i]
        start_extra[0], start_extra[1], start_extra[2] = step * h, works[0], works[1]
        start_extra[3], start_extra[4] = 0.0, 0.0
        for p in range(ports):
            start_extra[3] += energy_weights[0, p] * square_sum[p]
            start_extra[4] += energy_weights[1, p] * square_sum[p]
        np.dot(propagator, w, w1)  # w1 = P w in place (a slice assignment compiles a shape message: 1.8 s)
        for e in range(exits.shape[0]):
            g0 = 0.0
            g1 = 0.0
            r0 = 0.0
            r1 = 0.0
            for j in range(m):
                g0 += exits[e, j] * w[j]
                g1 += exits[e, j] * w1[j]
                r0 += slopes[e, j] * w[j]
                r1 += slopes[e, j] * w1[j]
            if g0 > 0.0 or g1 > 0.0 or (g0 < 0.0 and r0 > 0.0 and r1 < 0.0):
                return SWITCH, step
        for q in range(3):
            total = w @ (grams[q] @ w)
            if q < 2:
                works[q] += total
            else:
                rock_work[0] += total
        for b in range(body_forces.shape[0]):
            impulse = 0.0
            end = 0.0
            for i in range(m):
                moved = 0.0
                for j in range(m):
                    moved += integral[i, j] * w[j]
                impulse += body_forces[b, i] * moved
                end += body_forces[b, i] * w1[i]
            loads[0, b] = 2.0 * impulse / h - end
            loads[1, b] = end
        for i in range(m):
            w[i] = w1[i]
        k = step % ring
        raised_end = False
        end_raised[:, :] = False
        for p in range(ports):
            velocity = 0.0
            for q in range(velocity_counts[p]):
                velocity += port_velocity[p, velocity_columns[p, q]] * w[velocity_columns[p, q]]
            a1 = w[inputs + 2 * p]
            out_right = velocity - a1
            out_left = 2.0 * ((w[port_nodes[p]] - x0[p]) / h - 0.5 * (a0[p] + a1)) - out_right
            old = (step - port_delays[p]) % ring
            sq = (out_left * out_left + out_left * out_right + out_right * out_right) / 3.0
            mn = 0.5 * (out_left + out_right)
            square_sum[p] += sq - square[p, old]
            mean_sum[p] += mn - mean[p, old]
            left[p, k] = out_left
            right[p, k] = out_right
            start[p, k] = s0[p]
            broken[p, k] = 0
            square[p, k] = sq
            mean[p, k] = mn
            if own[p]:
                start_c = port_signs[p] * (s0[p] - a0[p])
                end_c = port_signs[p] * (out_right - a1)
                for kind in range(2):
                    sign = 1.0 if kind == 0 else -1.0
                    best = compression[p] if kind == 0 else tension[p]
                    if sign * start_c > best or sign * end_c > best:
                        side = 1 if sign * start_c >= sign * end_c else 2
                        if kind == 0:
                            compression[p] = max(start_c, end_c)
                        else:
                            tension[p] = -min(start_c, end_c)
                        peak_sides[p, kind] = side
                        if side == 1:
                            for i in range(m):
                                peak_states[p, kind, i] = w0[i]
                            for i in range(5):
                                peak_extras[p, kind, i] = start_extra[i]
                        else:
                            raised_end = True
                            end_raised[p, kind] = True
                            for i in range(m):
                                peak_states[p, kind, i] = w[i]
                incoming = a0[p] * a0[p] + a0[p] * a1 + a1 * a1
                outgoing = out_left * out_left + out_left * out_right + out_right * out_right
                energy[p] += port_down[p] * port_impedances[p] * h * (outgoing - incoming) / 3.0
                arriving_energy[p] += port_impedances[p] * h * incoming / 3.0
        if raised_end:  # the works and the waves' energy at the step's end, where a peak was raised there
            string_energy, piston_energy = 0.0, 0.0
            for p in range(ports):
                string_energy += energy_weights[0, p] * square_sum[p]
                piston_energy += energy_weights[1, p] * square_sum[p]
            for p in range(ports):
                for kind in range(2):
                    if end_raised[p, kind]:
                        peak_extras[p, kind, 0] = (step + 1) * h
                        peak_extras[p, kind, 1], peak_extras[p, kind, 2] = works[0], works[1]
                        peak_extras[p, kind, 3], peak_extras[p, kind, 4] = string_energy, piston_energy
        step += 1
        if piston_mode != PISTON_NONE:
            momentum = rod_impedance * h * (mean_sum[piston_ports[0]] + mean_sum[piston_ports[1]])
            if piston_mode == PISTON_OPEN and momentum <= 0.0:
                return CATCH, step
            if piston_mode == PISTON_CLOSED and abs(momentum) <= momentum_tolerance:
                force = 0.0
                for j in range(m):
                    force += impact_row[j] * w[j]
                if abs(force) <= force_tolerance:
                    return CATCH, step
    return STEPS_DONE, step


@njit(cache=True)
def _crossed(rows, w):
    """The row with the largest positive value at w, -1 if none is positive."""
    best, top = -1, 0.0
    for e in range(rows.shape[0]):
        g = 0.0
        for j in range(w.shape[0]):
            g += rows[e, j] * w[j]
        if g > top:
            best, top = e, g
    return best


@njit(cache=True)
def first_crossing(steps, rows, slopes, w0, span, levels):
    """(finest steps, exit) of the first crossing of rows . w > 0 within ``span`` finest steps from w0,
    (0, -1) if none (models.waves.levels): bisection on the levels' grid, a step refused where an exit
    crosses at its end or its slopes show a maximum inside (a crossing and its return); a maximum that
    stays below zero restarts the search after it."""
    w = steps[levels] @ w0
    crossed = _crossed(rows, w)
    if crossed >= 0:  # on its crossed side already at the start: a switch there
        return 1, crossed
    reached = 1
    while reached < span:
        limit = span
        point = w.copy()
        for j in range(1, levels + 1):
            length = 1 << (levels - j)
            while reached + length <= limit:
                trial = steps[j] @ point
                refused = _crossed(rows, trial) >= 0
                for e in range(rows.shape[0]):
                    if refused:
                        break
                    g = 0.0
                    s0 = 0.0
                    s1 = 0.0
                    for i in range(point.shape[0]):
                        g += rows[e, i] * point[i]
                        s0 += slopes[e, i] * point[i]
                        s1 += slopes[e, i] * trial[i]
                    refused = s0 > 0.0 and s1 < 0.0 and g < 0.0
                if refused:
                    limit = reached + length
                    break
                point = trial
                reached += length
        crossed = _crossed(rows, steps[levels] @ point)
        if crossed >= 0:
            return reached + 1, crossed
        if limit >= span:
            return 0, -1
        w = w0.copy()
        for j in range(levels + 1):
            if (limit >> (levels - j)) & 1:
                w = steps[j] @ w
        reached = limit
    return 0, -1


@njit(cache=True)
def envelope(start, right, top, bottom, ring, first, stop, delay, stations, impedance):
    """The largest compression and tension (a positive number) at each station j (steps from the top) of one rod
    over steps ``first`` .. ``stop`` - 1, and the steps where: P(x_j, t) = Z (d(t - j h) - u(t - (N - j) h)), d the
    wave leaving its top, u its bottom's, at each step's start (exact values ``start``) and end (``right``)."""
    count = stations.shape[0]
    largest = np.zeros(count)
    lowest = np.zeros(count)
    at_largest = np.full(count, -1)
    at_lowest = np.full(count, -1)
    for s in range(count):
        j = stations[s]
        down = (first - j) % ring
        up = (first - delay + j) % ring
        high, low, at_high, at_low = 0.0, 0.0, -1, -1
        for k in range(first, stop):
            value = start[top, down] - start[bottom, up]
            other = right[top, down] - right[bottom, up]
            if other > value:
                value, other = other, value
            if value > high:  # value the larger of the two, other the smaller
                high, at_high = value, k
            if -other > low:
                low, at_low = -other, k
            down += 1
            up += 1
            if down == ring:
                down = 0
            if up == ring:
                up = 0
        largest[s], at_largest[s] = impedance * high, at_high
        lowest[s], at_lowest[s] = impedance * low, at_low
    return largest, at_largest, lowest, at_lowest
