"""An independent method-of-characteristics solution of wave-rod drills, for the tests (not the model's code).

d'Alembert: in a uniform rod of impedance Z and transit time T the velocity at an end is the sum of the wave
arriving there and the wave leaving, v = w_in + w_out, the rod pushes its end face along +x with Z (2 w_in - v),
and a wave arrives at one end T after it left the other. A drill is rods and *junctions*: what sits between rod
ends (a rigid piston on a face, a rod piston's contact, a rigid or sprung joint, a bit and the rock). Every
junction is a small ODE (massless faces by their force balance) driven by the waves arriving at its ports.

The solution is the method of steps of this neutral delay system: time advances in chunks no longer than the
shortest transit time, so that every arriving wave over a chunk left before it; each junction is integrated over
the chunk by SciPy's DOP853 (or Radau) at tolerances near round-off, every switch (a contact opening or closing,
the rock's loading and unloading, a catch) an event located by the integrator, and a wave arriving with a jump
is a hard break of the integration. The waves leaving are stored as adaptive Chebyshev interpolants between
breaks, so that evaluating one never recurses into the history. Exact up to the integrator's tolerance: no grid,
no rounding of transit times.
"""

from __future__ import annotations

import bisect
import itertools
import math
from dataclasses import dataclass, field

import numpy as np
from numpy.polynomial import chebyshev
from scipy.integrate import solve_ivp

RTOL, ATOL = 1e-12, 1e-16
# how far an event function goes beyond zero before it counts as crossed (by what it measures)
TOLERANCE = {"gap": 1e-15, "speed": 1e-13, "force": 1e-6}
SIDE_S = 1e-14  # "just before" and "just after" a break: this far from it
MERGE_S = 1e-12  # breaks closer than this are one (a time reached two ways)
DEGREE = 24


@dataclass
class Piece:
    """One stretch [start, end) of a wave as a Chebyshev series (``coefficients`` on [start, end])."""

    start: float
    end: float
    coefficients: np.ndarray
    hard: bool  # a break at ``start`` the receiver must not integrate across (a jump or a kink)

    def __call__(self, t):
        x = (2.0 * np.asarray(t, dtype=float) - self.start - self.end) / (self.end - self.start)
        return chebyshev.chebval(x, self.coefficients)


@dataclass
class Wave:
    """The wave leaving one port over time: pieces in order (constant ``initial`` before the first)."""

    initial: float = 0.0
    pieces: list[Piece] = field(default_factory=list)
    starts: list[float] = field(default_factory=list)

    def add(self, piece: Piece) -> None:
        self.pieces.append(piece)
        self.starts.append(piece.start)

    def truncate(self, time_s: float) -> None:
        """Drop what was stored from ``time_s`` on (a piston's waves replaced at its strike)."""
        keep = bisect.bisect_left(self.starts, time_s - 1e-18)
        del self.pieces[keep:], self.starts[keep:]
        if self.pieces and self.pieces[-1].end > time_s:
            last = self.pieces[-1]
            self.pieces[-1] = fit(last, last.start, time_s, last.hard)

    def __call__(self, t, side: int = 1):
        """The wave at the times t (side +1: just after a break there, -1: just before)."""
        times = np.atleast_1d(np.asarray(t, dtype=float)) + side * SIDE_S
        index = np.searchsorted(self.starts, times, side="right") - 1
        out = np.full(len(times), self.initial)
        for i in np.unique(index[index >= 0]):
            mask = index == i
            out[mask] = self.pieces[i](times[mask])
        return out if np.ndim(t) else float(out[0])

    def breaks(self, start: float, end: float) -> list[float]:
        """Hard breaks in (start, end)."""
        first = bisect.bisect_right(self.starts, start)
        last = bisect.bisect_left(self.starts, end)
        return [p.start for p in self.pieces[first:last] if p.hard]

    def function(self, start: float, end: float):
        """A vectorised function of the wave on [start, end] (one stretch between hard breaks)."""
        first = max(bisect.bisect_right(self.starts, start + MERGE_S) - 1, 0)  # a break at the start: after it
        last = bisect.bisect_left(self.starts, end - MERGE_S)
        pieces = self.pieces[first:last] if self.pieces else []
        if not pieces or pieces[0].start > start + MERGE_S:
            initial = self.initial
            lead = [Piece(-math.inf, pieces[0].start if pieces else math.inf, np.array([initial]), False)]
            pieces = lead + pieces
        bounds = [p.start for p in pieces[1:]]

        def value(t):
            t = np.atleast_1d(np.asarray(t, dtype=float))
            out = np.empty_like(t)
            where = np.searchsorted(bounds, t, side="right")
            for i in np.unique(where):
                piece, mask = pieces[i], where == i
                out[mask] = piece.coefficients[0] if math.isinf(piece.start) else piece(t[mask])
            return out
        return value


def fit(function, start: float, end: float, hard: bool, scale: float = 1.0) -> Piece:
    """``function`` on [start, end] as a Chebyshev series of DEGREE (the pieces it is split into are returned
    through :func:`fit_pieces`; this is one piece, no check)."""
    if isinstance(function, Piece):
        source = function
        function = source
    coefficients = chebyshev.chebinterpolate(
        lambda x: np.asarray(function(0.5 * (start + end) + 0.5 * (end - start) * x), dtype=float), DEGREE)
    return Piece(start, end, coefficients, hard)


def fit_pieces(function, start: float, end: float, hard: bool, scale: float, depth: int = 0) -> list[Piece]:
    """``function`` on [start, end] as Chebyshev pieces accurate to 1e-12 of ``scale`` (halved until they are)."""
    piece = fit(function, start, end, hard)
    probe = start + (end - start) * np.array([0.013, 0.29, 0.517, 0.71, 0.987])
    error = np.max(np.abs(piece(probe) - np.asarray(function(probe), dtype=float)))
    if error <= 1e-12 * scale or depth > 24 or end - start < 1e-13:
        return [piece]
    middle = 0.5 * (start + end)
    return fit_pieces(function, start, middle, hard, scale, depth + 1) + \
        fit_pieces(function, middle, end, False, scale, depth + 1)


@dataclass
class Rod:
    """A uniform rod: impedance Z = A sqrt(E rho), transit time T = L / c; ports 2 r (top) and 2 r + 1 (bottom)."""

    impedance: float
    transit: float
    initial_top: float = 0.0  # the waves leaving each end before the start (a preload: +-P / 2Z)
    initial_bottom: float = 0.0


class Junction:
    """What sits at some rod ends (module doc): ``ports`` (port index, impedance); subclasses give the ODE."""

    method = "DOP853"
    ports: list[int]
    impedances: list[float]

    def rhs(self, t: float, y: np.ndarray, ins: np.ndarray) -> np.ndarray:
        raise NotImplementedError

    def velocities(self, t: float, y: np.ndarray, ins: np.ndarray) -> np.ndarray:
        """The velocity of each port's face (vectorised over the last axis of y and ins)."""
        raise NotImplementedError

    def events(self) -> list:
        """(g(t, y, ins), direction, action(t, y) -> y, kind: gap, speed or force) of the current mode."""
        return []

    def settle(self, t: float, y: np.ndarray, ins: np.ndarray) -> np.ndarray:
        """The mode consistent with the state at a (re)start, y changed where a mode change resets it."""
        return y

    def blow(self, t: float, y: np.ndarray, ins: np.ndarray, solution: Solution) -> np.ndarray:
        return y


class Solution:
    """The drill's waves over time, run by :meth:`run` (module doc)."""

    def __init__(self, rods: list[Rod], junctions: list[Junction], period_s: float, end_s: float,
                 states: list[np.ndarray], scale: float) -> None:
        self.rods, self.junctions, self.period, self.end, self.scale = rods, junctions, period_s, end_s, scale
        self.waves = []
        for rod in rods:
            self.waves += [Wave(rod.initial_top), Wave(rod.initial_bottom)]
        self.states = [np.array(y, dtype=float) for y in states]
        self.log: list[tuple[float, str, float]] = []

    def source(self, port: int) -> tuple[Wave, float]:
        """The wave arriving at ``port``: the other end's, T later."""
        return self.waves[port ^ 1], self.rods[port // 2].transit

    def incoming(self, port: int, t, side: int = 1):
        wave, delay = self.source(port)
        return wave(np.asarray(t) - delay, side)

    def run(self) -> Solution:
        chunk = min(rod.transit for rod in self.rods)
        t, blow = 0.0, 0
        while t < self.end - 1e-15:
            if abs(t - blow * self.period) < 1e-15:
                for j, junction in enumerate(self.junctions):
                    ins = np.array([self.incoming(p, t) for p in junction.ports])
                    self.states[j] = junction.blow(t, self.states[j], ins, self)
                blow += 1
            t1 = min(t + chunk, blow * self.period, self.end)
            for j, junction in enumerate(self.junctions):
                self.states[j] = self._advance(junction, self.states[j], t, t1)
            t = t1
        return self

    def _advance(self, junction: Junction, y: np.ndarray, t0: float, t1: float) -> np.ndarray:
        breaks = {t0, t1}
        hard = abs(t0 / self.period - round(t0 / self.period)) < 1e-9  # a blow start
        for port in junction.ports:
            wave, delay = self.source(port)
            breaks.update(b + delay for b in wave.breaks(t0 - delay, t1 - delay))
            hard = hard or any(abs(b - (t0 - delay)) <= SIDE_S for b in wave.breaks(t0 - delay - 2 * SIDE_S,
                                                                                  t0 - delay + 2 * SIDE_S))
        times = [t0]
        for b in sorted(b for b in breaks if t0 < b <= t1):  # breaks closer than MERGE_S are one
            if b - times[-1] > MERGE_S:
                times.append(b)
        times[-1] = t1
        for a, b in itertools.pairwise(times):
            if b - a < 1e-15:
                continue
            functions = []
            for port in junction.ports:
                wave, delay = self.source(port)
                function = wave.function(a - delay, b - delay)
                functions.append(lambda t, f=function, d=delay: f(np.asarray(t) - d))

            def ins(t, fs=functions):
                return np.array([f(t) for f in fs])[:, 0] if np.ndim(t) == 0 else np.array([f(t) for f in fs])
            y = self._stretch(junction, y, a, b, ins, a != t0 or hard)
        return y

    def _stretch(self, junction: Junction, y: np.ndarray, a: float, b: float, ins, hard: bool) -> np.ndarray:
        """Integrate from a to b (no arriving break inside), switching at events; the first piece stored is a
        hard break when ``hard`` (an arriving break or a blow start), those after an event are."""
        start, first = a, hard
        for _ in range(200):
            if b - start <= MERGE_S:
                return y
            y = junction.settle(start, y, ins(start))
            events = junction.events()
            functions = []
            for g, direction, _, kind in events:
                # crossed only beyond a tolerance: a function resting on zero (the rock before the wave comes,
                # a contact at C = 0) is not a switch at every step
                margin = -direction * TOLERANCE[kind]

                def event(t, state, g=g, margin=margin):
                    return g(t, state, ins(t)) + margin
                event.terminal, event.direction = True, direction
                functions.append(event)
            solution = solve_ivp(lambda t, state: junction.rhs(t, state, ins(t)), (start, b), y,
                                 method=junction.method, rtol=RTOL, atol=ATOL, events=functions or None,
                                 dense_output=True)
            if solution.status < 0:
                raise RuntimeError(solution.message)
            end, action = float(solution.t[-1]), None
            if solution.status == 1:
                fired = next(i for i, times in enumerate(solution.t_events) if len(times))
                action = events[fired][2]
            dense = solution.sol
            velocities = junction.velocities

            for k, port in enumerate(junction.ports if end - start > 1e-16 else ()):
                def out(t, k=k, dense=dense, velocities=velocities):
                    t = np.atleast_1d(np.asarray(t, dtype=float))
                    state, arriving = dense(t), ins(t)
                    return velocities(t, state, arriving)[k] - arriving[k]
                for piece in fit_pieces(out, start, end, first, self.scale):
                    self.waves[port].add(piece)
            first = True
            y = dense(end)
            if action is None:
                return y
            y = action(end, y)
            start = end
        raise RuntimeError(f"more than 200 switches in one stretch at {start} ({type(junction).__name__}, "
                           f"{getattr(junction, 'mode', '')})")


# -- junctions ------------------------------------------------------------------------------------------

class FreeEnd(Junction):
    """A free face: no force, v = 2 w_in (a rod piston's back)."""

    def __init__(self, port: int, impedance: float) -> None:
        self.ports, self.impedances = [port], [impedance]

    def rhs(self, t, y, ins):
        return np.array([2.0 * ins[0]])

    def velocities(self, t, y, ins):
        return np.array([2.0 * ins[0]])


class RigidPiston(Junction):
    """A rigid piston of mass m on a rod's top face through a rigid compression-only contact, a feed F on the
    face. y = (x_face, x_piston, v_piston, int C v_face dt); modes closed, open, caught. Blows: the piston
    placed on the face at v_p. Caught when the contact opens (or is open) with the piston moving back."""

    def __init__(self, port: int, impedance: float, mass: float, speed: float, feed: float = 0.0) -> None:
        self.ports, self.impedances = [port], [impedance]
        self.mass, self.speed, self.feed, self.mode = mass, speed, feed, "caught"
        self.rebounds: list[tuple[float, float]] = []  # (blow start, energy at the catch)
        self.blow_start = 0.0

    def _face(self, y, ins):
        z = self.impedances[0]
        if self.mode == "closed":
            return y[2] + 0.0 * ins[0]
        return 2.0 * ins[0] + self.feed / z

    def contact(self, y, ins):
        """C: the compression of the contact (closed: what holds the face's balance)."""
        z = self.impedances[0]
        return -(self.feed + z * (2.0 * ins[0] - y[2]))

    def rhs(self, t, y, ins):
        v = self._face(y, ins)
        if self.mode == "closed":
            c = self.contact(y, ins)
            return np.array([v, v, -c / self.mass, c * v])
        return np.array([v, y[2] if self.mode == "open" else 0.0, 0.0, 0.0])

    def velocities(self, t, y, ins):
        return np.array([self._face(y, ins)])

    def _catch(self, t, y):
        self.mode = "caught"
        self.rebounds.append((self.blow_start, 0.5 * self.mass * y[2] ** 2))
        return y

    def _open(self, t, y):
        self.mode = "open"
        return self._catch(t, y) if y[2] <= 0 else y

    def _close(self, t, y):
        self.mode = "closed"
        return y

    def events(self):
        if self.mode == "closed":
            return [(lambda t, y, ins: self.contact(y, ins), -1, self._open, "force")]
        if self.mode == "open":
            return [(lambda t, y, ins: y[1] - y[0], 1, self._close, "gap")]
        return []

    def settle(self, t, y, ins):
        if self.mode == "closed" and self.contact(y, ins) < -TOLERANCE["force"]:
            return self._open(t, y)
        return y

    def blow(self, t, y, ins, solution):
        if self.mode != "caught":
            self.rebounds.append((self.blow_start, 0.5 * self.mass * y[2] ** 2))
        self.mode, self.blow_start = "closed", t
        return np.array([y[0], y[0], self.speed, y[3]])


class RodPistonContact(Junction):
    """A rod piston's front face (port ``piston``) on a rod's top face (port ``struck``), a rigid
    compression-only contact, a feed F on the struck face. y = (x_piston_face, x_struck_face, impulse
    int C dt since the strike); caught when the contact opens with the piston's momentum (m v_p - int C dt,
    constant while free) not forward, or when it rests on the face without pushing (rpdrill's rule for a wave
    piston: both nil to 1e-9). Blows: the piston rod at v_p, unstressed (its waves v_p / 2)."""

    def __init__(self, piston: int, struck: int, impedances: tuple[float, float], mass: float, speed: float,
                 feed: float = 0.0) -> None:
        self.ports, self.impedances = [piston, struck], list(impedances)
        self.mass, self.speed, self.feed, self.mode = mass, speed, feed, "caught"
        self.catches: list[tuple[float, float]] = []  # (time, momentum)

    def velocities(self, t, y, ins):
        zp, zs = self.impedances
        if self.mode == "closed":
            v = (2 * zp * ins[0] + 2 * zs * ins[1] + self.feed) / (zp + zs)
            return np.array([v, v])
        piston = 2.0 * ins[0] if self.mode == "open" else 0.0 * ins[0]
        return np.array([piston, 2.0 * ins[1] + self.feed / zs])

    def contact(self, y, ins):
        zp = self.impedances[0]
        return zp * (2.0 * ins[0] - self.velocities(0.0, y, ins)[0])

    def rhs(self, t, y, ins):
        v = self.velocities(t, y, ins)
        c = self.contact(y, ins) if self.mode == "closed" else 0.0
        return np.array([v[0], v[1], c])

    def _open(self, t, y):
        self.mode = "open"
        if self.mass * self.speed - y[2] <= 0:
            self.mode = "caught"
            self.catches.append((t, self.mass * self.speed - y[2]))
        return y

    def _close(self, t, y):
        self.mode = "closed"
        return y

    def events(self):
        if self.mode == "closed":
            return [(lambda t, y, ins: self.contact(y, ins), -1, self._open, "force")]
        if self.mode == "open":
            return [(lambda t, y, ins: y[0] - y[1], 1, self._close, "gap")]
        return []

    def settle(self, t, y, ins):
        if self.mode == "closed" and self.contact(y, ins) < -TOLERANCE["force"]:
            return self._open(t, y)
        momentum = self.mass * self.speed - y[2]
        if self.mode == "closed" and abs(momentum) <= 1e-9 * self.mass * self.speed and \
                abs(self.contact(y, ins)) <= 1e-9 * self.impedances[0] * self.speed:  # at rest, not pushing
            self.mode = "caught"
            self.catches.append((t, momentum))
        return y

    def blow(self, t, y, ins, solution):
        rod = solution.rods[self.ports[0] // 2]
        for port in (self.ports[0], self.ports[0] ^ 1):
            wave = solution.waves[port]
            wave.truncate(t - rod.transit)
            wave.add(Piece(t - rod.transit, t, np.array([0.5 * self.speed]), True))
        self.mode = "closed"
        return np.array([y[1], y[1], 0.0])


class Bilinear:
    """The bilinear rock (rocklaw.bilinear, written again): F = max(0, min(k_l (x - s), k_u (x - p)));
    loading (on the k_l line, p = s + (1 - k_l / k_u)(x - s)), unloading (k_u (x - p)), off (x <= p)."""

    def __init__(self, loading: float, unloading: float) -> None:
        self.kl, self.ku = loading, unloading
        self.ratio = 1.0 - loading / unloading

    def force(self, mode, x, s, p):
        if mode == "loading":
            return self.kl * (x - s)
        if mode == "unloading":
            return self.ku * (x - p)
        return 0.0 * x


class RockFoot(Junction):
    """A rod's bottom face (port) on the bilinear rock, with a bit of ``mass`` joined rigidly (0: none), or
    through a spring ``spring`` (N/m) and ``damper`` (N s/m) to a bit of that mass. y = (x_face, x_bit, v_bit,
    s, p, rock work int F v_bit dt); p is the bottom once off the loading line."""

    def __init__(self, port: int, impedance: float, rock: Bilinear, mass: float = 0.0, spring: float = 0.0,
                 damper: float = 0.0, stiff: bool = False) -> None:
        self.ports, self.impedances = [port], [impedance]
        self.rock, self.mass, self.spring, self.damper = rock, mass, spring, damper
        self.mode = "off"
        self.method = "Radau" if stiff else "DOP853"
        self.work: list[float] = []  # per blow

    def bottom(self, y):
        return y[3] + self.rock.ratio * (y[1] - y[3]) if self.mode == "loading" else y[4]

    def force(self, y):
        return self.rock.force(self.mode, y[1], y[3], y[4])

    def _bit_velocity(self, y, ins):
        z = self.impedances[0]
        if self.mass == 0:  # a massless face on the rock: Z (2 w - v) = F
            return 2.0 * ins[0] - self.force(y) / z
        return y[2] + 0.0 * ins[0]

    def velocities(self, t, y, ins):
        z = self.impedances[0]
        if self.spring:  # the face between the rod and the spring-damper: Z (2 w - v) = k (x_f - x_b) + c (v - v_b)
            return np.array([(2 * z * ins[0] - self.spring * (y[0] - y[1]) + self.damper * y[2]) / (z + self.damper)])
        return np.array([self._bit_velocity(y, ins)])

    def rhs(self, t, y, ins):
        z, force = self.impedances[0], self.force(y)
        if self.spring:
            face = self.velocities(t, y, ins)[0]
            link = self.spring * (y[0] - y[1]) + self.damper * (face - y[2])
            return np.array([face, y[2], (link - force) / self.mass, 0.0, 0.0, force * y[2]])
        v = self._bit_velocity(y, ins)
        acceleration = 0.0 if self.mass == 0 else (z * (2 * ins[0] - v) - force) / self.mass
        return np.array([v, v, acceleration, 0.0, 0.0, force * v])

    def _velocity_event(self, t, y, ins):
        return self.velocities(t, y, ins)[0] if not self.spring and self.mass == 0 else y[2]

    def events(self):
        if self.mode == "loading":
            return [(self._velocity_event, -1, self._unload, "speed")]
        if self.mode == "unloading":
            return [(lambda t, y, ins: self.rock.ku * (y[1] - y[4]) - self.rock.kl * (y[1] - y[3]), 1, self._load, "force"),
                    (lambda t, y, ins: y[1] - y[4], -1, self._lift, "gap")]
        return [(lambda t, y, ins: y[1] - y[4], 1, self._touch, "gap")]

    def _unload(self, t, y):
        y = y.copy()
        y[4] = y[3] + self.rock.ratio * (y[1] - y[3])
        self.mode = "unloading"
        return y

    def _load(self, t, y):
        self.mode = "loading"
        return y

    def _lift(self, t, y):
        self.mode = "off"
        return y

    def _touch(self, t, y):
        self.mode = "loading" if y[3] >= y[4] else "unloading"
        return y

    def settle(self, t, y, ins):
        for _ in range(3):
            if self.mode == "loading" and self._velocity_event(t, y, ins) < -TOLERANCE["speed"]:
                y = self._unload(t, y)
            elif self.mode == "unloading" and y[1] < y[4] - TOLERANCE["gap"]:
                y = self._lift(t, y)
            elif self.mode == "unloading" and \
                    self.rock.ku * (y[1] - y[4]) - self.rock.kl * (y[1] - y[3]) > TOLERANCE["force"]:
                y = self._load(t, y)
            elif self.mode == "off" and y[1] > y[4] + TOLERANCE["gap"]:
                y = self._touch(t, y)
        return y

    def blow(self, t, y, ins, solution):
        """The next blow meets fresh rock: s <- min(p, x - F / k_l) (rocklaw.bilinear.start_blow, eta = 1)."""
        y = y.copy()
        self.work.append(y[5])
        p = self.bottom(y)
        x = y[1]
        if self.mode == "loading":
            y[4] = p
        force = self.force(y)
        y[3] = min(p, x - force / self.rock.kl) if x > p else p
        self.mode = "off" if x <= p else ("loading" if self._velocity_event(t, y, ins) >= 0 else "unloading")
        return y

    def blow_works(self, final: np.ndarray) -> np.ndarray:
        """The rock's work in each blow (the run's last blow closed with the final state)."""
        cumulative = np.array([*self.work[1:], final[5]])
        return np.diff(np.concatenate([[0.0], cumulative]))


class Joint(Junction):
    """Two rods joined at a lower face of rod 1 (port ``upper``) and the top face of rod 2 (port ``lower``):
    rigid (``spring`` None: one point, an impedance step), or a compression-only coupling of stiffness k,
    damping c and gap g (its compression C = -(k (x_u - x_l - g)... written as closure e = x_u - x_l - g > 0
    in contact: C = max(k e + c e', 0)). y = (x_upper, x_lower, energy the damper took)."""

    def __init__(self, upper: int, lower: int, impedances: tuple[float, float], spring: float | None = None,
                 damper: float = 0.0, gap: float = 0.0) -> None:
        self.ports, self.impedances = [upper, lower], list(impedances)
        self.spring, self.damper, self.gap = spring, damper, gap
        self.mode = "rigid" if spring is None else "open"
        self.method = "DOP853"

    def velocities(self, t, y, ins):
        z1, z2 = self.impedances
        if self.mode == "rigid":
            v = (2 * z1 * ins[0] + 2 * z2 * ins[1]) / (z1 + z2)
            return np.array([v, v])
        if self.mode == "open":
            return np.array([2.0 * ins[0], 2.0 * ins[1]])
        # closed: Z1 (2 w1 - v1) = C, Z2 (2 w2 - v2) = -C, C = k e + c (v1 - v2)
        k, c, e = self.spring, self.damper, y[0] - y[1] - self.gap
        a = np.array([[z1 + c, -c], [-c, z2 + c]])
        rhs = np.array([2 * z1 * ins[0] - k * e, 2 * z2 * ins[1] + k * e])
        return np.linalg.solve(a, rhs)

    def compression(self, y, ins):
        if self.mode != "closed":
            return 0.0 * ins[0]
        v = self.velocities(0.0, y, ins)
        return self.spring * (y[0] - y[1] - self.gap) + self.damper * (v[0] - v[1])

    def rhs(self, t, y, ins):
        v = self.velocities(t, y, ins)
        lost = self.damper * (v[0] - v[1]) ** 2 if self.mode == "closed" else 0.0
        return np.array([v[0], v[1], lost])

    def events(self):
        if self.mode == "open":
            return [(lambda t, y, ins: y[0] - y[1] - self.gap, 1, self._close, "gap")]
        if self.mode == "closed":
            return [(lambda t, y, ins: self.compression(y, ins), -1, self._open, "force")]
        return []

    def _close(self, t, y):
        self.mode = "closed"
        return y

    def _open(self, t, y):
        self.mode = "open"
        return y

    def settle(self, t, y, ins):
        if self.mode == "closed" and self.compression(y, ins) < -TOLERANCE["force"]:
            self.mode = "open"
        elif self.mode == "open" and y[0] - y[1] - self.gap > TOLERANCE["gap"]:
            self.mode = "closed"
        return y


# -- readings -------------------------------------------------------------------------------------------

def compression(solution: Solution, port: int, t, side: int = 1) -> np.ndarray:
    """P = sigma Z (w_out - w_in) at a rod end (sigma +1 at the top, -1 at the bottom), at the times t."""
    rod = solution.rods[port // 2]
    sigma = 1.0 if port % 2 == 0 else -1.0
    t = np.atleast_1d(np.asarray(t, dtype=float))
    out = solution.waves[port](t, side)
    arriving = solution.incoming(port, t, side)
    return sigma * rod.impedance * (out - arriving)


def breaks(solution: Solution, port: int, start: float, end: float) -> np.ndarray:
    """Every break of the waves at a port (its own and those arriving) in [start, end]."""
    wave, delay = solution.source(port)
    own = [p.start for p in solution.waves[port].pieces if start <= p.start <= end]
    arriving = [p.start + delay for p in wave.pieces if start <= p.start + delay <= end]
    return np.array(sorted(set(own + arriving)))


def extremes(solution: Solution, port: int, start: float, end: float, spacing: float) -> tuple[float, float]:
    """(largest compression, largest tension as a positive number) at a rod end over [start, end): the
    values on both sides of every break and on a grid of ``spacing``."""
    times = np.concatenate([np.arange(start, end, spacing), breaks(solution, port, start, end)])
    times = times[(times >= start) & (times < end)]
    values = np.concatenate([compression(solution, port, times, 1), compression(solution, port, times, -1)])
    return float(values.max()), float(max(-values.min(), 0.0))


def arriving_energy(solution: Solution, port: int, start: float, end: float) -> float:
    """Z int w_in^2 dt at a rod end over [start, end]: the energy the waves arriving there bring."""
    rod = solution.rods[port // 2]
    cuts = np.concatenate([[start], breaks(solution, port, start, end), [end]])
    x, weights = np.polynomial.legendre.leggauss(40)
    total = 0.0
    for a, b in itertools.pairwise(cuts):
        if b - a > 0:
            t = 0.5 * (a + b) + 0.5 * (b - a) * x
            total += 0.5 * (b - a) * float(np.sum(weights * rod.impedance * solution.incoming(port, t) ** 2))
    return total


def energy_through(solution: Solution, port: int, start: float, end: float) -> float:
    """int P v dt along +x at a rod end over [start, end] (Z (w_out^2 - w_in^2) dt, along +x at the top)."""
    rod = solution.rods[port // 2]
    cuts = np.concatenate([[start], breaks(solution, port, start, end), [end]])
    total = 0.0
    for a, b in itertools.pairwise(cuts):
        if b - a <= 0:
            continue
        x, weights = np.polynomial.legendre.leggauss(40)
        t = 0.5 * (a + b) + 0.5 * (b - a) * x
        out = solution.waves[port](t)
        arriving = solution.incoming(port, t)
        total += 0.5 * (b - a) * float(np.sum(weights * rod.impedance * (out**2 - arriving**2)))
    return total if port % 2 == 0 else -total
