"""The examples of docs/extending.md (every Python block runs as printed when the site is built:
docs/page_examples.py), and the worked example checked: a new connector type (a threaded joint with axial
play) registered and used from YAML.
Unit tests of what the worked example extends, models.definition.links and rocklaw.modes, with its runs compared
by models.evaluation.compare: they import them."""

import re
from pathlib import Path

import numpy as np
import pytest
from ruamel.yaml import YAML
from scenes import result_of, scene_dict, simulate

from rpdrill import Scene
from rpdrill.models.definition.links import LINK_TYPES, RATE, STRETCH, Link
from rpdrill.models.evaluation.compare import compare_bottom_at, compare_histories
from rpdrill.rocklaw.modes import check_mode_forces

# unit tests of: a connector type registered and its mode rows; two runs' histories compared
UNITS = ("rpdrill.models.definition.links", "rpdrill.models.evaluation.compare", "rpdrill.rocklaw.modes")

DOC = Path(__file__).resolve().parents[1] / "docs" / "extending.md"
SHORT = {"solver.end_time_s": 0.2, "metrics.transient_blows": 3, "metrics.block_blows": 3,
         "impact.amplitude_n": 400e3, "impact.frequency_hz": 45.0}


def _blocks(language: str) -> list[str]:
    return re.findall(rf"```{language}\n(.*?)```", DOC.read_text(), flags=re.DOTALL)


RUNNABLE = [block for block in _blocks("python") if "class JointWithPlay" not in block]


def test_the_page_shows_each_way_with_an_example():
    assert len(RUNNABLE) >= 6
    for way in ("drill_string.bodies.clamp", '"extensions"', "rate_dependent_rock:RateDependentRock",
                "add_energy_term", "exu.SolveDynamic", "rpdrill.draw(model"):
        assert any(way in block for block in _blocks("python")) or way in DOC.read_text(), way


@pytest.fixture(scope="module")
def joint_type():
    namespace: dict = {}
    exec(next(b for b in _blocks("python") if "class JointWithPlay" in b), namespace)  # noqa: S102
    yield namespace["JointWithPlay"]
    LINK_TYPES.pop("joint_with_play", None)


def _scene(joint_type, **joint) -> Scene:
    # YAML 1.2, as rpdrill reads a scene file (studies.inputs.strict_yaml: ruamel.yaml's safe reader)
    connector = YAML(typ="safe", pure=True).load(next(b for b in _blocks("yaml") if b.startswith("collar_bit_joint:")))
    connector["collar_bit_joint"].update(joint)
    return Scene.model_validate(scene_dict(**SHORT, **{"drill_string.connectors.collar_bit_joint":
                                                       connector["collar_bit_joint"]}))


def test_joint_with_play_transmits_nothing_inside_its_play_and_keeps_the_energy_balance(joint_type):
    run = result_of(_scene(joint_type))
    chain = run.chain
    i = next(k for k, link in enumerate(chain.links) if link.name == "collar_bit_joint")
    link = chain.links[i]
    assert isinstance(link, joint_type) and link.gap_m == 2e-5
    stretch = chain.link_stretch(run.position_m)[:, i]
    inside = np.abs(stretch) < link.gap_m
    assert inside.any() and (~inside).any()  # the play is crossed
    assert np.all(link.force_n(stretch[inside], 0.0) == 0.0)
    assert run.energy.relative_residual() < 5e-3


def test_exudyn_agrees_with_the_exact_formulation_on_the_new_type(joint_type):
    """Over the first two blows, against the exact solution sampled at Exudyn's step (the reference to
    round-off: it runs the new type from its modes and agrees with the ODE, the test below). The
    rattling joint (k = 1e10 N/m on the 30 kg bit) needs a fine step: at 2e-5 s the bit velocity differs
    by 8 % of its range within the first blow, at 1e-6 s by 2.4e-4 (python benchmarks/bench_extending.py);
    later the rattle amplifies any difference (chaotic)."""
    s = _scene(joint_type)
    s = Scene.model_validate(s.model_dump(by_alias=True, exclude={"effects", "outputs"}) | {
        "solver": {"type": "rk44", "step_s": 1e-6, "end_time_s": 0.045},
        "metrics": {"transient_blows": 0, "block_blows": 2}})
    exact, exudyn = simulate(s, "exact", sample_interval_s=s.solver.step_s), simulate(s)
    velocity = compare_histories(exact, exudyn, 0.044)["bit_velocity_m_per_s"]["max_rel_to_range"]
    assert velocity < 2e-3  # measured 6.4e-4 (against the ODE at rtol 1e-10: the same)
    assert compare_bottom_at(exact, exudyn, 0.044)["rel"] < 1e-5  # measured 2e-7


def test_zero_play_reproduces_the_bonded_joint(joint_type):
    played = simulate(_scene(joint_type, gap_m=0.0))
    bonded = simulate(_scene(joint_type, type="spring_damper", gap_m=None))
    np.testing.assert_allclose(played.bottom_m, bonded.bottom_m, rtol=0, atol=1e-12)


def test_declared_modes_agree_with_the_closed_form(joint_type):
    link = joint_type("play", 0, 1, 1e10, 1e3, gap_m=2e-5)
    rng = np.random.default_rng(3)
    samples = [{STRETCH: s, RATE: r} for s, r in zip(rng.uniform(-6e-5, 6e-5, 300), rng.uniform(-2.0, 2.0, 300))]
    assert check_mode_forces(link, samples, lambda v: link.force_n(v[STRETCH], v[RATE])) == []
    assert {link.initial_mode(v) for v in samples} == set(link.modes())


@pytest.mark.slow
def test_exact_formulation_runs_the_new_type_from_its_modes(joint_type):
    """Two blows, the second crushing (the rattle amplifies differences over many): the exact solution
    against the ODE."""
    s = _scene(joint_type)
    s = Scene.model_validate(s.model_dump(by_alias=True, exclude={"effects", "outputs"}) | {
        "solver": {"formulation": "exact", "end_time_s": 2 / 45.0}, "metrics": {"transient_blows": 0, "block_blows": 2}})
    exact, ode = simulate(s), simulate(s, "ode", relative_tolerance=1e-12, absolute_tolerance=1e-15)
    assert exact.bottom_m[-1] > 0 and exact.solver.mode_switches == ode.solver.mode_switches
    assert abs(exact.bottom_m[-1] - ode.bottom_m[-1]) <= 1e-9 * exact.bottom_m[-1]


def test_a_nonlinear_type_without_modes_is_refused_by_the_formulations_that_need_them(joint_type):
    class Undeclared(joint_type):
        modes = Link.modes  # back to the base class's: only a linear link has that one

    LINK_TYPES["undeclared"] = Undeclared
    try:
        s = _scene(joint_type, type="undeclared")
        for formulation in ("exact", "ode"):
            with pytest.raises(ValueError, match="connector collar_bit_joint declare no modes"):
                simulate(s, formulation)
    finally:
        LINK_TYPES.pop("undeclared")
