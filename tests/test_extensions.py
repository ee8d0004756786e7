"""An extended drill is a first-class drill: what a multibody engineer adds in Python (items on the built
model, extensions named by the scene, rock laws by import path) is stepped, solved, accounted, recorded and
drawn like the rest. Each failure the issue found is a test here (studies: tests/test_extension_studies.py).
Where they check a prepared scene's step, a pickled simulation's run (what a worker does), the drawing's tags and
a run folder's solution as view_solution loads it, unit tests of models.solvers.simulation, models.runs.scene_run,
studies.drawings.system_drawing and studies.drawings.drill_animation: they import them."""

from __future__ import annotations

import json
import math
import pickle
from pathlib import Path

import exudyn
import numpy as np
import pandas as pd
import pytest
import user_rig
import yaml
from scenes import crushing_scene

import rpdrill
from rpdrill.models.runs.scene_run import run as run_simulation
from rpdrill.models.solvers.simulation import prepare

# unit tests of: a prepared scene's step and its run after pickling; the drawing's tags; a run folder's solution
UNITS = ("rpdrill.models.runs.scene_run", "rpdrill.models.solvers.simulation", "rpdrill.studies.drawings.drill_animation",
         "rpdrill.studies.drawings.system_drawing")

ROOT = Path(__file__).resolve().parents[1]
# the tests' rig (tests/user_rig.py) is code of one's own: allowed for these scenes (a scene runs none unasked)
PAPER = rpdrill.load_scene(ROOT / "studies" / "scenes" / "paper_base.yaml", allow_code=["user_rig"]).with_(
    {"solver.end_time_s": 0.3})
CLAMP = {"function": "user_rig:add_clamp", "parameters": {"mass_kg": 300.0, "stiffness_n_per_m": 1.0e12}}
SHORT = {"solver.end_time_s": 0.1, "metrics.transient_blows": 1, "metrics.block_blows": 3}


def rate(result) -> float:
    return result.metrics["penetration_rate_m_per_s"]


def write(path: Path, scene: rpdrill.Scene) -> None:
    """The scene as a scene file (as a run folder's scene.resolved.yaml holds it)."""
    path.write_text(yaml.safe_dump(scene.model_dump(mode="json", by_alias=True, exclude_none=True), sort_keys=False))


def clamped(scene=PAPER, **parameters):
    model = rpdrill.build_exudyn(scene)
    user_rig.add_clamp(model, **{**CLAMP["parameters"], **parameters})
    return model


def test_a_stiff_clamp_added_in_python_runs_at_the_step_it_needs_and_equals_a_heavier_collar():
    """Why 1: the step ignored what was added (10 000 steps where the clamp needs 15 547, and a rock that
    diverged). The step now follows the assembled system: the clamp written as a scene body gets the same."""
    model = clamped()
    result = model.run()
    as_body = PAPER.with_({"drill_string.bodies.clamp": {"mass_kg": 300.0},
                           "drill_string.connectors.clamp_joint": {"from": "collar", "to": "clamp",
                                                                   "stiffness_n_per_m": 1.0e12}})
    body_step = prepare(as_body).settings.step_s
    assert body_step < 0.2 * prepare(PAPER).settings.step_s  # the clamp's mode sets the step
    assert result.raw.simulation.settings.step_s == pytest.approx(body_step, rel=1e-9)
    assert result.exudyn_model.step_s == pytest.approx(body_step, rel=1e-9)
    heavier = PAPER.with_({"drill_string.bodies.collar.mass_kg": 1830.0 + 300.0})
    exact = rate(rpdrill.simulate(heavier, formulation="exact"))
    assert rate(result) == pytest.approx(exact, rel=2e-3)


def test_a_diverged_run_never_advises_a_step_larger_than_the_one_that_diverged():
    """Why 1: 'diverged ... try solver.step_s 8.22e-05' after 5e-05 diverged."""
    model = clamped(PAPER.with_({"solver.step_s": 5e-5, "solver.type": "rk44", "solver.preset": None}))
    with pytest.warns(rpdrill.StepLimitWarning, match="exceeds the stability limit"), pytest.raises(rpdrill.SimulationFailed) as failed:
        model.run()
    advised = float(str(failed.value).split("try solver.step_s ")[1].split()[0])
    assert "diverged at t" in str(failed.value) and advised < 5e-5 / 2 * (1 + 1e-9)


def test_exudyns_own_solve_dynamic_runs_the_physics_of_run():
    """Why 2: exu.SolveDynamic on a built model left the rock uncrushed (2.54e-4 m against 5.29e-3 m)."""
    reference = rpdrill.build_exudyn(PAPER).run()
    for solver in ({}, {"solverType": "scene's"}):
        model = rpdrill.build_exudyn(PAPER)
        model.mbs.Assemble()
        options = {"solverType": model.solver_type} if solver else {}
        assert exudyn.SolveDynamic(model.mbs, model.settings, **options)
        bit = model.mbs.GetNodeOutput(model.bodies["bit"].node, exudyn.OutputVariableType.Coordinates)
        assert bit == pytest.approx(reference.raw.bit_position_m[-1], rel=1e-3)  # Exudyn's default solver too
        assert rate(model.result()) == pytest.approx(rate(reference), rel=0 if solver else 2e-3)
    assert reference.raw.bottom_m[-1] > 1e-3  # the rock crushed


def test_a_pre_step_function_set_on_mbs_runs_beside_the_models_or_is_refused():
    """Why 2: a user's own mbs.SetPreStepUserFunction replaced the rock's update and was called 0 times."""
    reference = rpdrill.build_exudyn(PAPER).run()
    model = rpdrill.build_exudyn(PAPER)
    calls = []
    model.mbs.SetPreStepUserFunction(lambda mbs, t: calls.append(t) or True)
    result = model.run()
    steps = round(PAPER.solver.end_time_s / result.raw.simulation.settings.step_s)
    assert len(calls) == steps and rate(result) == rate(reference)
    assert result.exudyn_model.foreign_pre_step
    model = rpdrill.build_exudyn(PAPER)
    model.mbs.SetPreStepUserFunction(lambda mbs, t: True)
    exudyn.SolveDynamic(model.mbs, model.settings, solverType=model.solver_type)
    with pytest.raises(RuntimeError, match="add_pre_step"):
        model.result()
    added = rpdrill.build_exudyn(PAPER)
    added.add_pre_step(lambda mbs, t: calls.append(t) or True)
    assert rate(added.run()) == rate(reference)


def test_sensors_of_ones_own_are_in_the_time_series_and_time_is_a_plain_column():
    """Why 6: sensors of one's own were read back through mbs only; time_s was index and column at once."""
    model = clamped(stiffness_n_per_m=1e9)
    frame = model.run().timeseries
    assert "clamp_velocity" in frame and frame.index.equals(pd.RangeIndex(len(frame)))
    sensor = next(i for i in range(model.mbs.systemData.NumberOfSensors())
                  if model.mbs.GetSensor(i)["name"] == "clamp_velocity")
    stored = model.mbs.GetSensorStoredData(sensor)
    np.testing.assert_allclose(frame["clamp_velocity"], np.interp(frame["time_s"], stored[:, 0], stored[:, 1]))
    assert np.ptp(frame["clamp_velocity"]) > 0.05
    events = pd.DataFrame({"time_s": [0.05, 0.1], "event": ["a", "b"]})
    merged = pd.merge_asof(events, frame, on="time_s")  # failed until reset_index
    assert len(merged) == 2 and merged["time_s"].tolist() == [0.05, 0.1]


def test_a_damped_clamp_enters_the_energy_account():
    """Why 4: the balance was 9.4e-6 without the clamp and 7.5e-3 with it, and nothing said why."""
    plain = rpdrill.build_exudyn(PAPER).run().metrics["energy_balance_relative_error"]
    result = clamped(stiffness_n_per_m=1e9, damping_n_s_per_m=2e4).run()
    error = result.metrics["energy_balance_relative_error"]
    assert error < 1e-3 and error < 10 * plain, (error, plain)
    assert {"Mass1D 'clamp'", "ConnectorCoordinateSpringDamper 'clamp_joint'"} <= \
        {name.split(" (")[0] for name in result.user_energy.accounted}


def test_an_item_the_account_cannot_take_makes_the_balance_not_a_number_unless_declared():
    model = rpdrill.build_exudyn(PAPER)
    user_rig.add_friction_clamp(model, 300.0, 1e9, 2e4, declare=False)
    result = model.run()
    assert math.isnan(result.metrics["energy_balance_relative_error"])
    assert result.user_energy.unaccounted == ("ConnectorCoordinateSpringDamper 'friction_joint' (object 12)",)
    assert "add_energy_term" in result.user_energy.note
    model = rpdrill.build_exudyn(PAPER)
    user_rig.add_friction_clamp(model, 300.0, 1e9, 2e4, declare=True)
    declared = model.run()
    assert declared.metrics["energy_balance_relative_error"] < 1e-3
    assert declared.user_energy.declared == ("friction joint, stored", "friction joint, dissipated")
    with pytest.raises(ValueError, match="kind 'lost' is not one of stored, dissipated, work_in"):
        model.add_energy_term("x", "lost", lambda model, t: t)


@pytest.mark.slow
def test_an_extension_named_by_the_scene_is_applied_in_every_run_and_recorded(tmp_path):
    scene = PAPER.with_({"extensions": {"clamp": {**CLAMP, "parameters": {"mass_kg": 300.0, "stiffness_n_per_m": 1e9}}}})
    result = rpdrill.simulate(scene)
    by_hand = clamped(stiffness_n_per_m=1e9).run()
    assert rate(result) == rate(by_hand) and result.exudyn_model.extensions == ("clamp",)
    simulation = pickle.loads(pickle.dumps(prepare(scene)))  # data: a worker rebuilds the model by name
    assert rate(run_simulation(simulation)) == rate(by_hand)
    rpdrill.save_result(result, tmp_path)
    recorded = rpdrill.load_scene(tmp_path / "scene.resolved.yaml", allow_code=["user_rig"]).extensions["clamp"]
    assert recorded.recorded["import_path"] == "user_rig:add_clamp" and recorded.recorded["file"].endswith("user_rig.py")
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["provenance"]["extensions"]["clamp"]["parameters"]["stiffness_n_per_m"] == 1e9
    assert (tmp_path / "drill.png").stat().st_size > 10_000


def test_an_extension_that_changes_the_motion_is_refused_by_the_exact_and_ode_formulations():
    scene = PAPER.with_({"extensions": {"clamp": CLAMP}})
    for formulation in ("exact", "ode"):
        with pytest.raises(rpdrill.InputError, match=f"'{formulation}' cannot run this scene: extension 'clamp' "
                           r"\(user_rig:add_clamp\) adds to the Exudyn model"):
            rpdrill.simulate(scene, formulation=formulation)
    watching = PAPER.with_({"extensions": {"sensor": {"function": "user_rig:add_sensors"}}, **SHORT})
    exact = rpdrill.simulate(watching, formulation="exact")  # changes_motion = False: it adds nothing they miss
    assert rate(exact) == rate(rpdrill.simulate(PAPER.with_(SHORT), formulation="exact"))
    assert "bit_speed_sensor" in rpdrill.simulate(watching).timeseries


@pytest.mark.parametrize(("changes", "message"), [
    ({"extensions.clamp.parameters.mass_kg": "heavy"}, "extensions.clamp.parameters.mass_kg: 'heavy': a number is required"),
    ({"extensions.clamp.parameters.mass": 1.0}, ("extensions.clamp.parameters.mass: 1.0: not a parameter of "
     "user_rig:add_clamp; its parameters: mass_kg, stiffness_n_per_m, damping_n_s_per_m, body")),
    ({"extensions.clamp.parameters.stiffness_n_per_m": None}, "extensions.clamp.parameters.stiffness_n_per_m: missing"),
    ({"extensions.clamp.function": "user_rig:no_such"}, ("extensions.clamp.function: 'user_rig:no_such': module "
     "'user_rig' has no 'no_such'")),
    ({"extensions.clamp.function": "no_such_module:f"}, ("extensions.clamp.function: 'no_such_module:f': module "
     "'no_such_module' is code of one's own, which a scene runs only when the user allows it")),
    ({"extensions.clamp.function": "user_rig.no_such_module:f"}, "cannot import module 'user_rig.no_such_module'"),
    ({"extensions.other.parameters.mass_kg": 1.0}, "'other' is not in the scene's extensions"),
])
def test_an_extensions_keys_are_checked_as_strictly_as_the_scenes(changes, message):
    scene = PAPER.with_({"extensions": {"clamp": CLAMP}})
    with pytest.raises(rpdrill.InputError) as error:
        scene.with_(changes)
    assert message in str(error.value)


def test_a_body_and_a_connector_added_by_key_path_run_in_every_formulation():
    """Why 5: Scene.with_: drill_string.bodies.clamp: unknown scene key path."""
    scene = crushing_scene(**{k.replace(".", "__"): v for k, v in SHORT.items()}).with_({
        "drill_string.bodies.clamp": {"mass_kg": 200.0},
        "drill_string.connectors.clamp_joint": {"from": "collar", "to": "clamp", "stiffness_n_per_m": 5e7,
                                                "damping_n_s_per_m": 1e3}})
    rates = {formulation: rate(rpdrill.simulate(scene, formulation=formulation)) for formulation in ("exact", "ode")}
    rates["exudyn"] = rate(rpdrill.simulate(scene.with_({"solver.step_s": 2e-6}), formulation="exudyn"))
    assert rates["exact"] > 0 and rates["ode"] == pytest.approx(rates["exact"], rel=1e-6)
    assert rates["exudyn"] == pytest.approx(rates["exact"], rel=1e-3)
    without = rate(rpdrill.simulate(scene.with_({"drill_string.bodies.clamp": None,
                                                 "drill_string.connectors.clamp_joint": None}), formulation="exact"))
    assert abs(without - rates["exact"]) > 1e-3 * rates["exact"]  # the branch body acts
    with pytest.raises(rpdrill.InputError, match=r"'clamp' is not in the scene's drill_string.bodies; .*\(a new one "
                       r"is given whole: drill_string.bodies.clamp: \{...\}\)"):
        crushing_scene().with_({"drill_string.bodies.clamp.mass_kg": 1.0})


def test_a_rock_law_by_import_path_is_the_built_in_law_when_it_is_the_paper_law_under_another_name():
    """Why 3: a registered law was refused ('rate_jenkins': Input should be 'jenkins' or 'bilinear')."""
    with pytest.raises(rpdrill.InputError, match="rock.law: 'rate_jenkins': no installed package registers a rock law "
                       "named 'rate_jenkins' .*'package.module:Class'"):
        PAPER.with_({"rock.law": "rate_jenkins"})
    values = PAPER.rock.completed()
    own = PAPER.with_({"rock": {"law": "user_rig:RenamedJenkins", "parameters": {
        "stiffness_n_per_m": values.stiffness_n_per_m, "damping_n_s_per_m": values.damping_n_s_per_m,
        "threshold_n": values.threshold_n}}})
    for formulation in ("exact", "exudyn"):
        built_in, renamed = rpdrill.simulate(PAPER, formulation=formulation), rpdrill.simulate(own, formulation=formulation)
        assert renamed.raw.simulation.rock.name == "renamed_jenkins"
        assert rate(renamed) == pytest.approx(rate(built_in), rel=1e-6)
        assert renamed.metrics["crushing_work_j"] == pytest.approx(built_in.metrics["crushing_work_j"], rel=1e-6)


def test_the_crushing_work_is_the_work_of_the_law_that_ran():
    """Why 4: with a rock law of one's own, crushing_work_j used the scene's F_th."""
    values = PAPER.rock.completed()
    own = PAPER.with_({"rock": {"law": "user_rig:RenamedJenkins", "parameters": {
        "stiffness_n_per_m": values.stiffness_n_per_m, "damping_n_s_per_m": values.damping_n_s_per_m,
        "threshold_n": 0.5 * values.threshold_n}}})
    result = rpdrill.simulate(own, formulation="exact")
    advance = result.metrics["penetration_rate_m_per_s"] * (result.metrics["window_end_s"] - result.metrics["window_start_s"])
    assert result.metrics["crushing_work_j"] == pytest.approx(0.5 * values.threshold_n * advance, rel=1e-6)


@pytest.mark.parametrize(("parameters", "message"), [
    ({"stiffness_n_per_m": "5e8", "damping_n_s_per_m": 0.0, "threshold_n": 1e5}, ("rock.parameters.stiffness_n_per_m: "
     "'5e8': a number is required")),
    ({"stiffness_n_per_m": 5e8, "threshold_n": 1e5}, "rock.parameters.damping_n_s_per_m: missing"),
    ({"stiffness_n_per_m": 5e8, "damping_n_s_per_m": 0.0, "threshold_n": 1e5, "friction": 1.0},
     "rock.parameters.friction: 1.0: not a parameter of user_rig:RenamedJenkins"),
])
def test_a_rock_laws_own_keys_are_checked_as_strictly_as_a_built_in_ones(parameters, message):
    with pytest.raises(rpdrill.InputError) as error:
        PAPER.with_({"rock": {"law": "user_rig:RenamedJenkins", "parameters": parameters}})
    assert message in str(error.value)


def test_a_formulation_a_rock_law_cannot_run_is_refused_naming_what_is_missing():
    own = PAPER.with_({"rock": {"law": "user_rig:ForceOnlyRock", "parameters": {
        "stiffness_n_per_m": 5e8, "damping_n_s_per_m": 1980.0, "threshold_n": 138e3}}, **SHORT})
    with pytest.raises(rpdrill.InputError, match="rock law force_only declare no modes .*modes\\(\\) and initial_mode"):
        rpdrill.simulate(own, formulation="exact")
    assert rate(rpdrill.simulate(own)) > 0  # the Exudyn formulation needs no mode table
    with pytest.raises(rpdrill.InputError, match="a class that does not subclass rocklaw.base.RockLaw"):
        PAPER.with_({"rock": {"law": "rpdrill.rocklaw.catalog:RockProperties", "parameters": {
            "description": "x", "threshold_n": 1.0, "stiffness_n_per_m": 1.0, "damping_n_s_per_m": 1.0}}},
            allow_code=["rpdrill.rocklaw"])


def test_draw_an_extended_model_from_its_exudyn_graphics(tmp_path):
    """Why 6: rpdrill.draw(model, ...) raised AttributeError; the drawing showed the scene's bodies only."""
    from matplotlib.figure import Figure

    from rpdrill.studies.drawings.system_drawing import SystemPicture

    model = clamped(PAPER.with_(SHORT), stiffness_n_per_m=1e9)
    assert rpdrill.draw(model, tmp_path / "model.png").stat().st_size > 10_000
    assert rpdrill.draw(model, tmp_path / "model.svg").stat().st_size > 10_000
    _points, tags = SystemPicture(Figure().add_subplot(), model.mbs, model.built_items["objects"]).show()
    clamp = next((point, user) for point, text, user, _ in tags if text.startswith("clamp\n300 kg"))
    collar = model.mbs.GetObjectOutputBody(model.bodies["collar"].object, exudyn.OutputVariableType.Position, [0, 0, 0])
    assert clamp[1] and clamp[0] == pytest.approx(collar)  # the user's body, where it is, in its own colour
    assert ("clamp_joint", True) in {(text, user) for _, text, user, _ in tags}  # and its connector
    # its animation: test_view_solution_replays_an_extended_run_... (rpdrill simulate --animate)


@pytest.mark.slow
def test_view_solution_replays_an_extended_run_and_refuses_one_it_cannot_rebuild(tmp_path, monkeypatch):
    """Why 6: view_solution of an extended run failed (SetODE2Coords: incompatible size of vectors). The
    animation at 4 frames a blow, not 20 (as tests/test_drill_drawing.py's command test: each frame is drawn
    alike, the first is the one read; three quarters of this test's CPU went into drawing 60 frames, measured)."""
    from commands import main
    from pictures import inked_at_the_edges

    from rpdrill.studies.drawings import drill_animation
    from rpdrill.studies.drawings.drill_animation import load_solution

    monkeypatch.setattr(drill_animation, "FRAMES_PER_BLOW", 4)
    scene = PAPER.with_({"extensions": {"clamp": CLAMP}, **SHORT,
                         "extensions.clamp.parameters.stiffness_n_per_m": 1e9})
    write(tmp_path / "scene.yaml", scene)
    assert main(["simulate", str(tmp_path / "scene.yaml"), "--out", str(tmp_path / "run"), "--animate", "--quiet",
                 "--allow-code", "user_rig"]) == 0
    model, solution = load_solution(tmp_path / "run", allow_code=["user_rig"])
    assert solution["data"].shape[1] == 1 + model.coordinate_count and "clamp" in {
        model.mbs.GetObject(i)["name"] for i in range(model.mbs.systemData.NumberOfObjects())}
    assert (tmp_path / "run" / "drill.gif").stat().st_size > 10_000  # the model drawn from its graphics, every frame
    assert inked_at_the_edges(tmp_path / "run" / "drill.gif") == 0  # laid out: its labels inside the frame
    assert (tmp_path / "run" / "drill.png").stat().st_size > 10_000
    by_hand = clamped(PAPER.with_(SHORT), stiffness_n_per_m=1e9)
    by_hand.write_solution(tmp_path / "solution.txt")
    by_hand.run()
    assert load_solution(by_hand)[1]["data"].shape[1] == 1 + by_hand.coordinate_count
    (tmp_path / "plain").mkdir()
    write(tmp_path / "plain" / "scene.resolved.yaml", PAPER.with_(SHORT))
    (tmp_path / "plain" / "solution.txt").write_bytes((tmp_path / "solution.txt").read_bytes())
    with pytest.raises(rpdrill.InputError, match="items added in Python that the scene does not name"):
        load_solution(tmp_path / "plain")
