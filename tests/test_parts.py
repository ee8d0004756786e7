"""Outputs per part: every link's force and compression, every body's histories and metrics by its name."""

from pathlib import Path

import numpy as np
import pytest
from pydantic import ValidationError
from scenes import crushing_scene, scene, simulate

import rpdrill
from rpdrill import load_scene

SHORT = {"solver__end_time_s": 0.1, "metrics__transient_blows": 1, "metrics__block_blows": 2}
LINKS = ("shock_absorber", "shank_collar_joint", "collar_bit_joint")
FOUR_RODS = Path(__file__).resolve().parents[1] / "studies" / "scenes" / "four_rod_string.yaml"


@pytest.fixture(scope="module")
def three_runs():
    s = crushing_scene(**SHORT)
    return {name: simulate(s, name).resampled(1e-4) for name in ("exudyn", "exact", "ode")}


def test_every_connector_has_force_and_compression_histories_and_every_body_its_own(three_runs):
    columns = three_runs["exudyn"]
    for link in LINKS:
        assert {f"{link}_force_n", f"{link}_compression_m"} <= set(columns)
    for body in ("carriage", "shank", "collar", "bit"):
        assert {f"{body}_position_m", f"{body}_velocity_m_per_s"} <= set(columns)
    compression = columns["collar_position_m"] - columns["bit_position_m"]  # x_a - x_b
    np.testing.assert_allclose(columns["collar_bit_joint_compression_m"], compression)


def test_the_three_formulations_give_the_same_connector_histories(three_runs):
    exact = three_runs["exact"]
    for name in ("exudyn", "ode"):
        other = three_runs[name]
        for link in LINKS:
            column = f"{link}_force_n"
            scale = np.max(np.abs(exact[column]))
            assert scale > 1e3, column  # the link carries load
            assert np.max(np.abs(other[column] - exact[column])) < 0.02 * scale, (name, column)


def test_a_preloaded_string_carries_the_feed_through_every_connector_in_compression():
    s = crushing_scene(start="preloaded", **SHORT)
    for name in ("exudyn", "exact"):
        first = {key: values[0] for key, values in simulate(s, name).columns().items()}
        for link in LINKS:
            assert first[f"{link}_force_n"] == pytest.approx(s.feed.force_n, rel=1e-6)
            assert first[f"{link}_compression_m"] > 0


def test_a_coupling_reports_its_gap_opening():
    s = crushing_scene(**SHORT, drill_string__connectors__collar_bit_joint={
        "from": "collar", "to": "bit", "type": "coupling", "gap_m": 1e-4, "stiffness_n_per_m": 5e9})
    columns = simulate(s, "exact").columns()
    opening = columns["collar_bit_joint_gap_opening_m"]
    compression = columns["collar_bit_joint_compression_m"]
    np.testing.assert_allclose(opening, np.maximum(1e-4 - compression, 0.0), atol=1e-15)
    closed = opening == 0
    assert closed.any() and (~closed).any()
    assert np.all(columns["collar_bit_joint_force_n"][~closed] == 0.0)


def test_metrics_of_any_body_by_name():
    names = ["shank_velocity_peak_m_per_s", "collar_velocity_peak_m_per_s", "carriage_velocity_rms_m_per_s"]
    s = crushing_scene(outputs={"metrics": names}, **SHORT)
    result = rpdrill.simulate(s, "exact")
    metrics = result.metrics
    assert list(metrics) == names
    window = (result.time_s >= metrics_window(result)[0] - 1e-12) & (result.time_s <= metrics_window(result)[1] + 1e-12)
    shank = result.body_velocity_m_per_s("shank")
    assert metrics["shank_velocity_peak_m_per_s"] == pytest.approx(np.max(np.abs(shank[window])))
    assert metrics["shank_velocity_peak_m_per_s"] > metrics["collar_velocity_peak_m_per_s"] > 0


def metrics_window(result):
    period = result.scene.impact.period_s
    first = result.scene.metrics.transient_blows
    blows = (int(result.time_s[-1] / period + 1e-9) - first) // result.scene.metrics.block_blows \
        * result.scene.metrics.block_blows
    return first * period, (first + blows) * period


def test_a_rod_segment_by_its_name_and_an_unknown_body_refused():
    four = load_scene(FOUR_RODS)
    data = four.model_dump(by_alias=True, exclude_none=True)
    data["metrics"] = {"transient_blows": 1, "block_blows": 2}
    data["solver"] = {"formulation": "exact", "end_time_s": 0.08}
    data["outputs"] = {"metrics": ["rod1[0]_velocity_peak_m_per_s", "rod1_velocity_peak_m_per_s"]}
    s = type(four).model_validate(data)
    metrics = rpdrill.simulate(s).metrics
    assert metrics["rod1[0]_velocity_peak_m_per_s"] > 0
    assert metrics["rod1[0]_velocity_peak_m_per_s"] != metrics["rod1_velocity_peak_m_per_s"]  # the rod: its last segment
    with pytest.raises(ValidationError, match="need a body named colar"):
        scene(outputs={"metrics": ["colar_velocity_peak_m_per_s"]})
    with pytest.raises(ValidationError, match="'speed' is not a metric"):
        scene(outputs={"metrics": ["speed"]})


def test_a_connector_name_that_would_shadow_a_model_history_is_refused():
    with pytest.raises(ValidationError, match="rock_force_n would be the model's own"):
        scene(drill_string__connectors__rock={"from": "collar", "to": "bit", "stiffness_n_per_m": 1e9}, drill_string__connectors__collar_bit_joint=None)
