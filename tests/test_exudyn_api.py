"""The Exudyn model opened to a user: build it, see its items, add one's own, run it.
Where it checks the bodies' places and sizes, a unit test of models.drill.shapes (the layout, with the steel of
models.definition.drill_string): it imports them."""

import math
from pathlib import Path

import exudyn
import numpy as np
import pytest
from exudyn.itemInterface import (
    MarkerNodePosition,
    NodePoint,
    ObjectConnectorSpringDamper,
    ObjectMassPoint,
    SensorNode,
)
from scenes import crushing_scene, scene

from rpdrill import build_exudyn, load_scene, simulate
from rpdrill.models.definition.drill_string import STEEL_DENSITY_KG_PER_M3
from rpdrill.models.drill.shapes import DEFAULT_DIAMETER_M, layout

# unit tests of: the drill's layout (where each body is drawn, how long, how wide) and the steel it assumes
UNITS = ("rpdrill.models.definition.drill_string", "rpdrill.models.drill.shapes")

SHORT = {"solver__end_time_s": 0.4, "metrics__transient_blows": 8, "metrics__block_blows": 6}
FOUR_RODS = Path(__file__).resolve().parents[1] / "studies" / "scenes" / "four_rod_string.yaml"


def _tuned_absorber(model, mass_kg: float = 200.0, damping_ratio: float = 0.1):
    """A mass on a spring-damper hung on the collar, tuned to the blow frequency; its node."""
    mbs, collar = model.mbs, model.bodies["collar"]
    centre = mbs.GetObject(collar.object)["referencePosition"][0]
    stiffness = mass_kg * (2 * math.pi * model.simulation.impact.frequency_hz) ** 2
    node = mbs.AddNode(NodePoint(referenceCoordinates=[centre + 1.0, 0.0, 0.0]))
    mbs.AddObject(ObjectMassPoint(mass=mass_kg, nodeNumber=node))
    mbs.AddObject(ObjectConnectorSpringDamper(
        markerNumbers=[collar.marker_position, mbs.AddMarker(MarkerNodePosition(nodeNumber=node))],
        stiffness=stiffness, damping=2 * damping_ratio * math.sqrt(stiffness * mass_kg), referenceLength=1.0))
    return node


def test_a_tuned_absorber_added_by_the_user_changes_the_penetration_rate():
    s = crushing_scene(**SHORT)
    plain = build_exudyn(s).run().metrics["penetration_rate_m_per_s"]
    model = build_exudyn(s)
    node = _tuned_absorber(model)
    sensor = model.mbs.AddSensor(SensorNode(nodeNumber=node, storeInternal=True,
                                             outputVariableType=exudyn.OutputVariableType.Displacement))
    result = model.run()
    tuned = result.metrics["penetration_rate_m_per_s"]
    assert plain > 0 and abs(tuned - plain) > 0.2 * plain, (plain, tuned)
    swing = model.mbs.GetSensorStoredData(sensor)[:, 1]  # the user's sensor, read back through mbs
    assert np.ptp(swing) > 1e-5
    told = result.exudyn_model
    assert told.user_items == {"nodes": 1, "objects": 2, "markers": 1, "sensors": 1}
    assert "only by the Exudyn formulation" in told.note


def test_a_normal_run_is_the_build_and_its_run():
    s = crushing_scene(solver__end_time_s=0.1, metrics__transient_blows=1, metrics__block_blows=2)
    normal, built = simulate(s), build_exudyn(s).run()
    np.testing.assert_array_equal(normal.position_m, built.position_m)
    assert normal.exudyn_model is None


def test_a_model_built_without_graphics_moves_as_the_drawn_one_and_has_no_body_graphics():
    s = crushing_scene(solver__end_time_s=0.1, metrics__transient_blows=1, metrics__block_blows=2)
    drawn, bare = build_exudyn(s), build_exudyn(s, graphics=False)
    mbs = bare.mbs
    items = [mbs.GetObject(i, addGraphicsData=True) for i in range(mbs.systemData.NumberOfObjects())]
    assert not any(item["VgraphicsData"] for item in items if item["objectType"] == "Mass1D")
    np.testing.assert_array_equal(drawn.run().raw.position_m, bare.run().raw.position_m)


def test_a_scene_of_another_formulation_is_built_and_run_by_exudyn_and_says_so():
    s = crushing_scene(solver__end_time_s=0.1, metrics__transient_blows=1, metrics__block_blows=2).with_solver("exact")
    result = build_exudyn(s).run()
    assert result.formulation == "exudyn"
    assert result.exudyn_model.scene_formulation == "exact"
    assert "only by the Exudyn formulation" in result.exudyn_model.note


def test_a_model_runs_once():
    model = build_exudyn(crushing_scene(solver__end_time_s=0.1, metrics__transient_blows=1, metrics__block_blows=2))
    model.run()
    with pytest.raises(RuntimeError, match="runs once"):
        model.run()


def test_bodies_and_connectors_by_their_scene_names_with_3d_markers_at_their_drawn_centres():
    s = load_scene(FOUR_RODS)
    model = build_exudyn(s)
    assert {"carriage", "shank", "rod1[0]", "rod4[3]", "bit"} <= set(model.bodies)
    assert {"shock_absorber", "coupling1", "bit_coupling", "rod2[0-1]"} <= set(model.connectors)
    shapes = layout(s)
    for name, body in model.bodies.items():
        point = model.mbs.GetMarkerOutput(body.marker_position, exudyn.OutputVariableType.Position,
                                          exudyn.ConfigurationType.Reference)
        np.testing.assert_allclose(point, [shapes[name].centre_m, 0.0, 0.0])
    assert model.connectors["coupling1"].link.name == "coupling1"


def test_every_body_is_drawn_to_scale_and_every_connector_drawn():
    s = load_scene(FOUR_RODS)
    model = build_exudyn(s)
    mbs = model.mbs
    bodies = [mbs.GetObject(i, addGraphicsData=True) for i in range(mbs.systemData.NumberOfObjects())]
    bodies = [item for item in bodies if item["objectType"] in ("Mass1D", "RotationalMass1D", "MassPoint")]
    assert len(bodies) == model.chain.size and all(item["VgraphicsData"] for item in bodies)
    drawn = model.graphics.links(np.zeros(model.chain.size))
    assert set(drawn) == set(model.connectors) and all(drawn.values())
    ground = [mbs.GetObject(i) for i in range(mbs.systemData.NumberOfObjects())]
    assert any(item["objectType"] == "Ground" and item["VgraphicsDataUserFunction"] != 0 for item in ground)
    assert len(model.graphics(mbs, 0)) == len(model.connectors)  # what the renderer calls: one spring a link
    shapes = layout(s)
    assert shapes["rod1[0]"].length_m == pytest.approx(3.66 / 4) and shapes["rod1[0]"].diameter_m == 0.045
    bit = s.drill_string.bodies["bit"].mass_kg  # a rigid body: a steel cylinder of the default diameter
    assert shapes["bit"].length_m == pytest.approx(bit / (STEEL_DENSITY_KG_PER_M3 * math.pi * DEFAULT_DIAMETER_M**2 / 4))
    stated = layout(scene(drill_string__bodies__collar={"mass_kg": 3000.0, "diameter_m": 0.2}))
    assert stated["collar"].diameter_m == 0.2


def test_the_solution_file_is_written_when_asked_and_reads_back(tmp_path):
    from exudyn.utilities import LoadSolutionFile

    model = build_exudyn(crushing_scene(solver__end_time_s=0.1, metrics__transient_blows=1, metrics__block_blows=2))
    model.write_solution(tmp_path / "solution.txt", period_s=1e-3)
    result = model.run()
    solution = LoadSolutionFile(str(tmp_path / "solution.txt"), verbose=False)
    assert solution["data"].shape == (101, 1 + model.coordinate_count)
    row = np.searchsorted(result.time_s, 0.05)
    np.testing.assert_allclose(solution["data"][50, 1:1 + model.chain.size], result.position_m[row], rtol=1e-6, atol=1e-12)
