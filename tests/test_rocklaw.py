"""The rock laws alone, through the interface (rocklaw.base.RockLaw): pure functions, the ODE mode
tables against the return maps, and the symbolic recording for Exudyn.
Unit tests of rocklaw.base, rocklaw.modes and rocklaw.exudyn_element: they import them."""

import dataclasses
import math

import numpy as np
import pytest

from rpdrill.rocklaw import LAWS, TABLE_1, BilinearRock, JenkinsRock, RockLaw, force_and_state
from rpdrill.rocklaw.base import local_values
from rpdrill.rocklaw.modes import check_mode_forces, evaluate

# unit tests of: a law's local values, its mode tables evaluated and checked, its Exudyn element's compiled force
UNITS = ("rpdrill.rocklaw.base", "rpdrill.rocklaw.exudyn_element", "rpdrill.rocklaw.modes")

ROCK = JenkinsRock(stiffness_n_per_m=5e8, damping_n_s_per_m=0.0, threshold_n=138e3)
CRUSH = ROCK.crushing_penetration_m  # 276 um
LAW_CASES = {
    "jenkins": ROCK,
    "jenkins_damped": JenkinsRock(5e8, 1.98e3, 138e3),
    "jenkins_always": JenkinsRock(5e8, 1.98e3, 138e3, damping_mode="always"),
    "jenkins_elastic": JenkinsRock(5e8, 0.0, math.inf),
    "jenkins_indexed": JenkinsRock(5e8, 2e4, 138e3, indexed=True, fresh_fraction=0.6),
    "bilinear": BilinearRock(2e8, 1e9),
    "bilinear_elastic": BilinearRock(2e8, 2e8),
}


def walk(path_m: np.ndarray, law: RockLaw = ROCK, velocity_m_per_s: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Forces and states (samples x states) along a bit path, return map then force at every point."""
    state, forces, states = law.initial_state(), [], []
    for x in path_m:
        force, state = force_and_state(law, x, velocity_m_per_s, state)
        forces.append(force)
        states.append(state)
    return np.array(forces), np.array(states)


def blows(amplitude_m: float, count: int = 6, points: int = 4001) -> np.ndarray:
    """A bit path of ``count`` blows going deeper and lifting off in between, from x = 0."""
    t = np.linspace(0.0, count, points)
    return amplitude_m * (0.6 * t + 1.5 * np.sin(2 * np.pi * t)) * (t < count)


def test_registry_and_interface():
    assert set(LAWS) == {"jenkins", "bilinear", "none"}  # none: no rock, a string that ends free (rocklaw.free)
    for name, law in LAW_CASES.items():
        assert isinstance(law, RockLaw), name
        assert law.name in LAWS and isinstance(law, LAWS[law.name])
        assert len(law.initial_state()) == len(law.state_names) and 0 <= law.bottom_index < len(law.state_names)
        assert law.unloading_stiffness_n_per_m >= law.loading_stiffness_n_per_m > 0


def test_load_unload_reload_loop():
    up = np.linspace(0.0, 3 * CRUSH, 301)
    down = np.linspace(3 * CRUSH, -CRUSH, 401)
    again = np.linspace(-CRUSH, 4 * CRUSH, 501)
    path = np.concatenate([up, down, again])
    force, states = walk(path)
    bottom = states[:, ROCK.bottom_index]

    loading = path[:301] <= CRUSH
    np.testing.assert_allclose(force[:301][loading], ROCK.stiffness_n_per_m * path[:301][loading])
    assert np.all(force[:301][~loading] == pytest.approx(ROCK.threshold_n))
    # crushing moved the bottom to 3 CRUSH - CRUSH = 2 CRUSH; unloading is elastic from there
    assert bottom[300] == pytest.approx(2 * CRUSH)
    unloading = down > 2 * CRUSH
    np.testing.assert_allclose(force[301:702][unloading], ROCK.stiffness_n_per_m * (down[unloading] - 2 * CRUSH),
                               atol=1e-6)
    assert np.all(force[301:702][~unloading] == 0.0)  # off the bottom: no tension
    # reload: no force until the old bottom, elastic to F_th, then crushing again
    reload_contact = (again > 2 * CRUSH) & (again < 3 * CRUSH)
    np.testing.assert_allclose(force[702:][reload_contact],
                               ROCK.stiffness_n_per_m * (again[reload_contact] - 2 * CRUSH))
    assert bottom[-1] == pytest.approx(3 * CRUSH)
    assert np.all(np.diff(bottom) >= 0.0)
    assert np.all(force >= 0.0) and np.all(force <= ROCK.threshold_n * (1 + 1e-12))


@pytest.mark.parametrize("name", ["jenkins", "jenkins_damped", "jenkins_indexed", "bilinear"])
def test_no_pull_monotone_bottom_and_spring_part(name):
    law = LAW_CASES[name]
    path = blows(2e-4)
    force, states = walk(path, law, velocity_m_per_s=-1.0)  # moving out: a damper would pull if it could
    spring = law.spring_force(path, tuple(states.T))
    bottom = states[:, law.bottom_index]
    assert np.all(force >= 0.0) and np.all(spring >= 0.0)
    assert np.all(np.diff(bottom) >= 0.0) and bottom[-1] > 0.0  # it crushed, and never backwards
    off = path <= bottom
    assert off.any() and np.all(force[off] == 0.0)
    np.testing.assert_array_equal(law.force(path, 0.0, tuple(states.T)), spring)  # at rest: the spring part


@pytest.mark.parametrize("name", list(LAW_CASES))
def test_return_map_is_idempotent_and_gives_the_preload_state(name):
    law = LAW_CASES[name]
    _, states = walk(blows(2e-4), law)
    for x, state in zip(blows(2e-4)[::97], states[::97], strict=True):
        once = law.return_map(x, tuple(state))
        assert law.return_map(x, once) == once
    # static preload below crushing: the consistent state carries k_load x0
    x0 = 0.5 * min(CRUSH, 1e-4)
    preload = law.return_map(x0, law.initial_state())
    assert law.spring_force(x0, preload) == pytest.approx(law.loading_stiffness_n_per_m * x0)


def follow_modes(law: RockLaw, time_s: np.ndarray, path_m: np.ndarray) -> np.ndarray:
    """The law's mode table (rocklaw.modes) along a prescribed path: states integrated at the mode's
    rates, modes switched where an exit surface crosses zero in its direction, entry values applied
    (the bottom never decreasing); first order in the step."""
    velocity = np.gradient(path_m, time_s)
    table, names, bottom = law.modes(), law.state_names, law.bottom_index
    state = np.array(law.initial_state())
    mode = law.initial_mode(local_values(law, path_m[0], velocity[0], state))
    states = [state]
    for i in range(len(time_s) - 1):
        values = local_values(law, path_m[i], velocity[i], state)
        state = state + np.array([evaluate(table[mode].rates.get(name, {}), values) for name in names]) \
            * (time_s[i + 1] - time_s[i])
        before, after = values, local_values(law, path_m[i + 1], velocity[i + 1], state)
        for switch in table[mode].exits:
            if switch.direction * evaluate(switch.surface, before) <= 0 < switch.direction * evaluate(switch.surface, after):
                mode = switch.next_mode
                entry = {name: evaluate(row, after) for name, row in table[mode].entry.items()}
                state = np.array([entry.get(name, value) for name, value in zip(names, state, strict=True)])
                state[bottom] = max(state[bottom], after[names[bottom]])
                break
        states.append(state)
    return np.array(states)


@pytest.mark.parametrize("name", ["jenkins", "jenkins_damped", "jenkins_elastic", "jenkins_indexed", "bilinear",
                                  "bilinear_elastic"])
def test_mode_table_reproduces_the_return_map(name):
    """Integrating the mode table's state rates and switching at its exits follows the return map."""
    law = LAW_CASES[name]
    # the walk is first order in the step: the indexed law moves two states while crushing (x_n and
    # tau), with twice the first-order error of one; half the step keeps the same tolerance
    time_s = np.linspace(0.0, 6.0, 60001 if name == "jenkins_indexed" else 30001)
    path = blows(2e-4, points=len(time_s))
    _, mapped = walk(path, law)
    followed = follow_modes(law, time_s, path)
    bottom = law.bottom_index
    assert np.max(np.abs(followed[:, bottom] - mapped[:, bottom])) < 1e-3 * max(mapped[-1, bottom], CRUSH)
    forces = law.spring_force(path, tuple(followed.T)), law.spring_force(path, tuple(mapped.T))
    assert np.max(np.abs(forces[0] - forces[1])) < 5e-3 * np.max(forces[1])


@pytest.mark.parametrize("name", sorted(LAW_CASES))
def test_declared_force_rows_agree_with_the_closed_form(name):
    """In whatever mode a state lies (initial_mode), the mode's force row equals the closed-form force
    that Exudyn records: the two descriptions of a law cannot drift apart."""
    law = LAW_CASES[name]
    rng = np.random.default_rng(1)
    scale = max(CRUSH, 1e-4)
    samples = []
    for _ in range(400):  # reachable states: the return map along a few random positions
        state = law.initial_state()
        for x in rng.uniform(-scale, 3 * scale, 4):
            state = law.return_map(x, state)
        samples.append(local_values(law, x, rng.uniform(-5.0, 5.0), state))
    problems = check_mode_forces(law, samples, lambda v: law.force(
        v["position"], v["velocity"], [v[n] for n in law.state_names]))
    assert problems == []
    assert {law.initial_mode(v) for v in samples} == set(law.modes())  # the samples visit every mode


@pytest.mark.parametrize("mode", ["contact", "always"])
def test_damping_modes(mode):
    rock = JenkinsRock(5e8, 2e4, 138e3, damping_mode=mode)
    off, in_contact, untouched = -1e-5, 1e-5, (0.0,)
    if mode == "contact":
        assert rock.force(off, -3.0, untouched) == 0.0 and rock.force(off, 3.0, untouched) == 0.0
        assert rock.force(in_contact, -10.0, untouched) == 0.0  # a damper cannot pull the bit into the rock
        assert rock.force(in_contact, 0.1, untouched) == pytest.approx(5e3 + 2e3)
    else:  # Eq. 4 literally: c_n on the bit velocity at all times
        assert rock.force(off, -3.0, untouched) == pytest.approx(-6e4)
        assert rock.force(in_contact, 0.1, untouched) == pytest.approx(5e3 + 2e3)


def test_table_1_rocks():
    assert TABLE_1["conglomerate"].stiffness_n_per_m == 8.4e8
    assert TABLE_1["soft_limestone"].threshold_n == 138e3


@pytest.mark.parametrize("bad", [{"stiffness_n_per_m": 0.0}, {"threshold_n": -1.0}, {"damping_n_s_per_m": -1.0}])
def test_invalid_parameters(bad):
    values = {"stiffness_n_per_m": 5e8, "damping_n_s_per_m": 0.0, "threshold_n": 1e5} | bad
    with pytest.raises(ValueError):
        JenkinsRock(**values)


def test_indexed_jenkins_hardens_and_advances_eta_of_the_stroke():
    """Indexed (a share eta on fresh rock): past F_th the force rises along k_n (1 - eta) and the bottom
    moves eta of the bit's crushing stroke; a new blow starts at F_th again; eta = 1 is Eq. 1, 2."""
    eta, stroke = 0.6, 2e-4
    law = JenkinsRock(5e8, 0.0, 138e3, indexed=True, fresh_fraction=eta)
    path = np.linspace(0.0, CRUSH + stroke, 201)
    force, states = walk(path, law)
    assert force[-1] == pytest.approx(138e3 + 5e8 * (1 - eta) * stroke)
    assert states[-1, 0] == pytest.approx(eta * stroke) and states[-1, 1] == pytest.approx(force[-1])
    assert law.start_blow(0.0, tuple(states[-1])) == (states[-1, 0], 138e3)  # off the rock: a fresh F_th
    plain, _ = walk(path, ROCK)
    fresh, _ = walk(path, JenkinsRock(5e8, 0.0, 138e3, indexed=True))
    np.testing.assert_allclose(fresh, plain, rtol=1e-12)


@pytest.mark.parametrize("name", ["jenkins_damped", "jenkins_always", "jenkins_indexed", "bilinear"])
def test_symbolic_recording_matches_numeric_in_every_branch(name):
    """The compiled (symbolic) force equals the pure function in every branch and follows the state
    set through the element (off, elastic, crushing; bilinear loading, unloading, reloading)."""
    import exudyn as exu
    from exudyn.itemInterface import MarkerNodeCoordinate, Node1D, NodePointGround, ObjectMass1D

    from rpdrill.rocklaw.exudyn_element import ExudynRockContact

    law = LAW_CASES[name]
    mbs = exu.SystemContainer().AddSystem()
    ground = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=mbs.AddNode(NodePointGround()), coordinate=0))
    node = mbs.AddNode(Node1D(referenceCoordinates=[0.0], initialCoordinates=[1.2e-4]))
    mbs.AddObject(ObjectMass1D(nodeNumber=node, mass=1.0))
    bit = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node, coordinate=0))
    element = ExudynRockContact(mbs, ground, bit, node, law)
    assert element.state == law.return_map(1.2e-4, law.initial_state())  # consistent with the start
    compiled = element._user_function
    _, states = walk(blows(2e-4, count=2, points=41), law)
    for state in map(tuple, states[::4]):
        element.set_state(state, 0.0)
        for position in (-1e-4, 0.0, 1.5e-4, 3e-4, 2 * CRUSH, 6e-4):
            for velocity in (-2.0, 0.0, 0.7):
                expected = law.force(position, velocity, state)
                got = compiled.Evaluate(mbs, 0.0, 0, position, velocity, 0.0, 0.0, 0.0)
                assert got == pytest.approx(expected, rel=1e-12, abs=1e-9)
    if law.modes_follow_fresh_fraction:  # another blow's eta reaches the compiled expression
        element.set_law(dataclasses.replace(law, fresh_fraction=0.3))
        got = compiled.Evaluate(mbs, 0.0, 0, 6e-4, 0.0, 0.0, 0.0, 0.0)
        assert got == pytest.approx(element.rock.force(6e-4, 0.0, element.state), rel=1e-12)
        assert got != pytest.approx(law.force(6e-4, 0.0, element.state), rel=1e-6)
