"""The drill string drawn, animated and handed to Exudyn's viewer (studies.drawings.drill_drawing, studies.drawings.drill_animation)."""

import json
from pathlib import Path

import numpy as np
import pytest
import yaml
from commands import main
from matplotlib.figure import Figure
from pictures import inked_at_the_edges
from PIL import Image
from scenes import crushing_scene, scene_dict, simulate

import rpdrill
from rpdrill.models.drill.shapes import layout
from rpdrill.studies.drawings import drill_animation
from rpdrill.studies.drawings.drill_animation import load_solution, nice_factor
from rpdrill.studies.drawings.drill_drawing import draw_string, drawn_layout

# the drawing's layout, the animation's scale and the solution file read back for the viewer
UNITS = ("rpdrill.models.drill.shapes", "rpdrill.studies.drawings")

load_scene, draw, write_animation = rpdrill.load_scene, rpdrill.draw, rpdrill.write_animation

SCENES = Path(__file__).resolve().parents[1] / "studies" / "scenes"
QUICK = {"solver.end_time_s": 0.1, "metrics.transient_blows": 1, "metrics.block_blows": 2}


@pytest.mark.parametrize("name", ["four_rod_string", "paper_base", "dth_drill", "wave_rod"])
def test_every_body_and_connector_is_labelled_by_its_scene_name(name):
    s = load_scene(SCENES / f"{name}.yaml")
    ax = Figure().subplots()
    draw_string(ax, s)
    labels = {text.get_text().splitlines()[0] for text in ax.texts}
    assert set(s.drill_string.bodies) <= labels and set(s.drill_string.connectors) <= labels
    assert "rock" in labels and any(label.startswith("impact") for label in labels)


def test_bodies_follow_the_connectors_from_hammer_to_rock_whatever_the_files_order(tmp_path):
    path = tmp_path / "sorted.yaml"
    path.write_text(yaml.safe_dump(scene_dict(**QUICK)))  # keys sorted: bit, carriage, collar, shank
    s = load_scene(path)
    assert next(iter(s.drill_string.bodies)) == "bit"
    drawing, shapes = drawn_layout(s), layout(s)
    for placed in ({b.name: b.start for b in drawing.bodies}, {c.name: c.start_m for c in shapes.cylinders}):
        assert sorted(placed, key=placed.get) == ["carriage", "shank", "collar", "bit"]


def test_lengths_drawn_to_scale_but_for_the_shortened_ones_named_in_the_title(tmp_path):
    s = load_scene(SCENES / "paper_base.yaml")  # a 1110 m pipe beside a 0.36 m shank
    drawing, shapes = drawn_layout(s), layout(s)
    true = {c.name: c.length_m for c in shapes.cylinders}
    kept = [b for b in drawing.bodies if not b.broken]
    scales = {round(b.length / true[b.name], 12) for b in kept}
    assert len(kept) >= 2 and len(scales) == 1  # one scale for every body drawn to scale
    assert {b.group for b in drawing.bodies if b.broken} >= {"pipe"}
    four = drawn_layout(load_scene(SCENES / "four_rod_string.yaml"))
    assert not any(b.broken for b in four.bodies)
    for suffix in (".png", ".svg"):
        path = draw(s, tmp_path / f"drill{suffix}")
        assert path.stat().st_size > 10_000


@pytest.mark.slow
def test_the_animation_shows_the_last_blows_magnified(tmp_path, monkeypatch):
    """The magnification a nice factor above 1, a frame count of the blows asked times the frames a blow; at 4
    frames a blow, not the 20 shipped (each frame drawn alike: 40 frames were nine tenths of this test's CPU,
    measured)."""
    monkeypatch.setattr(drill_animation, "FRAMES_PER_BLOW", 4)
    result = simulate(crushing_scene(solver__end_time_s=0.1, metrics__transient_blows=1, metrics__block_blows=2))
    factor = write_animation(result, tmp_path / "drill.gif", blows=2)
    assert factor == nice_factor(factor) and factor > 1
    with Image.open(tmp_path / "drill.gif") as movie:
        assert movie.n_frames == 2 * 4  # not the 3 blows of the default, nor 20 frames a blow
    with pytest.raises(ValueError, match="ffmpeg"):
        if __import__("shutil").which("ffmpeg") is None:
            write_animation(result, tmp_path / "drill.mp4")
        else:
            raise ValueError("ffmpeg present")
    assert [nice_factor(v) for v in (7.0, 0.03, 250.0)] == [5.0, 0.02, 200.0]


@pytest.mark.slow
def test_simulate_draws_the_drill_and_with_animate_writes_what_exudyns_viewer_opens(tmp_path, monkeypatch):
    """Both formulations; the animations at 4 frames a blow, not 20, as the test above's (two thirds of this
    test's CPU went into drawing them, measured)."""
    monkeypatch.setattr(drill_animation, "FRAMES_PER_BLOW", 4)
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(scene_dict(**QUICK)))
    out = tmp_path / "out"
    assert main(["simulate", str(path), "--out", str(out), "--quiet", "--animate"]) == 0
    assert {"drill.png", "drill.gif", "solution.txt"} <= {p.name for p in out.iterdir()}
    model, solution = load_solution(out)
    assert solution["data"].shape[1] == 1 + model.coordinate_count
    positions = np.loadtxt(out / "timeseries.csv", delimiter=",", skiprows=1, usecols=[1])  # carriage
    np.testing.assert_allclose(solution["data"][-1, 1], positions[-1], rtol=1e-6)
    exact = tmp_path / "exact"
    assert main(["simulate", str(path), "--out", str(exact), "--quiet", "--animate", "--formulation", "exact"]) == 0
    assert {"drill.png", "drill.gif"} <= {p.name for p in exact.iterdir()}
    assert not (exact / "solution.txt").exists()  # only an Exudyn run writes Exudyn's solution file
    assert json.loads((exact / "summary.json").read_text())["formulation"] == "exact"
    for movie in (out / "drill.gif", exact / "drill.gif"):  # Exudyn's: the model's graphics; exact: the drawing
        assert inked_at_the_edges(movie) == 0, movie



def test_a_drawing_into_a_folder_that_is_not_there_is_refused_before_anything_is_drawn(tmp_path):
    import rpdrill

    scene = rpdrill.load_scene("paper_base")
    with pytest.raises(rpdrill.InputError, match=r"rpdrill.draw: path: .*x.svg: no folder .*missing"):
        rpdrill.draw(scene, tmp_path / "missing" / "x.svg")
    with pytest.raises(rpdrill.InputError, match=r"rpdrill.write_animation: path: .*x.gif: no folder"):
        rpdrill.write_animation(rpdrill.build_exudyn(scene), tmp_path / "missing" / "x.gif")
