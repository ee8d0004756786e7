"""Wave rods: what a run checks before it starts (issue 47, section 4) and a string that ends free (issue 45,
item 5): a wave step off the rods' grid refused naming its key, the step and memory budgets counting the
characteristics' grid before anything is allocated, the shipped wave scene on Exudyn clean, the period check
tolerant of rounding, a rod without a rock under it."""

from __future__ import annotations

import json
import math
import time
import warnings
from pathlib import Path

import numpy as np
import pytest
import yaml
from commands import main
from scenes import read_yaml

import rpdrill

E_PA, RHO = 2.1e11, 7850.0
C = math.sqrt(E_PA / RHO)
SHIPPED = Path(__file__).resolve().parents[1] / "studies" / "scenes" / "top_hammer_waves.yaml"


def shipped(**solver) -> dict:
    data = read_yaml(str(SHIPPED))
    data["solver"].update(solver)
    data["solver"]["end_time_s"], data["metrics"] = 0.04, {"transient_blows": 1, "block_blows": 1}
    return data


def write(tmp_path: Path, data: dict) -> Path:
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


@pytest.mark.parametrize("formulation, key", [("exact", "wave_step_s"), ("exudyn", "step_s")])
def test_a_wave_step_off_the_rods_grid_is_refused_naming_its_key(tmp_path, capsys, formulation, key):
    """1 ms on the shipped top hammer ran "ok" at 366 mm/s (11 times the drill's rate) with the transit times off by
    2 740 %: refused before anything runs, exit 2, naming the key, the value and a step that fits."""
    data = shipped(formulation=formulation, **{key: 1e-3})
    assert main(["simulate", str(write(tmp_path, data)), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    error = capsys.readouterr().err
    assert f"solver.{key}: 0.001" in error and "whole number of steps" in error and "at most" in error
    assert not (tmp_path / "out" / "summary.json").exists()


@pytest.mark.slow
def test_a_wave_step_near_the_rods_grid_runs_on_it_and_says_so(tmp_path):
    """2.3 us is no whole fraction of the shipped scene's period and transit times; the run takes the nearest step
    on the rods' grid and says which (the transit times as run are in the summary)."""
    data = shipped(formulation="exact", wave_step_s=2.3e-6)
    with pytest.warns(UserWarning, match=r"solver.wave_step_s 2.3e-06 runs as \d\.\d+e-06 s: the nearest step"):
        assert main(["simulate", str(write(tmp_path, data)), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    run = json.loads((tmp_path / "out" / "summary.json").read_text())["run"]["solver"]
    assert abs(run["wave_step_s"] - 2.3e-6) < 0.1 * 2.3e-6
    assert max(abs(error) for error in run["transit_time_errors"].values()) < 1e-3


@pytest.mark.parametrize("change, key", [
    ({"length_m": 1e-6}, "drill_string.bodies.rod1.length_m"),
    ({"density_kg_per_m3": 1e-9}, "drill_string.bodies.rod1.density_kg_per_m3"),
    ({"youngs_modulus_pa": 1e30}, "drill_string.bodies.rod1.youngs_modulus_pa"),
    ({"length_m": 3.66e5}, "drill_string.bodies.rod1.length_m"),
    ("wave_step_s", "solver.wave_step_s")])
def test_the_budgets_count_the_characteristics_grid(change, key):
    """A 1 um rod, a density of 1e-9, E = 1e30, a 366 km rod or a 1e-12 s step asked for 19 GB to 11 TiB (the step's
    search) or would have held the waves of a rod 1e10 steps long: refused before anything is allocated, naming
    the key (the budget: --max-steps, --max-memory-gb), within a second."""
    data = shipped(formulation="exact")
    data["start"] = "rest"  # E = 1e30 would be refused by the preload first (it names the modulus too)
    if change == "wave_step_s":
        data["solver"]["wave_step_s"] = 1e-12
    else:
        data["drill_string"]["bodies"]["rod1"].update(change)
    started = time.process_time()
    with pytest.raises(rpdrill.BudgetError, match="--max-steps|--max-memory-gb") as error:
        rpdrill.simulate(rpdrill.Scene.model_validate(data))
    assert key in str(error.value)
    assert time.process_time() - started < 2.0


@pytest.mark.slow
def test_the_shipped_wave_scene_runs_ok_on_exudyn_without_warnings(tmp_path, capsys):
    """Every wave scene on Exudyn was "unstable" with ten NumPy warnings: the stability check computed on the rigid
    joints' infinite stiffness and the faces' zero mass. It now checks what Exudyn integrates (the bodies with mass,
    their links, the rods' dashpots on them): one blow of the shipped scene, status ok, nothing printed. One blow,
    not two: the check runs once before the steps, the status reads the whole run (its balance, its one block);
    3.5 CPU s against 6.5. The couplings' figures still tell: a sprung and damped coupling2 (5e9 N/m, 5e4 N s/m)
    loses 24 J of that blow, an absorber of 1e13 N/m passes 10 J on (measured)."""
    data = shipped(formulation="exudyn")
    data["solver"]["end_time_s"], data["metrics"] = 0.02, {"transient_blows": 0, "block_blows": 1}
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert main(["simulate", str(write(tmp_path, data)), "--out", str(tmp_path / "out")]) == 0
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["status"] == "ok"
    assert "warning" not in capsys.readouterr().err
    # its rigid couplings per blow: what came, what passed, what was lost (nothing: a rigid joint stores none)
    couplings = json.loads((tmp_path / "out" / "wave_readings.json").read_text())["couplings"]
    assert set(couplings) == {"shank_coupling", "coupling1", "coupling2", "coupling3"}
    for coupling in couplings.values():
        assert len(coupling["energy_out_j"]) == 1 and coupling["energy_out_j"][0] > 100.0
        assert np.allclose(coupling["lost_j"], 0.0, atol=1e-9 * coupling["energy_in_j"][0])


def test_the_period_check_tolerates_rounding():
    """end_time_s = 10 T with frequency_hz = 1 / (10 T) (T the transit time of a 1.01 m rod) is one period, not
    less (1 / (1 / (10 T)) rounds above 10 T: the check refused it)."""
    transit = 1.01 / C
    data = {"name": "one_period", "drill_string": {"bodies": {"rod": {"length_m": 1.01, "diameter_m": 0.045,
                                                                      "model": "waves", "youngs_modulus_pa": E_PA,
                                                                      "density_kg_per_m3": RHO}},
                                                   "impact_body": "rod"},
            "feed": {"force_n": 0.0}, "impact": {"frequency_hz": 1 / (10 * transit), "amplitude_n": 1e5,
                                                 "duration_s": transit, "shape": "rectangular"},
            "solver": {"formulation": "exact", "end_time_s": 10 * transit},
            "metrics": {"transient_blows": 0, "block_blows": 1}}
    assert 10 * transit < 1 / (1 / (10 * transit))  # the rounding the check used to refuse
    assert rpdrill.Scene.model_validate(data).solver.end_time_s == 10 * transit


def free_rod(formulation: str, **scene) -> dict:
    """A rectangular pulse F = 100 kN of 100 us on the top of a 45 mm x 2 m rod that ends free (no rock body)."""
    return {"name": "free_rod", "drill_string": {"bodies": {"rod": {"length_m": 2.0, "diameter_m": 0.045,
                                                                    "model": "waves", "youngs_modulus_pa": E_PA,
                                                                    "density_kg_per_m3": RHO}},
                                                 "impact_body": "rod"},
            "feed": {"force_n": 0.0}, "impact": {"frequency_hz": 1 / 1e-3, "amplitude_n": 1e5, "duration_s": 1e-4,
                                                 "shape": "rectangular"},
            "solver": {"formulation": formulation, "end_time_s": 1e-3, "output_interval_s": 1e-6},
            "metrics": {"transient_blows": 0, "block_blows": 1}, **scene}


@pytest.mark.parametrize("formulation", ["exact", "exudyn"])
def test_a_rod_may_end_free(formulation):
    """No rock body: the foot is free. The pulse arrives there after T = L / c and the foot moves at 2 F / Z while
    it passes (the reflection doubles the velocity), its stress stays 0, the top carries F while it is applied;
    at the end the rod has the pulse's momentum F tau and no rock took anything."""
    result = rpdrill.simulate(rpdrill.Scene.model_validate(free_rod(formulation)))
    z = math.pi * 0.045**2 / 4 * math.sqrt(E_PA * RHO)
    transit = 2.0 / C
    t, columns = result.time_s, result.columns()
    passing = (t > transit + 5e-6) & (t < transit + 95e-6)
    assert np.allclose(columns["rod[bottom]_velocity_m_per_s"][passing], 2e5 / z, rtol=1e-9)
    assert np.max(np.abs(columns["rod_bottom_stress_pa"])) < 1e-9 * 1e5 / (math.pi * 0.045**2 / 4)
    applied = (t > 5e-6) & (t < 95e-6)
    assert np.allclose(columns["rod_top_stress_pa"][applied] * math.pi * 0.045**2 / 4, 1e5, rtol=1e-9)
    assert result.waves.energy_j[-1] == pytest.approx(1e10 * 1e-4 / z, rel=1e-9)  # the pulse's energy, all kept
    assert result.metrics["rock_energy_per_blow_j"] == 0.0


def test_a_rock_needs_a_rock_body_and_none_is_no_rock(tmp_path, capsys):
    data = free_rod("exact", rock={"name": "sandstone"})
    assert main(["simulate", str(write(tmp_path, data)), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    error = capsys.readouterr().err
    assert "drill_string.rock_body" in error and "law: none" in error
    named = free_rod("exact", rock={"law": "none"})
    named["drill_string"]["rock_body"] = "rod"  # the named body's foot is free: the same run
    free = rpdrill.simulate(rpdrill.Scene.model_validate(free_rod("exact")))
    assert np.array_equal(rpdrill.simulate(rpdrill.Scene.model_validate(named)).position_m, free.position_m)
