"""One way to run a prepared scene, typed results and run options (the public API's shape)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from commands import main
from scenes import PAPER_BASE

import rpdrill

QUICK = {"solver": {"formulation": "exact", "end_time_s": 0.3}}


def test_dir_shows_the_public_names_only():
    names = dir(rpdrill)
    assert names == sorted(rpdrill.__all__)
    assert not {"Any", "TYPE_CHECKING", "annotations"} & set(names)
    assert all(callable(getattr(rpdrill, name)) for name in names)  # each resolves (classes and functions)


def test_a_result_carries_typed_records_and_no_info_dict():
    result = rpdrill.simulate(rpdrill.load_scene(PAPER_BASE).with_(QUICK))
    assert not hasattr(result.raw, "info")
    assert result.steady_state.regime is rpdrill.Regime.TIME_RUN and result.steady_state.requested == "time"
    assert result.steady_state.regime_name == "time run" and result.steady_state.period_blows is None
    solver = result.solver
    assert solver.samples == len(result.time_s) and solver.mode_switches == len(solver.switch_times_s) > 0
    assert sum(solver.switches_into.values()) == solver.mode_switches and solver.sub_step_s > 0
    assert result.exudyn_model is None and result.source == "scene 'test_drill'" and result.warnings == ()


def test_a_periodic_result_holds_its_orbit_with_complex_multipliers(tmp_path):
    scene = rpdrill.load_scene(PAPER_BASE).with_({"solver": {**QUICK["solver"], "steady_state": "periodic"}})
    result = rpdrill.simulate(scene)
    steady = result.steady_state
    assert steady.regime is rpdrill.Regime.PERIODIC and steady.regime_name == "period-1"
    orbit = steady.orbit
    assert all(isinstance(mu, complex) for mu in orbit.multipliers) and 0 < steady.floquet_max_abs < 1
    assert steady.floquet_max_abs == max(abs(mu) for mu in orbit.multipliers)
    assert len(orbit.state) == len(orbit.state_labels) and orbit.residual < 1e-8
    assert result.metrics["advance_per_blow_m"] == pytest.approx(orbit.advance_per_blow_m, rel=1e-9)
    rpdrill.save_result(result, tmp_path)
    written = json.loads((tmp_path / "summary.json").read_text())["run"]["steady_state"]
    assert written["regime"] == "periodic" and written["regime_name"] == "period-1"
    multipliers = np.array([complex(*mu) for mu in written["orbit"]["multipliers"]])
    np.testing.assert_allclose(multipliers, np.array(orbit.multipliers), rtol=1e-15)


def test_a_wave_scene_whose_cap_comes_before_it_settles_says_so_with_the_time_run():
    scene = rpdrill.load_scene("top_hammer_waves").with_({"solver.steady_state": "periodic",
                                                          "solver.formulation": "exact",
                                                          "solver.end_time_s": 0.05, "metrics.transient_blows": 1,
                                                          "metrics.block_blows": 1, "impact.frequency_hz": 40.0})
    result = rpdrill.simulate(scene)
    assert result.steady_state.regime is rpdrill.Regime.NOT_FOUND and result.steady_state.blows == 2
    assert "not settled within the cap" in result.steady_state.note and result.time_s[-1] == pytest.approx(0.05)


def test_warnings_of_a_run_are_shown_and_kept():
    """Explicit Euler on the drill's undamped modes: warned as the run starts (and small enough a step not to
    diverge over two blows)."""
    scene = rpdrill.load_scene(PAPER_BASE).with_({"solver.type": "explicit_euler", "solver.step_s": 5e-6,
                                                 "solver.end_time_s": 0.04, "metrics.transient_blows": 1,
                                                 "metrics.block_blows": 1, "outputs": {
                                                     "metrics": ["penetration_rate_m_per_s"]}})
    with pytest.warns(Warning, match="explicit_euler is unstable at any step") as shown:
        result = rpdrill.simulate(scene)
    assert len(result.warnings) == 1 and result.warnings[0] in {str(w.message) for w in shown}


@pytest.mark.parametrize(("call", "given", "message"), [
    (rpdrill.run_study, {"workers": 0}, "rpdrill.run_study: workers: 0: must be a whole number of at least 1"),
    (rpdrill.run_study, {"overwrite": True}, ("rpdrill.run_study: overwrite: not an option of this call; its "
                                             "options: workers, dask, out, budget, quiet")),
    (rpdrill.sensitivity, {"quiet": "no"}, "rpdrill.sensitivity: quiet: 'no': must be True or False"),
    (rpdrill.calibrate, {"budget": 3}, "rpdrill.calibrate: budget: 3: .*rpdrill.Budget"),
    (rpdrill.accuracy, {"options": {"workers": 2}}, "rpdrill.accuracy: options: .*rpdrill.RunOptions"),
])
def test_run_options_are_checked_in_one_place_naming_the_call(call, given, message):
    with pytest.raises(rpdrill.InputError, match=message):
        call("no_such_file.yaml", **given)


def test_run_options_given_whole_or_by_name_run_the_same_study(tmp_path):
    study = rpdrill.load_study("paper/frequency_scan", formulation="exact")
    study = rpdrill.load_study(_small(study, tmp_path), formulation="exact")
    whole = rpdrill.run_study(study, rpdrill.RunOptions(workers=1, out=tmp_path / "whole"))
    named = rpdrill.run_study(study, workers=1, out=tmp_path / "named")
    costs = ["wall_time_s", "cpu_time_s"]  # what a run cost, not what it gave
    assert whole.drop(columns=costs).equals(named.drop(columns=costs))
    with pytest.raises(rpdrill.InputError, match=r"RunOptions: workers: -1"):
        rpdrill.RunOptions(workers=-1)
    assert main(["study", str(tmp_path / "small.yaml"), "--out", str(tmp_path / "cli"), "--workers", "1",
                 "--formulation", "exact", "--quiet"]) == 0


def _small(study: rpdrill.Study, folder) -> str:
    """A three-point copy of a shipped study's file, its base scene by the shipped file's path."""
    import yaml

    data = yaml.safe_load(study.source.read_text())
    data["base_scene"] = str((study.source.parent / data["base_scene"]).resolve())
    data["scan"] = {"impact.frequency_hz": [55.0, 60.0, 65.0]}
    data["plots"] = []
    path = folder / "small.yaml"
    path.write_text(yaml.safe_dump(data))
    return str(path)
