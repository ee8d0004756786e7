"""Which attractor the drill reaches from its scene's start, beside the orbit the steady-state solver found.

A stable orbit found from a neighbour's (a continuation) or from a few blows of the start need not be where
the drill goes from its start: two attractors may coexist (on the test drill of docs/steady_state.md at
30.25-31.25 Hz the continuation follows stable period-1 and period-2 orbits while the drill run from its
start bounces irregularly, or settles on period 5). So once an orbit is found the drill is run on from the
scene's start by the exact map (the scene's own, or the exact model guiding another formulation), a chunk of
``CHUNK_BLOWS`` blows at a time, until

* its blow-start state comes within ``REACHED`` (scaled, models.steady.shooting.scales) of one of the orbit's
  blow-start states: the start reaches the orbit;
* or its last blows repeat a period m <= MAX_PERIOD_BLOWS within ``NEAR`` (scaled) and Newton on the m-blow map
  from its last blow start converges to a stable orbit: that is the attractor the start reaches, the orbit found
  if it is within ``REACHED`` of it, else a coexisting one (its regime and advance said). The first chunk is
  2 n + 1 blows, n the orbit's period: where the start repeats the orbit's period by then, Newton from there
  decides at once (a drill that goes to the orbit costs a few blows and one Newton);
* or ``MAX_BLOWS`` have run: the start reaches no period up to MAX_PERIOD_BLOWS blows (irregular bouncing, a
  longer period, or a transient longer than that).

A drill that reaches the orbit stops as soon as it is within reach (on the paper drill's scan tens of blows);
one that does not costs ``MAX_BLOWS`` blows of the exact map (about 0.05 CPU s on the test drill). A scene the
exact model does not run (an Exudyn extension that changes the motion) is not checked.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

import numpy as np

from .shooting import Orbit, scales
from .steady_state import IRREGULAR, StartCheck, regime_name

CHUNK_BLOWS = 13  # 2 MAX_PERIOD_BLOWS + 1: the fewest over which every period up to 6 repeats twice
MAX_BLOWS = 390  # 30 chunks: about 13 s of drilling at 30 Hz
REACHED = 1e-3  # scaled distance to one of the orbit's blow-start states
NEAR = 0.05  # scaled distance of blow-start states m blows apart under which Newton looks for the start's orbit


def coexisting_note(check: StartCheck, orbit: Orbit) -> str:
    """'' where the start reaches the orbit; else what it reaches instead (coexisting attractors)."""
    if check.reaches_orbit:
        return ""
    found = f"the {regime_name(orbit.periods)} orbit found (advance per blow {orbit.advance_per_blow_m:.4g} m)"
    if check.regime == IRREGULAR:
        reached = (f"no periodic response within {check.blows} blows (irregular bouncing, a period beyond "
                   f"{CHUNK_BLOWS // 2} blows, or a longer transient)")
    else:
        reached = f"another, stable {check.regime} orbit (advance per blow {check.advance_per_blow_m:.4g} m)"
    return (f"coexisting regimes: {found} is not where the drill goes from the scene's start, which reaches "
            f"{reached}; a time run (solver.steady_state: time) shows that one")




def check_start(period_map: Any, simulation: Any, section: Any, start: np.ndarray, orbit: Orbit,
                repeating: Callable[[list[np.ndarray]], tuple[int, float]],
                shoot: Callable[[int, np.ndarray], Orbit | None]) -> StartCheck:
    """Run the drill from ``start`` (y at the scene's start) by ``period_map`` (a one-blow map with
    ``blow_states``) against ``orbit`` (module doc); ``repeating(states)``: the period that repeats best over
    blow-start states and its scaled distance (models.steady.regimes.repeating_period); ``shoot(n, y)``: the
    stable orbit of n blows Newton finds from y, or None."""
    cpu = time.process_time()
    around = period_map.blow_states(orbit.state, orbit.periods - 1) if orbit.periods > 1 else []
    targets = [section.reduce(y)[0] for y in [orbit.state, *around]]
    scale = scales(simulation, section, targets[0])

    def distance(y: np.ndarray) -> float:
        z = section.reduce(y)[0]
        return min(float(np.max(np.abs(z - target) / scale)) for target in targets)

    y, history, blows, tried = start, [start], 0, set()
    while blows < MAX_BLOWS:
        chunk = 2 * orbit.periods + 1 if blows == 0 else CHUNK_BLOWS  # first: enough to see the orbit's period
        states = period_map.blow_states(y, chunk)
        blows += chunk
        history = (history + states)[-CHUNK_BLOWS:]
        y = states[-1]
        if distance(y) <= REACHED:
            return StartCheck(regime_name(orbit.periods), True, blows, np.nan, time.process_time() - cpu)
        periods, repeat = repeating(history) if len(history) == CHUNK_BLOWS else \
            (orbit.periods, _repeat(history, orbit.periods, section, scale))
        if repeat <= NEAR and (periods not in tried or len(history) < CHUNK_BLOWS):
            tried.add(periods)  # (once a period: a start still on its way is run on)
            found = shoot(periods, y)
            if found is not None:
                same = distance(found.state) <= REACHED
                return StartCheck(regime_name(found.periods), same, blows, np.nan if same else found.advance_per_blow_m,
                                  time.process_time() - cpu)
    return StartCheck(IRREGULAR, False, blows, np.nan, time.process_time() - cpu)


def _repeat(states: list[np.ndarray], periods: int, section: Any, scale: np.ndarray) -> float:
    """The scaled distance of the last blow-start state from the one ``periods`` blows before it."""
    return float(np.max(np.abs(section.reduce(states[-1])[0] - section.reduce(states[-1 - periods])[0]) / scale))
