"""The paper's rock law alone: pure functions, and their symbolic recording for Exudyn."""

import numpy as np
import pytest

from rocklaw import TABLE_1, JenkinsRock, force_and_bottom

ROCK = JenkinsRock(stiffness_n_per_m=5e8, damping_n_s_per_m=0.0, threshold_n=138e3)
CRUSH = ROCK.crushing_penetration_m  # 276 um


def walk(path_m: np.ndarray, rock: JenkinsRock = ROCK) -> tuple[np.ndarray, np.ndarray]:
    """Forces and bottoms along a quasi-static bit path (velocity 0), step by step."""
    bottom, forces, bottoms = 0.0, [], []
    for x in path_m:
        force, bottom = force_and_bottom(rock, x, 0.0, bottom)
        forces.append(force)
        bottoms.append(bottom)
    return np.array(forces), np.array(bottoms)


def test_load_unload_reload_loop():
    up = np.linspace(0.0, 3 * CRUSH, 301)
    down = np.linspace(3 * CRUSH, -CRUSH, 401)
    again = np.linspace(-CRUSH, 4 * CRUSH, 501)
    path = np.concatenate([up, down, again])
    force, bottom = walk(path)

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


@pytest.mark.parametrize("mode", ["contact", "always"])
def test_damping_modes(mode):
    rock = JenkinsRock(5e8, 2e4, 138e3, damping_mode=mode)
    off, in_contact = -1e-5, 1e-5
    if mode == "contact":
        assert rock.force(off, -3.0) == 0.0 and rock.force(off, 3.0) == 0.0
        assert rock.force(in_contact, -10.0) == 0.0  # a damper cannot pull the bit into the rock
        assert rock.force(in_contact, 0.1) == pytest.approx(5e3 + 2e3)
    else:  # Eq. 4 literally: c_n on the bit velocity at all times
        assert rock.force(off, -3.0) == pytest.approx(-6e4)
        assert rock.force(in_contact, 0.1) == pytest.approx(5e3 + 2e3)


def test_table_1_rocks():
    assert TABLE_1["conglomerate"].stiffness_n_per_m == 8.4e8
    assert TABLE_1["soft_limestone"].threshold_n == 138e3


@pytest.mark.parametrize("bad", [{"stiffness_n_per_m": 0.0}, {"threshold_n": -1.0}, {"damping_n_s_per_m": -1.0}])
def test_invalid_parameters(bad):
    values = {"stiffness_n_per_m": 5e8, "damping_n_s_per_m": 0.0, "threshold_n": 1e5} | bad
    with pytest.raises(ValueError):
        JenkinsRock(**values)


@pytest.mark.parametrize("mode", ["contact", "always"])
def test_symbolic_recording_matches_numeric_in_every_branch(mode):
    """The compiled (symbolic) force equals the pure function off, in elastic contact and crushing."""
    import exudyn as exu
    from exudyn.itemInterface import MarkerNodeCoordinate, Node1D, NodePointGround, ObjectMass1D

    from rocklaw.exudyn_element import ExudynRockContact

    rock = JenkinsRock(5e8, 1.98e3, 138e3, damping_mode=mode)
    mbs = exu.SystemContainer().AddSystem()
    ground = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=mbs.AddNode(NodePointGround()), coordinate=0))
    node = mbs.AddNode(Node1D(referenceCoordinates=[0.0]))
    mbs.AddObject(ObjectMass1D(nodeNumber=node, mass=1.0))
    bit = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node, coordinate=0))
    element = ExudynRockContact(mbs, ground, bit, node, rock, initial_bottom_m=1e-4)
    compiled = element._user_function
    for position in (-1e-4, 0.0, 1.5e-4, 1e-4 + CRUSH / 2, 1e-4 + 2 * CRUSH):
        for velocity in (-2.0, 0.0, 0.7):
            expected = rock.force(position - 1e-4, velocity)
            got = compiled.Evaluate(mbs, 0.0, 0, position, velocity, 5e8, 1.98e3, 1e-4)
            assert got == pytest.approx(expected, rel=1e-12, abs=1e-9)
