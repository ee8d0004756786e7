"""models.modal: the rock mode of the in-contact chain on chains with known answers; the scene glue."""

import math

import numpy as np
import pytest
from rpdrill.models.modal import rock_mode_frequency_hz
from rpdrill.studies.resonance import rock_mode_hz
from scenes import scene_dict


def test_one_body_on_the_rock_is_a_damped_oscillator():
    mass, rock_stiffness, rock_damping = 2000.0, 5e8, 4e4
    expected = math.sqrt(rock_stiffness / mass - (rock_damping / (2 * mass)) ** 2) / (2 * math.pi)
    found = rock_mode_frequency_hz([mass], [[0.0]], [[0.0]], 0, rock_stiffness, rock_damping)
    assert found == pytest.approx(expected, rel=1e-12)


def test_overdamped_rock_mode_has_no_frequency():
    assert rock_mode_frequency_hz([1.0], [[0.0]], [[0.0]], 0, 1.0, 3.0) == 0.0  # zeta = 1.5


def test_two_equal_bodies_pick_the_mode_that_rides_on_the_rock():
    # m -k- m -k_n: omega^2 = (3 -+ sqrt 5)/2 k/m; the lower mode holds 72 % of its strain energy
    # in the rock spring, the upper one 28 %
    k, m = 1e6, 10.0
    found = rock_mode_frequency_hz([m, m], [[k, -k], [-k, k]], np.zeros((2, 2)), 1, k, 0.0)
    assert found == pytest.approx(math.sqrt((3 - math.sqrt(5)) / 2 * k / m) / (2 * math.pi), rel=1e-12)
    # with the rock under the other body, the same answer (the chain is symmetric in its energy)
    assert rock_mode_frequency_hz([m, m], [[k, -k], [-k, k]], np.zeros((2, 2)), 0, k, 0.0) == pytest.approx(found)


def test_heavy_collar_on_a_stiff_joint_rides_on_the_rock_not_on_the_joint():
    # collar m1 -k- bit m2 on the rock k_n: m1 m2 w^4 - (k m2 + (k + k_n) m1) w^2 + k k_n = 0; the
    # lower root is the collar on the rock (~77 Hz), the upper one the bit on its joint (~3 kHz)
    m1, m2, k, k_n = 2000.0, 30.0, 1e10, 5e8
    b = k * m2 + (k + k_n) * m1
    lower = math.sqrt((b - math.sqrt(b**2 - 4 * m1 * m2 * k * k_n)) / (2 * m1 * m2)) / (2 * math.pi)
    found = rock_mode_frequency_hz([m1, m2], [[k, -k], [-k, k]], np.zeros((2, 2)), 1, k_n, 0.0)
    assert found == pytest.approx(lower, rel=1e-10)


def test_bad_shapes_are_refused():
    with pytest.raises(ValueError, match="bit_index"):
        rock_mode_frequency_hz([1.0, 2.0], np.zeros((2, 2)), np.zeros((2, 2)), 2, 1.0, 0.0)


def test_scene_glue_gives_the_test_drill_its_collar_on_rock_mode():
    # test drill: 3 t collar on k_n = 5e8 N/m; carriage, shank and bit add little
    found = rock_mode_hz(scene_dict())
    assert found == pytest.approx(math.sqrt(5e8 / 3000.0) / (2 * math.pi), rel=0.05)
    single = {"bodies": {"bit": {"mass_kg": 500.0}}, "connectors": {}, "impact_body": "bit", "rock_body": "bit"}
    alone = rock_mode_hz(scene_dict(**{"drill_string": single, "feed.acts_on": "bit"}))
    assert alone == pytest.approx(math.sqrt(5e8 / 500.0 - (1.98e3 / 1000.0) ** 2) / (2 * math.pi), rel=1e-12)
