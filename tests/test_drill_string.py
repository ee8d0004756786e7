"""The drill string as data: bodies and connectors by name, rods from geometry, couplings, waves.

The paper scene and the four-rod string run through the same builder; the segmented rod carries a
stress wave at the bar speed c = sqrt(E / rho).
Unit tests of models.drill.chain, models.definition.links and rocklaw.modes, with the prepared simulation's
outputs and start (models.solvers.simulation) and the pulse measures of models.evaluation.rod_outputs: they
import them.
"""

import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from commands import main
from pydantic import ValidationError
from scenes import read_yaml, result_of, scene, scene_dict, simulate

from rpdrill import Scene, load_scene
from rpdrill.models.definition.links import RATE, STRETCH, Coupling, Link
from rpdrill.models.drill.chain import axial_chain, link_load_n
from rpdrill.models.evaluation.rod_outputs import transmitted_pulse_n, travel_time_s
from rpdrill.models.solvers.simulation import prepare
from rpdrill.rocklaw.modes import check_mode_forces

# unit tests of: links and the chain built of them, their mode rows; a prepared scene's outputs and start; a
# rod's transmitted pulse and travel time
UNITS = ("rpdrill.models.definition.links", "rpdrill.models.drill.chain", "rpdrill.models.evaluation.rod_outputs",
         "rpdrill.models.solvers.simulation", "rpdrill.rocklaw.modes")

SCENES = Path(__file__).resolve().parents[1] / "studies" / "scenes"
ROD = {"length_m": 3.66, "diameter_m": 0.045, "bore_diameter_m": 0.012}
# 5 blows at 50 Hz: 2 transient and one block of 3 (two blocks of 2 so soon disagree: an UnsettledWarning)
QUICK = {"solver.end_time_s": 0.1, "metrics.transient_blows": 2, "metrics.block_blows": 3}


def rod_string(**rod_overrides) -> Scene:
    """Shank (rigid), two identical rods, bit: the smallest string with derived stiffnesses."""
    rod = ROD | rod_overrides
    return scene(drill_string={
            "bodies": {"carriage": {"mass_kg": 300.0}, "shank": {"mass_kg": 10.0}, "rod1": rod, "rod2": rod,
                       "bit": {"mass_kg": 8.0}},
            "connectors": {
                "shock_absorber": {"from": "carriage", "to": "shank", "stiffness_n_per_m": 2e6},
                "shank_coupling": {"from": "shank", "to": "rod1"},
                "coupling": {"type": "coupling", "from": "rod1", "to": "rod2"},
                "bit_coupling": {"from": "rod2", "to": "bit", "stiffness_n_per_m": 1e9}},
            "impact_body": "shank", "rock_body": "bit"}, impact__duration_s=2.5e-4)


def test_rod_mass_and_stiffness_follow_from_geometry():
    s = rod_string()
    chain = axial_chain(s)
    area = math.pi / 4 * (0.045**2 - 0.012**2)
    e_a = 210e9 * area
    assert chain.bodies[chain.index("rod1")].mass_kg == pytest.approx(7800.0 * area * 3.66)
    links = {link.name: link for link in chain.links}
    assert links["coupling"].stiffness_n_per_m == pytest.approx(e_a / 3.66)  # two half-rods in series
    assert links["shank_coupling"].stiffness_n_per_m == pytest.approx(2 * e_a / 3.66)  # rigid shank: one half
    assert links["bit_coupling"].stiffness_n_per_m == 1e9  # given values win
    assert isinstance(links["coupling"], Coupling) and not chain.is_linear
    assert s.drill_string.bodies["rod1"].wave_speed_m_per_s == pytest.approx(5189, abs=1)


def test_segments_split_mass_and_keep_total_compliance():
    chain = axial_chain(rod_string(segments=5))
    first, last = chain.groups["rod1"]
    assert last - first == 4
    masses = [chain.bodies[i].mass_kg for i in range(first, last + 1)]
    whole = axial_chain(rod_string())
    assert sum(masses) == pytest.approx(whole.bodies[whole.index("rod1")].mass_kg)
    inner = [link for link in chain.links if link.name.startswith("rod1[")]
    e_a_per_l = 210e9 * math.pi / 4 * (0.045**2 - 0.012**2) / 3.66
    assert [link.stiffness_n_per_m for link in inner] == pytest.approx([5 * e_a_per_l] * 4)
    # half-segments at both rod ends + 4 inner springs: the rod's compliance L / EA is kept
    coupling = next(link for link in chain.links if link.name == "coupling")
    assert coupling.stiffness_n_per_m == pytest.approx(5 * e_a_per_l)
    assert chain.impact_body == chain.index("shank") and chain.bit_body == chain.index("bit")


@pytest.mark.parametrize("change, message", [
    ({"drill_string.bodies.shank": {"mass_kg": 10.0, "length_m": 1.0}}, "not both"),
    ({"drill_string.bodies.shank": {"mass_kg": 10.0, "segments": 3}}, "segments > 1 needs a rod"),
    ({"drill_string.connectors.collar_bit_joint.stiffness_n_per_m": None}, "neither end is a rod"),
    ({"drill_string.connectors.collar_bit_joint.gap_m": 1e-4}, "does not apply to type 'spring_damper'"),
    ({"drill_string.connectors.collar_bit_joint.type": "weld"}, "'weld' is not one of spring_damper, coupling"),
    ({"drill_string.connectors.shank_collar_joint": None}, "a separate part"),
    ({"drill_string.rock_body": "collar_bit"}, "rock_body 'collar_bit' is not a body"),
    ({"drill_string.bodies.ground": {"mass_kg": 1.0}}, "reserved"),
])
def test_bad_drill_strings_are_refused_with_the_reason(change, message):
    with pytest.raises(ValidationError, match=message):
        Scene.model_validate(scene_dict(**change))


def test_collar_metrics_need_a_collar():
    s = rod_string()
    assert "collar_velocity_peak_m_per_s" not in prepare(s).outputs.metrics  # left out of the default outputs
    with pytest.raises(ValidationError, match="need a body named collar"):
        Scene.model_validate({**s.model_dump(by_alias=True, exclude={"effects", "outputs"}),
                              "outputs": {"metrics": ["collar_velocity_peak_m_per_s"]}})


def test_preloaded_string_with_couplings_is_in_static_equilibrium():
    s = rod_string(segments=3).model_copy(update={"start": "preloaded"})
    prepared = prepare(s)
    chain, q0 = prepared.chain, prepared.initial_positions_m
    rock = np.zeros(chain.size)
    rock[chain.bit_body] = s.rock.stiffness_n_per_m * q0[chain.bit_body]
    residual = chain.constant_forces() + link_load_n(chain, q0, np.zeros_like(q0)) - rock
    np.testing.assert_allclose(residual, 0.0, atol=1e-6 * s.feed.force_n)
    assert rock[chain.bit_body] == pytest.approx(s.feed.force_n)  # the feed rests on the rock


@pytest.fixture(scope="module")
def four_rod_run():
    s = load_scene(SCENES / "four_rod_string.yaml")
    return result_of(s.model_copy(update={"solver": s.solver.model_copy(update={"end_time_s": 0.3})}))


def test_paper_scene_and_four_rod_string_run_through_the_same_builder(four_rod_run):
    paper = result_of(load_scene(SCENES / "paper_base.yaml"))
    for run, bodies in ((paper, 4), (four_rod_run, 1 + 1 + 4 * 4 + 1)):
        assert run.position_m.shape[1] == bodies
        metrics = run.metrics
        assert metrics["penetration_rate_m_per_s"] > 0
        assert metrics["energy_balance_relative_error"] < 5e-3
        assert np.all(np.diff(run.bottom_m) >= 0)


def test_couplings_never_pull_and_do_open():
    run = result_of(rod_string(segments=2))
    chain = run.chain
    couplings = [i for i, link in enumerate(chain.links) if isinstance(link, Coupling)]
    stretch, rate = chain.link_stretch(run.position_m), chain.link_stretch(run.velocity_m_per_s)
    forces = np.stack([chain.links[i].force_n(stretch[:, i], rate[:, i]) for i in couplings], axis=-1)
    assert forces.max() <= 0.0  # F > 0 would pull the joined bodies together
    assert (forces == 0.0).any() and (forces < 0.0).any()  # it opens on rebound and closes again
    assert run.energy.relative_residual() < 5e-3


def wave_run(segments: int):
    data = read_yaml(SCENES / "wave_rod.yaml")
    data["drill_string"]["bodies"]["rod"]["segments"] = segments
    return simulate(Scene.model_validate(data))


def test_stress_wave_converges_and_travels_at_the_bar_speed():
    """A 0.2 ms pulse down a 3.66 m rod on a stiff rock: the transmitted pulse converges as the rod
    is split finer, arrives after L / c, and is doubled by the (nearly fixed) rock end."""
    runs = {n: wave_run(n) for n in (16, 32, 64)}
    grid = np.linspace(0.0, 1.3e-3, 1301)
    pulses = {n: transmitted_pulse_n(r, grid) for n, r in runs.items()}
    change = [np.max(np.abs(pulses[2 * n] - pulses[n])) / np.max(pulses[2 * n]) for n in (16, 32)]
    assert change[1] < 0.6 * change[0]  # measured 0.21 -> 0.10
    scene_64 = runs[64].scene
    rod = scene_64.drill_string.bodies["rod"]
    assert travel_time_s(runs[64]) == pytest.approx(rod.length_m / rod.wave_speed_m_per_s, rel=0.05)
    assert runs[64].rock_force_n.max() == pytest.approx(2 * scene_64.impact.amplitude_n, rel=0.05)


@pytest.mark.slow
def test_resolved_scene_uses_the_scene_file_keys(tmp_path):
    """The written scene names connectors' ends by the file's keys and reads back to the shipped four-rod
    string's drill string. Run for 5 blows, not 20 (the drill string as shipped; the run's length is not what is
    checked: a 0.4 s run and its plots took a third more CPU, 2.8 s against 1.8 s, measured)."""
    path, out = tmp_path / "four_rod_string.yaml", tmp_path / "out"
    path.write_text(yaml.safe_dump(scene_dict(SCENES / "four_rod_string.yaml", **QUICK)), encoding="utf-8")
    assert main(["simulate", str(path), "--out", str(out), "--quiet"]) == 0
    resolved = (out / "scene.resolved.yaml").read_text()
    assert "from: carriage" in resolved and "from_body" not in resolved
    assert load_scene(out / "scene.resolved.yaml").drill_string == load_scene(SCENES / "four_rod_string.yaml").drill_string


@pytest.mark.parametrize("link", [Link("bonded", 0, 1, 2e9, 1e3), Coupling("tight", 0, 1, 2e9, 0.0),
                                  Coupling("damped", 0, 1, 2e9, 1e4), Coupling("play", 0, 1, 2e9, 1e4, gap_m=1e-4)],
                         ids=lambda link: link.name)
def test_declared_link_modes_agree_with_the_closed_form(link):
    """Each connector type's mode rows (the exact and ODE formulations) equal its closed-form force
    (the Exudyn user function) in whatever mode a state lies, and the samples visit every mode."""
    rng = np.random.default_rng(2)
    samples = [{STRETCH: s, RATE: r} for s, r in zip(rng.uniform(-3e-4, 1e-4, 400), rng.uniform(-20.0, 20.0, 400))]
    assert check_mode_forces(link, samples, lambda v: link.force_n(v[STRETCH], v[RATE])) == []
    assert {link.initial_mode(v) for v in samples} == set(link.modes())


def gapped(gap_m: float, **changes) -> Scene:
    """The rod string preloaded, its middle coupling with a gap."""
    data = rod_string(segments=3).model_dump(by_alias=True, exclude_none=True)
    data["drill_string"]["connectors"]["coupling"]["gap_m"] = gap_m
    return Scene.model_validate({**data, "start": "preloaded", **changes})


@pytest.mark.parametrize("gap_m", [1e-4, 1e-3, 0.05])
def test_preloaded_string_with_a_gapped_coupling_is_in_exact_static_equilibrium(gap_m):
    """The equilibrium of a chain with gaps is piecewise linear: found exactly, the gap closed."""
    s = gapped(gap_m)
    prepared = prepare(s)
    chain, q0 = prepared.chain, prepared.initial_positions_m
    rock = np.zeros(chain.size)
    rock[chain.bit_body] = s.rock.stiffness_n_per_m * q0[chain.bit_body]
    residual = chain.constant_forces() + link_load_n(chain, q0, np.zeros_like(q0)) - rock
    np.testing.assert_allclose(residual, 0.0, atol=1e-9 * s.feed.force_n)
    assert rock[chain.bit_body] == pytest.approx(s.feed.force_n)
    coupling = next(link for link in chain.links if link.name == "coupling")
    assert coupling.stretch(q0) + gap_m < 0  # closed under the feed

