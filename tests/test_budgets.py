"""Run-cost estimates (models.solvers.cost) and budgets (studies.runtime.budgets): what a run will cost, which key
makes it cost that, and the refusals above a budget. The estimate against measurement is
benchmarks/bench_budgets.py (no timing here).
Unit tests of models.solvers.cost and studies.runtime.budgets on prepared runs (models.solvers.simulation): they
import them."""

from __future__ import annotations

import pytest
from scenes import PAPER_BASE, scene

from rpdrill import Budget, BudgetError, load_study
from rpdrill.models.solvers.cost import Cause, run_cost
from rpdrill.models.solvers.simulation import prepare
from rpdrill.studies.runtime.budgets import MAX_CPU_HOURS

# A prepared run's cost and the key that causes it, and the budgets' checks of a run and of many runs.
UNITS = ("rpdrill.models.solvers.cost", "rpdrill.models.solvers.simulation", "rpdrill.studies.runtime.budgets")

PRESET = {"solver__step_s": None, "solver__type": None}  # the standard preset chooses the step


def test_exudyn_steps_are_the_end_time_over_the_fixed_step():
    cost = run_cost(prepare(scene(solver__end_time_s=0.3)))  # the test drill: rk44 at 2e-5 s
    assert cost.steps == pytest.approx(0.3 / 2e-5) and cost.step_s == 2e-5
    assert cost.steps_cause == Cause("solver.step_s", 2e-5)


@pytest.mark.parametrize("overrides, key", [
    ({"rock__stiffness_n_per_m": 1e300}, "rock.stiffness_n_per_m"),  # the stiffest mode sets the step
    ({"drill_string__bodies__bit__mass_kg": 1e-20}, "drill_string.bodies.bit.mass_kg"),  # so does the lightest body
    ({"impact__duration_s": 1e-9}, "impact.duration_s"),  # the pulse must be resolved
    ({"solver__end_time_s": 1e5}, "solver.end_time_s"),  # a usual step over a very long run
])
def test_the_key_that_makes_many_steps_is_named(overrides, key):
    assert run_cost(prepare(scene(**PRESET, **overrides))).steps_cause.key == key


def test_steps_and_cpu_time_grow_with_the_end_time_and_memory_with_the_samples():
    short, long = (run_cost(prepare(scene(**PRESET, solver__end_time_s=t))) for t in (0.5, 1.0))
    assert long.steps == pytest.approx(2 * short.steps) and long.cpu_s == pytest.approx(2 * short.cpu_s)
    # samples every 1e-7 s: over 100 times as many as the preset's steps (1.5e-5 s on the test drill)
    sampled = run_cost(prepare(scene(**PRESET, solver__end_time_s=0.5)), Cause("solver.output_interval_s", 1e-7))
    assert sampled.memory_bytes > 10 * short.memory_bytes and sampled.memory_cause.key == "solver.output_interval_s"


def test_a_run_beyond_a_budget_is_refused_naming_the_key_and_the_option():
    simulation = prepare(scene(solver__end_time_s=0.3))
    with pytest.raises(BudgetError) as error:
        Budget(max_steps=1e3).check_run(simulation, "drill.yaml")
    assert str(error.value).startswith("drill.yaml: solver.step_s: 2e-05: ") and "--max-steps" in str(error.value)
    with pytest.raises(BudgetError, match="--max-memory-gb"):
        Budget(max_memory_gb=1e-6).check_run(simulation, "drill.yaml")


def test_many_runs_beyond_the_cpu_budget_need_yes():
    hours = 2 * MAX_CPU_HOURS * 3600
    with pytest.raises(BudgetError, match="--yes"):
        Budget().check_total("study.yaml", "scan: 10 points", 10, hours)
    Budget(accept_long=True).check_total("study.yaml", "scan: 10 points", 10, hours)


def test_study_points_carry_their_estimates(tmp_path):
    path = tmp_path / "study.yaml"
    path.write_text(f"name: s\nbase_scene: {PAPER_BASE}\nscan: {{solver.end_time_s: [0.5, 1.0]}}\n"
                    "metrics: [penetration_rate_m_per_s]\n")
    first, second = load_study(path).points
    assert second.cpu_s == pytest.approx(2 * first.cpu_s) and first.cpu_s > 0
