"""Only the effects a scene calls for are built; outputs pull in what they need.
Unit tests of models.solvers.simulation (the effects, outputs and rock law a prepared scene holds): they
import it."""

import numpy as np
import pytest
import yaml
from commands import main
from scenes import CRUSHING, result_of, scene, scene_dict, simulate

from rpdrill import build_exudyn
from rpdrill.models.solvers.simulation import prepare

# unit tests of: the effects, outputs and rock law a prepared scene holds
UNITS = ("rpdrill.models.solvers.simulation",)

SHORT = {"solver__end_time_s": 0.25, "metrics__transient_blows": 3, "metrics__block_blows": 4}
CRUSH = {k.replace(".", "__"): v for k, v in CRUSHING.items()}
# what a penetration-rate scan needs: the same physics, no torsion, no forces, no energy
RATE_ONLY = {"effects": {"rock_damping": True, "joint_damping": True},
             "outputs": {"metrics": ["penetration_rate_m_per_s"]}}


def test_full_model_when_no_effects_section():
    s = prepare(scene())
    assert s.effects.torsion and s.effects.rock_damping and s.effects.rock_plasticity and s.effects.joint_damping
    assert "full model" in s.effects.reasons["torsion"]
    assert "rock_force_n" in s.outputs.timeseries and "energy" in s.needed_data


def test_rate_only_scene_drops_torsion_sensors_and_storage():
    full, lean = build_exudyn(scene(**CRUSH)), build_exudyn(scene(**CRUSH, **RATE_ONLY))
    assert (full.coordinate_count, lean.coordinate_count) == (5, 4)
    assert set(full.sensors) - set(lean.sensors) == {"rock", "impact", "phi", "omega"}
    assert lean.settings.solution.sensors.writePeriod == lean.simulation.settings.output_interval_s
    assert full.settings.solution.sensors.writePeriod == 0.0  # energy needs every step
    effects = lean.simulation.effects
    assert effects.rock_plasticity and "needed by outputs" in effects.reasons["rock_plasticity"]


def test_dropping_decoupled_or_unused_parts_leaves_axial_results_unchanged():
    full = result_of(scene(**CRUSH, **SHORT))
    lean = result_of(scene(**CRUSH, **SHORT, **RATE_ONLY))
    assert full.torsion_angle_rad is not None and lean.torsion_angle_rad is None
    rate_full = full.metrics["penetration_rate_m_per_s"]
    rate_lean = lean.metrics["penetration_rate_m_per_s"]
    assert rate_full > 0 and rate_lean == pytest.approx(rate_full, rel=1e-12)
    common = np.isin(np.round(full.time_s, 12), np.round(lean.time_s, 12))
    np.testing.assert_allclose(full.position_m[common], lean.position_m, rtol=1e-12, atol=1e-15)


def test_an_output_pulls_in_its_effect():
    s = prepare(scene(effects={}, outputs={"timeseries": ["torsion_angle_rad"]}))
    assert s.effects.torsion and s.effects.reasons["torsion"] == "needed by outputs: torsion_angle_rad"
    assert not s.effects.rock_damping and s.effects.reasons["rock_damping"] == "not asked for"
    assert not s.effects.rock_plasticity  # nothing asked for the penetration


def test_contradictory_request_is_a_clear_error(tmp_path, capsys):
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(scene_dict(effects={"torsion": False}, outputs={"timeseries": ["torsion_angle_rad"]})))
    assert main(["simulate", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "effects.torsion is false but outputs torsion_angle_rad need it" in err and str(path) in err


def test_torsion_needs_its_section():
    with pytest.raises(ValueError, match="needs a torsion section"):
        scene(torsion=None, outputs={"timeseries": ["torsion_angle_rad"]})


def test_elastic_rock_without_plasticity_never_crushes():
    s = scene(**CRUSH, **SHORT, effects={"rock_damping": True, "joint_damping": True},
              outputs={"timeseries": ["rock_force_n"]})
    r = simulate(s)
    assert not r.simulation.effects.rock_plasticity and not r.simulation.rock.crushes
    assert np.all(r.bottom_m == 0.0)
    assert r.rock_force_n.max() > s.rock.threshold_n  # no cap without the slider


def test_rock_damping_off_removes_the_term():
    law = prepare(scene(effects={"rock_plasticity": True})).rock
    assert law.damping_n_s_per_m == 0.0 and law.force(1e-5, 3.0, law.initial_state()) == law.force(1e-5, 0.0, law.initial_state())


def test_resolved_scene_lists_effects_and_reasons(tmp_path):
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(scene_dict(**{"solver.end_time_s": 0.1, "metrics.transient_blows": 1,
                                                 "metrics.block_blows": 2}, **RATE_ONLY)))
    assert main(["simulate", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    resolved = yaml.safe_load((tmp_path / "out" / "scene.resolved.yaml").read_text())
    assert resolved["effects"]["torsion"] is False and resolved["effects"]["reasons"]["torsion"] == "not asked for"
    header = (tmp_path / "out" / "timeseries.csv").read_text().splitlines()[0]
    assert "torsion" not in header and "rock_force_n" not in header


def test_ode_and_exact_formulations_follow_the_same_switches():
    """Like with like: without torsion, rock damping and plasticity, all three build the same model."""
        
    lean = scene(**CRUSH, solver__end_time_s=0.1, metrics__transient_blows=1, metrics__block_blows=2,
                 effects={"joint_damping": True}, outputs={"timeseries": ["rock_force_n"]})
    runs = {"exudyn": simulate(lean), "ode": simulate(lean, "ode", relative_tolerance=1e-9), "exact": simulate(lean, "exact")}
    for result in runs.values():
        assert result.torsion_angle_rad is None and np.all(result.bottom_m == 0.0)
        assert result.rock_force_n.max() > lean.rock.threshold_n  # no slider: the spring is not capped
    end = {name: r.bit_position_m[-1] for name, r in runs.items()}
    assert end["ode"] == pytest.approx(end["exact"], rel=1e-6)
    assert end["exudyn"] == pytest.approx(end["exact"], rel=1e-3)
