"""The start and the solver of a drill with items of one's own (models/solvers/exudyn_start.py; issue 47,
section 3): ``start: preloaded`` is the equilibrium of the assembled system, extension items included, or is
refused naming the extension; a constraint an explicit solver cannot take is refused before the run naming the
extension and ``solver.type``; every coordinate is named in Exudyn's order (the solution file's columns).
Their references, the chain's own static solution (models.drill.chain) and a prepared scene's start and rock law
(models.solvers.simulation), are units they import."""

from __future__ import annotations

from pathlib import Path

import exudyn
import numpy as np
import pytest
import yaml
from commands import main
from exudyn.itemInterface import (
    LoadCoordinate,
    MarkerNodeCoordinate,
    Node1D,
    NodePointGround,
    ObjectConnectorCoordinate,
    ObjectMass1D,
)
from exudyn.utilities import LoadSolutionFile

import rpdrill
from rpdrill.models.drill.chain import axial_chain, static_preload_m
from rpdrill.models.solvers.simulation import prepare

# unit tests of: the chain's static solution under the feed; a prepared scene's rock law, start and piston
UNITS = ("rpdrill.models.drill.chain", "rpdrill.models.solvers.simulation")

ROOT = Path(__file__).resolve().parents[1]
PAPER = rpdrill.load_scene(ROOT / "studies" / "scenes" / "paper_base.yaml", allow_code=["user_rig"]).with_({
    "solver.end_time_s": 0.25, "metrics.transient_blows": 6, "metrics.block_blows": 5})
FEED = PAPER.feed.force_n
INITIAL = exudyn.ConfigurationType.Initial


def load(force_n: float, body: str = "pipe") -> dict:
    return {"function": "user_rig:add_load", "parameters": {"force_n": force_n, "body": body}}


def rate(result) -> float:
    return result.metrics["penetration_rate_m_per_s"]


def write(tmp_path: Path, scene: rpdrill.Scene) -> str:
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(scene.model_dump(mode="json", by_alias=True, exclude_none=True), sort_keys=False))
    return str(path)


def test_an_extensions_load_moves_the_preloaded_start_as_more_feed_does():
    """A LoadCoordinate of F on the pipe is F more feed: the start is the drill's equilibrium under 2 F (the
    chain's own static solution of the doubled feed, independent of Exudyn), and the run the doubled feed's."""
    loaded = rpdrill.simulate(PAPER.with_({"extensions": {"push": load(FEED)}}))
    doubled = PAPER.with_({"feed.force_n": 2 * FEED})
    expected = static_preload_m(axial_chain(doubled), prepare(doubled).rock)
    start = loaded.timeseries[[f"{name}_position_m" for name in ("pipe", "shank", "collar", "bit")]].iloc[0]
    np.testing.assert_allclose(start.to_numpy(), expected, rtol=1e-9)
    assert expected[0] > 1.9 * prepare(PAPER).initial_positions_m[0]  # the plain drill's start is not it
    assert rate(loaded) == pytest.approx(rate(rpdrill.simulate(doubled)), rel=1e-9)
    assert loaded.raw.simulation.initial_positions_m == pytest.approx(expected, rel=1e-9)


def test_a_load_added_by_hand_before_the_run_moves_the_start_too():
    model = rpdrill.build_exudyn(PAPER)
    model.mbs.AddLoad(LoadCoordinate(markerNumber=model.bodies["collar"].marker_coordinate, load=5e3))
    result = model.run()
    pushed = PAPER.with_({"feed.force_n": FEED + 5e3})  # the pipe's shock sub carries both: the same bit load
    expected = static_preload_m(axial_chain(pushed), prepare(pushed).rock)
    assert result.timeseries["bit_position_m"].iloc[0] == pytest.approx(expected[3], rel=1e-9)


def test_a_coordinate_nothing_joins_to_the_drill_keeps_its_extensions_start():
    """A reference oscillator on ground (user_rig: initial 1 mm) is not part of the drill's statics."""
    model = rpdrill.build_exudyn(PAPER.with_({"extensions": {"push": load(FEED), "reference": {
        "function": "user_rig:add_ground_oscillator"}}}))
    names = model.coordinate_names()
    start = np.array(model.mbs.systemData.GetODE2Coordinates(configuration=INITIAL))
    assert start[names.index("oscillator")] == 1e-3
    assert start[names.index("pipe")] == pytest.approx(2 * prepare(PAPER).initial_positions_m[0], rel=1e-9)


@pytest.mark.parametrize(("extension", "expected"), [
    (load(300e3), r"extensions push: the static loads alone crush the rock \(rock force .* N >= rock threshold"),
    (load(-1e6), (r"extensions push: the assembled system has no static equilibrium: nothing holds the body 'pipe', "
                  r"the body 'shank', the body 'collar', the body 'bit' at rest")),
])
def test_a_preloaded_start_the_assembled_system_cannot_hold_is_refused_naming_the_extension(tmp_path, capsys, extension,
                                                                                          expected):
    scene = PAPER.with_({"extensions": {"push": extension}})
    with pytest.raises(rpdrill.InputError, match=r"start: 'preloaded' with " + expected):
        rpdrill.simulate(scene)
    out = tmp_path / "out"
    assert main(["simulate", write(tmp_path, scene), "--out", str(out), "--quiet", "--allow-code", "user_rig"]) == 2
    error = capsys.readouterr().err
    assert "use start: rest" in error and "Traceback" not in error and "internal error" not in error
    assert not out.exists() or not any(out.iterdir())
    assert rate(rpdrill.simulate(scene.with_({"start": "rest"}))) >= 0  # the remedy it names runs


def test_a_preloaded_wave_drill_with_an_extensions_load_is_refused():
    waves = rpdrill.load_scene(ROOT / "studies" / "scenes" / "top_hammer_waves.yaml", allow_code=["user_rig"])
    scene = waves.with_({"start": "preloaded", "extensions": {"push": load(1e3, body="carriage")}})
    with pytest.raises(rpdrill.InputError, match="extensions push: the wave rods are not Exudyn items"):
        rpdrill.build_exudyn(scene)


def test_a_piston_stays_parked_behind_the_impact_body_where_the_load_moved_it():
    piston = rpdrill.load_scene(ROOT / "studies" / "scenes" / "top_hammer_piston.yaml", allow_code=["user_rig"])
    feed = piston.feed.force_n
    model = rpdrill.build_exudyn(piston.with_({"extensions": {"push": load(feed, body="carriage")}}))
    doubled = prepare(piston.with_({"feed.force_n": 2 * feed}))
    names = model.coordinate_names()
    start = np.array(model.mbs.systemData.GetODE2Coordinates(configuration=INITIAL))
    np.testing.assert_allclose(start[:doubled.chain.size], doubled.initial_positions_m, rtol=1e-9, atol=1e-15)
    parked = doubled.piston.parked(doubled.initial_positions_m)
    np.testing.assert_allclose(start[[names.index(f"piston[{i}]") for i in range(8)]], parked[doubled.chain.size:],
                               rtol=1e-12)


RIGID = {"function": "user_rig:add_rigid_clamp", "parameters": {"mass_kg": 300.0}}


@pytest.mark.parametrize(("solver", "named"), [({}, "solver.type, chosen by the standard preset"),
                                               ({"solver.type": "dopri5"}, r"'dopri5' \(solver.type\)")])
def test_a_constraint_on_an_explicit_solver_is_refused_before_the_run(tmp_path, capsys, solver, named):
    """Exudyn's explicit solvers raise a ModelError (an internal error) when they start on a constraint between
    two bodies; the scene is refused naming the extension, the item and the solver type."""
    scene = PAPER.with_({**solver, "extensions": {"clamp": RIGID}})
    message = (r"extension 'clamp' \(user_rig:add_rigid_clamp\) adds the constraint ConnectorCoordinate "
               r"'rigid_joint' .* explicit solver .*" + named + r".*generalized_alpha or trapezoidal_index2")
    with pytest.raises(rpdrill.InputError, match=message):
        rpdrill.simulate(scene)
    assert main(["simulate", write(tmp_path, scene), "--out", str(tmp_path / "out"), "--quiet", "--allow-code", "user_rig"]) == 2
    assert "rigid_joint" in capsys.readouterr().err


def test_a_constraint_on_an_implicit_solver_runs_as_the_heavier_collar():
    """Generalized-alpha at the preset's step (second order: 9.4e-4 off at 5e-5 s over 0.5 s, python
    benchmarks/bench_extensions.py --parts start) against the exact formulation's collar 300 kg heavier."""
    joined = rpdrill.simulate(PAPER.with_({"solver.type": "generalized_alpha", "extensions": {"clamp": RIGID}}))
    collar = PAPER.drill_string.bodies["collar"].mass_kg
    heavier = rpdrill.simulate(PAPER.with_({"drill_string.bodies.collar.mass_kg": collar + 300.0}), formulation="exact")
    assert rate(joined) == pytest.approx(rate(heavier), rel=2e-3)


def test_a_constraint_to_ground_runs_on_the_explicit_default():
    """Exudyn's explicit solvers eliminate a coordinate constraint to ground: not refused (a clamp fixed to the
    ground holds its own mass only; the drill runs as without it)."""
    model = rpdrill.build_exudyn(PAPER)
    mbs = model.mbs
    node = mbs.AddNode(Node1D(referenceCoordinates=[0.0], initialCoordinates=[0.0], initialVelocities=[0.0]))
    mbs.AddObject(ObjectMass1D(nodeNumber=node, mass=1.0, name="fixed_mass"))
    ground = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=mbs.AddNode(NodePointGround()), coordinate=0))
    mbs.AddObject(ObjectConnectorCoordinate(markerNumbers=[ground, mbs.AddMarker(MarkerNodeCoordinate(
        nodeNumber=node, coordinate=0))], name="fixed"))
    assert rate(model.run()) == pytest.approx(rate(rpdrill.simulate(PAPER)), rel=1e-9)


def test_coordinates_are_named_in_the_scenes_order_and_are_the_solution_files_columns(tmp_path):
    """The bodies in the order the scene file lists them (here sorted by name, as yaml.safe_dump writes them),
    then torsion, then an extension's node: the columns of Exudyn's solution file, against the run's histories."""
    data = PAPER.model_dump(mode="json", by_alias=True, exclude_none=True)
    data["extensions"] = {"clamp": {"function": "user_rig:add_clamp", "parameters": {
        "mass_kg": 300.0, "stiffness_n_per_m": 1.0e9}}}
    path = tmp_path / "sorted.yaml"
    path.write_text(yaml.safe_dump(data))  # sort_keys: bodies bit, collar, pipe, shank
    model = rpdrill.build_exudyn(rpdrill.load_scene(path, allow_code=["user_rig"]))
    names = model.coordinate_names()
    assert names == ["bit", "collar", "pipe", "shank", "torsion", "clamp"]
    model.write_solution(tmp_path / "solution.txt")
    result = model.run()
    columns = LoadSolutionFile(str(tmp_path / "solution.txt"), verbose=False)["data"]
    series = result.timeseries
    assert len(columns) == len(series)
    for body in ("bit", "collar", "pipe", "shank"):
        np.testing.assert_allclose(columns[:, 1 + names.index(body)], series[f"{body}_position_m"], rtol=1e-9,
                                   atol=1e-14)  # the file's 10 significant digits
    np.testing.assert_allclose(columns[:, 1 + names.index("torsion")], series["torsion_angle_rad"], rtol=1e-9)
    clamp = model.mbs.GetObject(model.mbs.GetObjectNumber("clamp"))["nodeNumber"]
    assert model.mbs.GetNodeODE2Index(clamp) == names.index("clamp")
