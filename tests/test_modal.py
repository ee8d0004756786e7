"""models.drill.modal: the rock mode of the in-contact chain on chains with known answers and on a scene.
Unit tests of models.drill.modal, on chains built of models.drill.chain's bodies and models.definition.links'
links and on a prepared scene's chain and rock (models.solvers.simulation): they import them."""

import math

import pytest
from scenes import scene, scene_dict

from rpdrill import Scene
from rpdrill.models.definition.links import Link
from rpdrill.models.drill.chain import AxialChain, ChainBody
from rpdrill.models.drill.modal import rock_mode_frequency_hz
from rpdrill.models.solvers.simulation import prepare
from rpdrill.rocklaw import JenkinsRock

# unit tests of: the rock mode of a chain of bodies and links, and of a prepared scene's chain on its rock
UNITS = ("rpdrill.models.definition.links", "rpdrill.models.drill.chain", "rpdrill.models.drill.modal",
         "rpdrill.models.solvers.simulation")


def chain(masses_kg: list[float], joint_n_per_m: float | None = None, bit: int | None = None) -> AxialChain:
    """Bodies in a row joined by springs of ``joint_n_per_m``; the rock under body ``bit`` (default the last)."""
    bodies = tuple(ChainBody(f"b{i}", m, 0.0) for i, m in enumerate(masses_kg))
    links = tuple(Link(f"j{i}", i, i + 1, joint_n_per_m, 0.0) for i in range(len(masses_kg) - 1))
    bit = len(masses_kg) - 1 if bit is None else bit
    return AxialChain(bodies, links, impact_body=0, bit_body=bit, groups={b.name: (i, i) for i, b in enumerate(bodies)})


def rock(stiffness_n_per_m: float, damping_n_s_per_m: float = 0.0) -> JenkinsRock:
    return JenkinsRock(stiffness_n_per_m, damping_n_s_per_m, math.inf)


def test_one_body_on_the_rock_is_a_damped_oscillator():
    mass, rock_stiffness, rock_damping = 2000.0, 5e8, 4e4
    expected = math.sqrt(rock_stiffness / mass - (rock_damping / (2 * mass)) ** 2) / (2 * math.pi)
    assert rock_mode_frequency_hz(chain([mass]), rock(rock_stiffness, rock_damping)) == pytest.approx(expected, rel=1e-12)


def test_overdamped_rock_mode_has_no_frequency():
    assert rock_mode_frequency_hz(chain([1.0]), rock(1.0, 3.0)) == 0.0  # zeta = 1.5


def test_two_equal_bodies_pick_the_mode_that_rides_on_the_rock():
    # m -k- m -k_n: omega^2 = (3 -+ sqrt 5)/2 k/m; the lower mode holds 72 % of its strain energy
    # in the rock spring, the upper one 28 %
    k, m = 1e6, 10.0
    found = rock_mode_frequency_hz(chain([m, m], k), rock(k))
    assert found == pytest.approx(math.sqrt((3 - math.sqrt(5)) / 2 * k / m) / (2 * math.pi), rel=1e-12)
    # with the rock under the other body, the same answer (the chain is symmetric in its energy)
    assert rock_mode_frequency_hz(chain([m, m], k, bit=0), rock(k)) == pytest.approx(found)


def test_heavy_collar_on_a_stiff_joint_rides_on_the_rock_not_on_the_joint():
    # collar m1 -k- bit m2 on the rock k_n: m1 m2 w^4 - (k m2 + (k + k_n) m1) w^2 + k k_n = 0; the
    # lower root is the collar on the rock (~77 Hz), the upper one the bit on its joint (~3 kHz)
    m1, m2, k, k_n = 2000.0, 30.0, 1e10, 5e8
    b = k * m2 + (k + k_n) * m1
    lower = math.sqrt((b - math.sqrt(b**2 - 4 * m1 * m2 * k * k_n)) / (2 * m1 * m2)) / (2 * math.pi)
    assert rock_mode_frequency_hz(chain([m1, m2], k), rock(k_n)) == pytest.approx(lower, rel=1e-10)


def test_the_test_drill_rides_its_collar_on_the_rock():
    # test drill: 3 t collar on k_n = 5e8 N/m; carriage, shank and bit add little
    drill = prepare(scene())
    assert rock_mode_frequency_hz(drill.chain, drill.rock) == pytest.approx(math.sqrt(5e8 / 3000.0) / (2 * math.pi),
                                                                            rel=0.05)
    single = {"bodies": {"bit": {"mass_kg": 500.0}}, "connectors": {}, "impact_body": "bit", "rock_body": "bit"}
    alone = prepare(Scene.model_validate(scene_dict(**{"drill_string": single, "feed.acts_on": "bit"})))
    assert rock_mode_frequency_hz(alone.chain, alone.rock) == pytest.approx(
        math.sqrt(5e8 / 500.0 - (1.98e3 / 1000.0) ** 2) / (2 * math.pi), rel=1e-12)
