"""A hole drilled over its depth (``rpdrill.drill_hole``, ``rpdrill hole``; studies.hole): the hole's rate is the
steady state of the scene it writes, rigid joints lose nothing and lossy couplings deliver the product of their
transmissions, bad hole files are refused naming the key, and an interrupted hole resumes to the same hole.csv.
Short holes of short rods on the shipped top-hammer rig, so that the file runs in well under a minute."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
import yaml
from commands import main

import rpdrill

# an interrupt injected into a hole's segment runner; the time-depth curve the figure draws
UNITS = ("rpdrill.studies.hole.hole_run", "rpdrill.studies.hole.hole_figures")

RIG = Path(rpdrill.__file__).parent / "studies" / "scenes" / "top_hammer_waves.yaml"
# samples every 1 ms, not 0.1 ms: a hole's figures are the settling stepper's own at the blow starts
# (models.steady.wave_settling) and the rods' stress envelopes the stepper's, not read from the samples; every
# record of this file's holes measured the same at both to round-off (1e-16), the runs 16-30 % cheaper
RIG_OVERRIDES = {"solver.formulation": "exact", "solver.end_time_s": 2.0, "solver.output_interval_s": 1e-3}
ROD = {"length_m": 1.5, "diameter_m": 0.045, "bore_diameter_m": 0.012, "model": "waves"}


def hole_file(folder: Path, name: str = "short", **changes) -> Path:
    data = {"name": name, "rig": str(RIG), "string": {"rod": dict(ROD), "first_rods": 1},
            "layers": [{"to_m": 3.0, "rock": {"name": "sandstone"}}], "depth_m": 3.0, "depth_step_m": "at_changes",
            "rod_change_s": 30.0, "rig_overrides": RIG_OVERRIDES}
    data.update(changes)
    path = folder / f"{name}.yaml"
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def drilled(tmp_path_factory):
    """Two rods of 1.5 m to 3 m in sandstone, rigid joints: two runs."""
    folder = tmp_path_factory.mktemp("hole")
    return rpdrill.drill_hole(hole_file(folder), out=folder / "out", workers=1)


@pytest.mark.slow
def test_one_rod_in_one_layer_drills_at_the_steady_rate_of_the_scene_it_writes(drilled):
    row = drilled.rows.iloc[0]
    assert row["rods"] == 1 and row["regime"] == "settled" and row["settle_blows"] < 150
    scene = drilled.out / row["scene"]
    result = rpdrill.simulate(scene)
    assert result.steady_state.regime is rpdrill.Regime.SETTLED and result.steady_state.last_change < 1e-6
    assert row["rate_m_per_s"] == pytest.approx(result.metrics["penetration_rate_m_per_s"], rel=1e-9)
    assert drilled.rows["depth_m"].tolist() == [0.0, 1.5, 3.0] and drilled.rows["rods"].tolist() == [1, 1, 2]


def test_time_to_depth_is_the_integral_of_dz_over_the_rate_plus_the_rod_changes(drilled):
    rows = drilled.rows
    first, second = rows.iloc[1], rows.iloc[2]
    assert first["time_s"] == pytest.approx(1.5 / first["rate_m_per_s"], rel=1e-12)
    assert second["time_s"] == pytest.approx(first["time_s"] + 30.0 + 1.5 / second["rate_m_per_s"], rel=1e-12)
    summary = drilled.summary
    # the rods added times rod_change_s, counted (it was total - drilling: 30.000000000000014 measured)
    assert summary["total_time_s"] == pytest.approx(second["time_s"]) and summary["rod_change_time_s"] == 30.0
    assert summary["mean_rate_m_per_s"] == pytest.approx(3.0 / (summary["total_time_s"] - 30.0))
    for name in ("hole.csv", "hole.json", "hole.png", "scenes", "runs"):
        assert (drilled.out / name).exists()


def test_the_figure_draws_a_rod_change_as_a_step_in_time_at_its_depth(drilled):
    """The time-depth curve: drilling to 1.5 m, the 30 s rod change at 1.5 m (the depth stays), drilling to 3 m;
    a line straight from the 1.5 m row to the 3 m row hid the change inside the second rod's drilling."""
    from rpdrill.studies.hole.hole_figures import time_with_rod_changes

    rows = drilled.rows
    time_s, depth_m = time_with_rod_changes(rows, 30.0)
    t = rows["time_s"].tolist()
    assert depth_m.tolist() == [0.0, 1.5, 1.5, 3.0]
    assert time_s.tolist() == [t[0], t[1], t[1] + 30.0, t[2]]


def test_rigid_joints_lose_nothing_so_the_rods_change_the_rock_energy_only_by_mass_and_transit(drilled):
    """Each rigid joint between like rods (no impedance step) passes all that reaches it: its loss per blow is
    round-off and its transmission 1, so the rock's energy per blow changes from 1 to 2 rods only through the
    string's mass and its transit time (no loss to account for it); and it does change."""
    two = drilled.runs["rods002_layer01"]
    for name in two.coupling_lost_j:
        assert abs(two.coupling_lost_j[name]) < 1e-9 * two.rock_energy_per_blow_j
        assert two.coupling_transmission[name] == pytest.approx(1.0, abs=1e-9)
    one = drilled.runs["rods001_layer01"]
    assert one.rock_energy_per_blow_j != two.rock_energy_per_blow_j


@pytest.mark.slow
def test_lossy_couplings_deliver_the_product_of_their_transmissions(tmp_path):
    """Couplings with a spring and a damper: the energy delivered into the last rod over the energy reaching the
    first coupling equals the product of each coupling's measured transmission (the rods between carry it
    without loss in the settled state) within 1e-3, and each coupling passes less than it receives."""
    path = hole_file(tmp_path, "lossy", depth_m=3.0, layers=[{"to_m": 3.0, "rock": {"name": "sandstone"}}],
                     string={"rod": dict(ROD, length_m=1.0), "first_rods": 3,
                             "coupling": {"stiffness_n_per_m": 2.0e9, "damping_n_s_per_m": 3.0e4}})
    run = rpdrill.drill_hole(path, workers=1).runs["rods003_layer01"]
    names = ["coupling1", "coupling2"]
    transmissions = [run.coupling_transmission[name] for name in names]
    assert all(0.5 < t < 1.0 for t in transmissions)
    delivered = run.coupling_out_j[names[-1]] / run.coupling_in_j[names[0]]
    assert delivered == pytest.approx(math.prod(transmissions), abs=1e-3)


@pytest.mark.parametrize(("change", "named"), [
    ({"layers": [{"to_m": 2.0, "rock": {"name": "sandstone"}}, {"to_m": 1.5, "rock": {"name": "sandstone"}}]},
     "layers.1.to_m: 1.5: overlaps"),
    ({"layers": [{"to_m": 1.0, "rock": {"name": "sandstone"}},
                 {"from_m": 1.2, "to_m": 3.0, "rock": {"name": "sandstone"}}]}, "layers.1.from_m: 1.2: leaves a gap"),
    ({"depth_m": 4.0}, "depth_m: 4.0: beyond the last layer"),
    ({"string": {"rod": dict(ROD, diameter_m=0.06)}}, "string.rod.diameter_m: 0.06: does not fit the rig's rod chain"),
    ({"strng": 1}, "strng"),
])
def test_bad_hole_files_exit_2_naming_the_key(tmp_path, capsys, change, named):
    path = hole_file(tmp_path, **change)
    assert main(["hole", str(path), "--out", str(tmp_path / "out"), "--workers", "1"]) == 2
    error = capsys.readouterr().err
    assert f"{path}: {named}" in error  # the file, then the key path (not '(top level)'), the value, the rule
    assert not (tmp_path / "out" / "runs").exists()  # refused before anything ran


@pytest.mark.slow
def test_an_interrupted_hole_resumes_to_the_same_hole_csv(drilled, tmp_path, monkeypatch, capsys):
    from rpdrill.studies.hole import hole_run

    path = hole_file(tmp_path)
    out = tmp_path / "out"
    real = hole_run.run_segment

    def interrupted(task):
        if task[1] == 2:
            raise KeyboardInterrupt
        return real(task)

    monkeypatch.setattr(hole_run, "run_segment", interrupted)
    assert main(["hole", str(path), "--out", str(out), "--workers", "1", "--quiet"]) == 130
    assert (out / "runs" / "rods001_layer01.json").exists() and not (out / "hole.csv").exists()
    monkeypatch.setattr(hole_run, "run_segment", real)
    assert main(["hole", str(path), "--out", str(out), "--workers", "1", "--quiet"]) == 0
    assert (out / "hole.csv").read_text() == (drilled.out / "hole.csv").read_text().replace(
        str(drilled.out), str(out))


@pytest.mark.slow
def test_an_advised_hole_runs_each_depth_at_the_advisors_point_and_says_the_time_gained(tmp_path):
    """``operating: advise`` (a small search at a fixed power): the depth's run is at the point found, inside the
    bounds, its scene written beside the rig's; the time gained is the fixed setting's time less the hole's."""
    advise = {"bounds": {"impact.frequency_hz": [40.0, 60.0], "feed.force_n": [8000.0, 16000.0]}, "power_kw": 15.0,
              "popsize": 2, "max_generations": 1, "search_end_time_s": 0.05}
    rig = {**RIG_OVERRIDES, "metrics.transient_blows": 1, "metrics.block_blows": 1}  # search runs of 2 blows at
    # 40 Hz: the test checks where the hole runs and its time gained, not the search's best (tests/test_advice.py
    # does); the settled runs read their own blows (the same 28 and rates as with search runs of 4 blows, measured)
    path = hole_file(tmp_path, "advised", depth_m=1.5, layers=[{"to_m": 1.5, "rock": {"name": "sandstone"}}],
                     operating={"advise": advise}, rig_overrides=rig)
    drilled = rpdrill.drill_hole(path, out=tmp_path / "out", workers=1)
    row, run = drilled.rows.iloc[0], drilled.runs["rods001_layer01"]
    assert 40.0 <= run.operating["impact.frequency_hz"] <= 60.0 and 8e3 <= run.operating["feed.force_n"] <= 16e3
    assert run.operating["impact.piston.energy_j"] == pytest.approx(15e3 / run.operating["impact.frequency_hz"])
    assert row["scene"].endswith("_advised.yaml") and (drilled.out / row["scene"]).exists()
    summary = drilled.summary
    assert summary["time_gained_s"] == pytest.approx(summary["fixed_total_time_s"] - summary["total_time_s"])
    assert summary["fixed_total_time_s"] == pytest.approx(1.5 / run.fixed_rate_m_per_s)


@pytest.mark.slow
def test_a_down_the_hole_hammer_strikes_the_bit_and_its_tubes_only_add_mass(tmp_path):
    """``hammer: down_the_hole``: the rig's rods are taken out, the struck shank joined to the bit; the tubes' mass
    joins the body the feed pushes; the rate with 1 and 2 tubes is the same within 1e-3 (no coupling crossed)."""
    tube = {"length_m": 1.5, "diameter_m": 0.076, "bore_diameter_m": 0.060}
    path = hole_file(tmp_path, "dth", hammer="down_the_hole", string={"rod": tube, "first_rods": 1})
    drilled = rpdrill.drill_hole(path, out=tmp_path / "out", workers=1)
    one, two = drilled.runs["rods001_layer01"], drilled.runs["rods002_layer01"]
    assert one.coupling_lost_j == {} and two.rate_m_per_s == pytest.approx(one.rate_m_per_s, rel=1e-3)
    scenes = [rpdrill.load_scene(drilled.out / f"scenes/dth_{n}rods_layer1.yaml") for n in (1, 2)]
    rig = rpdrill.load_scene(RIG)
    tube_kg = 7800.0 * 1.5 * math.pi * (0.076**2 - 0.060**2) / 4  # the rig's rods' steel (the scene's default)
    for n, scene in enumerate(scenes, start=1):
        bodies = scene.drill_string.bodies
        assert set(bodies) == {"carriage", "shank", "bit"}
        assert scene.drill_string.connectors["bit_coupling"].from_body == "shank"
        assert bodies["carriage"].mass_kg == pytest.approx(rig.drill_string.bodies["carriage"].mass_kg + n * tube_kg)
