"""studies.display.catalogue: every metric, time history and scene parameter has a name and a unit, and no
plot shows a raw key name.
Unit tests of studies.display.catalogue: they import it."""

from __future__ import annotations

import re

import numpy as np
import pytest
import yaml
from matplotlib.figure import Figure
from matplotlib.text import Text
from scenes import PAPER_BASE, scene

import rpdrill
from rpdrill import Scene
from rpdrill.models.definition.outputs import METRICS, SERIES
from rpdrill.models.definition.validation import allowed_keys
from rpdrill.studies.display import catalogue

# the catalogue against the registries it names (outputs, the scene's keys) and the figures that read it
UNITS = ("rpdrill.studies.display.catalogue", "rpdrill.models.definition.outputs", "rpdrill.models.definition.validation", "rpdrill.studies.figures", "rpdrill.studies.scan.study_optima")

WORDS = re.compile(r"[a-z]+(?:[._][a-z0-9]+)+")  # snake_case or dotted keys


def scene_leaf_paths(prefix: tuple[str, ...] = ()) -> list[str]:
    """Every key path of a scene file that holds a value ('*' for a name in a mapping of models)."""
    keys = allowed_keys(Scene, (*prefix, "x"))
    if keys == ["x"] and allowed_keys(Scene, (*prefix, "y")) == ["y"]:  # a mapping of plain values: one leaf
        return [".".join(prefix)]
    if keys is None:
        named = allowed_keys(Scene, (*prefix, "NAME", "x")) is not None
        return scene_leaf_paths((*prefix, "*")) if named else [".".join(prefix)]
    return [path for key in keys for path in scene_leaf_paths((*prefix, key))]


def test_every_metric_has_an_entry_with_a_unit():
    """Fails when a metric is added to models.definition.outputs without a catalogue entry."""
    missing = sorted(set(METRICS) - set(catalogue.METRICS))
    assert not missing, f"studies/display/catalogue.py has no entry for the metrics {missing}"
    assert set(catalogue.METRICS) == set(METRICS), "catalogue entries for metrics the model does not have"
    for name, quantity in catalogue.METRICS.items():
        assert quantity.unit and quantity.si_unit and quantity.scale > 0, name
        assert "_" not in quantity.name and name not in quantity.label(), name


def test_every_time_history_has_an_entry():
    for column in [*SERIES, "time_s", "collar_position_m", "rod_1_velocity_m_per_s"]:
        quantity = catalogue.series(column)
        assert quantity.unit and column not in quantity.label(), column
    assert catalogue.series("rod_1_velocity_m_per_s").name == "rod_1 velocity"


def test_every_scene_parameter_has_an_entry():
    """Fails when a key is added to the scene without a catalogue entry; numeric ones have units."""
    paths = scene_leaf_paths()
    assert "drill_string.bodies.*.mass_kg" in paths and "impact.frequency_hz" in paths
    missing = [p for p in paths if p not in catalogue.PARAMETERS]
    assert not missing, f"studies/display/catalogue.py has no entry for the scene keys {missing}"
    assert set(catalogue.PARAMETERS) <= set(paths), "catalogue entries for keys the scene does not have"
    numeric = [p for p in paths if re.search(r"_(hz|n|s|m|kg|pa|m3|m2|rad|n_m|per_m|per_rad)$", p)]
    assert numeric and all(not catalogue.PARAMETERS[p].categorical for p in numeric)


def test_named_parameters_and_display_values():
    collar = catalogue.parameter("drill_string.bodies.collar.mass_kg")
    assert (collar.name, collar.unit) == ("collar mass", "kg")
    assert catalogue.parameter("drill_string.connectors.shock_absorber.stiffness_n_per_m").name == \
        "shock_absorber stiffness"
    assert catalogue.metric("advance_per_blow_m").show_with_unit(0.00035) == "0.35 mm/blow"
    assert catalogue.parameter("feed.force_n").show_with_unit(75e3) == "75 kN"
    with pytest.raises(KeyError, match="no scene parameter"):
        catalogue.parameter("impact.speed_rpm")


def test_scene_description_names_rock_and_impact_and_leaves_out_what_varies():
    text = catalogue.describe_scene(scene(rock={"name": "sandstone"}))
    assert text == ("test_drill: rock sandstone (k_n 510 MN/m, F_th 210 kN), impact 220 kN half-sine of 1 ms at 65 Hz, "
                    "feed 30 kN")
    varied = catalogue.describe_scene(scene(), ["impact.frequency_hz", "rock.stiffness_n_per_m"])
    assert "Hz" not in varied and "k_n" not in varied and "F_th 138 kN" in varied


def assert_no_raw_keys(text: str) -> None:
    """No metric, history or scene key, nor the last part of one with its unit ('frequency_hz')."""
    keys = set(METRICS) | set(SERIES) | set(catalogue.PARAMETERS)
    parts = keys | {key.rsplit(".", 1)[-1] for key in keys if "_" in key.rsplit(".", 1)[-1]}
    raw = sorted({word for word in WORDS.findall(text) if word in parts})
    assert not raw, f"raw key names in plots: {raw}"


@pytest.fixture
def plot_texts(monkeypatch) -> list[str]:
    """Every text of every figure saved during the test (titles, labels, ticks, legends)."""
    texts: list[str] = []
    save = Figure.savefig

    def recording(figure: Figure, *args, **kwargs):
        texts.extend(t.get_text() for t in figure.findobj(Text) if t.get_text())
        return save(figure, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", recording)
    return texts


def test_study_plots_show_no_raw_key_names(tmp_path, plot_texts):
    from rpdrill.studies.figures.plot_tasks import start_plots
    from rpdrill.studies.scan.study_optima import study_optima

    study_file = tmp_path / "s.yaml"
    study_file.write_text(yaml.safe_dump({
        "name": "labels", "base_scene": str(PAPER_BASE),
        "scan": {"impact.frequency_hz": [40.0, 50.0, 60.0], "rock.stiffness_n_per_m": [2e8, 5e8]},
        "metrics": ["penetration_rate_m_per_s", "advance_per_blow_m"],
        "plots": [{"x": "impact.frequency_hz", "y": ["penetration_rate_m_per_s", "advance_per_blow_m"]},
                  {"kind": "map", "x": "impact.frequency_hz", "y": "rock.stiffness_n_per_m",
                   "z": "penetration_rate_m_per_s"}]}))
    study = rpdrill.load_study(study_file)
    rng = np.random.default_rng(0)
    table = rpdrill.table_frame([{"point": str(p.index), **{a: str(v) for a, v in p.values.items()}, "status": "ok",
                                  "error": "", "wall_time_s": "1", "penetration_rate_m_per_s": str(rng.uniform(0, 0.02)),
                                  "advance_per_blow_m": str(rng.uniform(0, 3e-4))} for p in study.points])
    written, _ = start_plots(study, table, study_optima(study, table), tmp_path)()
    assert {p.suffix for p in written} == {".png", ".svg"}
    text = "\n".join(plot_texts)
    assert "penetration rate" in text and "mm/s" in text and "rock stiffness" in text and "MN/m" in text
    assert_no_raw_keys(text)


def test_a_map_keeps_axes_zipped_with_its_rows_in_one_panel(tmp_path, monkeypatch):
    """The rock's damping zipped with its stiffness changes along the map's rows: one panel of two rows,
    the damping named in the row label, not a panel per damping."""
    from rpdrill.studies.figures import plot_tasks as tasks
    from rpdrill.studies.figures import scan_figures as scans

    study_file = tmp_path / "s.yaml"
    study_file.write_text(yaml.safe_dump({
        "name": "zipped", "base_scene": str(PAPER_BASE),
        "scan": {"impact.frequency_hz": [40.0, 50.0, 60.0], "rock.stiffness_n_per_m": [2e8, 5e8],
                 "rock.damping_n_s_per_m": [2e3, 5e3]},
        "combine": [["rock.stiffness_n_per_m", "rock.damping_n_s_per_m"]],
        "metrics": ["penetration_rate_m_per_s"],
        "plots": [{"kind": "map", "x": "impact.frequency_hz", "y": "rock.stiffness_n_per_m",
                   "z": "penetration_rate_m_per_s"}]}))
    study = rpdrill.load_study(study_file)
    assert study.zipped_with("rock.stiffness_n_per_m") == ["rock.stiffness_n_per_m", "rock.damping_n_s_per_m"]
    table = rpdrill.table_frame([{"point": str(p.index), **{a: str(v) for a, v in p.values.items()}, "status": "ok",
                                  "error": "", "wall_time_s": "1", "penetration_rate_m_per_s": str(0.001 * (p.index + 1))}
                                 for p in study.points])
    figures = []
    monkeypatch.setattr(scans, "save", lambda figure, path: figures.append(figure) or [path])
    tasks.start_plots(study, table, [], tmp_path)()
    panels = [ax for ax in figures[0].axes if ax.collections and ax.get_ylabel().startswith("rock stiffness")]
    assert len(panels) == 1 and "rock damping" in panels[0].get_ylabel()
    assert panels[0].collections[0].get_array().size == 6  # 3 frequencies x 2 rocks
