"""What an extended drill gives (docs/extending.md, "What the model's services see"): the figures of issue 35.

Usage: python benchmarks/bench_extensions.py [--parts clamp,solve,energy,rate_law,study,cost,steady,start]
Prints, on studies/scenes/paper_base.yaml over 0.5 s:

* clamp: a 300 kg clamp on the collar (examples/clamp_extension.py: a Mass1D on its own Node1D and a
  coordinate spring-damper) added in Python, at 1e9 and 1e12 N/m: the step and number of steps the run
  got, those of the same clamp written as a scene body, the penetration rates of both and of the collar
  made 300 kg heavier in the exact formulation;
* solve: Exudyn's own ``exu.SolveDynamic(mbs, model.settings)`` (Exudyn's default solver, and the scene's
  ``solverType=model.solver_type``) against ``model.run()``: the bit's final position;
* energy: the energy balance without the clamp, with a damped clamp (1e9 N/m, 2e4 N s/m), with the friction
  clamp undeclared (not a number) and with its declared energy terms;
* rate_law: examples/rate_dependent_rock.py's law: the exact formulation against the ODE, and Exudyn rk44 at
  several steps against the exact formulation (the slider advances once per step);
* study: a scan of the clamp's mass (three points) on two worker processes against the same points run one
  by one in this process (largest relative difference of the rate);
* cost: CPU s of a run (median of 5, one BLAS thread; shared machine) of the plain scene and with the 1e9 N/m
  clamp (the same step), and the CPU of sizing the step from the assembled system;
* start (not part of the default parts): ``start: preloaded`` with an extension's load of 16.6 kN on the pipe
  (tests/user_rig.py: add_load) against the feed doubled: the pipe's start and the rates; a 300 kg clamp joined
  rigidly to the collar (examples/clamp_extension.py: add_rigid_clamp, a constraint) on generalized-alpha at
  the preset's step against the collar 300 kg heavier in the exact formulation, and the CPU of solving the start
  of the assembled system (models/solvers/exudyn_start.py);
* steady (on tests/pipe_drill.yaml at 65 Hz, not part of the default parts): the periodic steady state
  (Exudyn, standard preset) with a damped clamp (300 kg, 1e9 N/m, 2e4 N s/m) followed in the section
  (models/steady/extension_section.py), against the last 10 of 200 blows of its time run, the clamp as a
  scene body in the exact formulation's orbit, and the orbit with the clamp left out of the section (as
  before: every map run restarts it at rest on the collar).
"""

from __future__ import annotations

import os

for _variable in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_variable, "1")

import argparse
import statistics
import sys
import time
from pathlib import Path

import exudyn

import rpdrill
from rpdrill.models.solvers.exudyn_user_items import assembled_scales
from rpdrill.models.solvers.simulation import prepare

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "examples"))
import clamp_extension  # the examples folder, as a user's module

ALLOWED = ["clamp_extension", "rate_dependent_rock"]  # the examples' modules: code of one's own, allowed here
SCENE = rpdrill.load_scene(ROOT / "studies" / "scenes" / "paper_base.yaml", allow_code=ALLOWED).with_(
    {"solver.end_time_s": 0.5})
COLLAR = SCENE.drill_string.bodies["collar"].mass_kg


def rate(result) -> float:
    return result.metrics["penetration_rate_m_per_s"]


def clamp() -> None:
    exact = rate(rpdrill.simulate(SCENE.with_({"drill_string.bodies.collar.mass_kg": COLLAR + 300.0}),
                                  formulation="exact"))
    print(f"collar {COLLAR + 300:g} kg, exact: {exact * 1e3:.6f} mm/s")
    print("clamp [N/m]  in Python: step [s], steps, rate [mm/s], rel. to exact | as a scene body: step, rate")
    for stiffness in (1e9, 1e12):
        model = rpdrill.build_exudyn(SCENE)
        clamp_extension.add_clamp(model, 300.0, stiffness)
        python = model.run()
        body = SCENE.with_({"drill_string.bodies.clamp": {"mass_kg": 300.0}, "drill_string.connectors.clamp_joint":
                            {"from": "collar", "to": "clamp", "stiffness_n_per_m": stiffness}})
        scene_body = rpdrill.simulate(body)
        step = python.raw.simulation.settings.step_s
        print(f"{stiffness:<13.0e}{step:.4g}, {round(SCENE.solver.end_time_s / step)}, {rate(python) * 1e3:.6f}, "
              f"{abs(rate(python) / exact - 1):.2e} | {scene_body.raw.simulation.settings.step_s:.4g}, "
              f"{rate(scene_body) * 1e3:.6f}", flush=True)


def solve() -> None:
    reference = rpdrill.build_exudyn(SCENE).run()
    bit = reference.raw.bit_position_m[-1]
    print(f"model.run(): bit at {bit:.6e} m, borehole bottom {reference.raw.bottom_m[-1]:.6e} m")
    for label, scene_solver in (("Exudyn's default solver", False), ("solverType=model.solver_type", True)):
        model = rpdrill.build_exudyn(SCENE)
        model.mbs.Assemble()
        exudyn.SolveDynamic(model.mbs, model.settings, **({"solverType": model.solver_type} if scene_solver else {}))
        end = model.mbs.GetNodeOutput(model.bodies["bit"].node, exudyn.OutputVariableType.Coordinates)
        print(f"exu.SolveDynamic, {label}: bit at {end:.6e} m (relative difference {abs(end / bit - 1):.2e})",
              flush=True)


def energy() -> None:
    def balance(extension=None, **parameters) -> float:
        model = rpdrill.build_exudyn(SCENE)
        if extension is not None:
            extension(model, 300.0, **parameters)
        return model.run().metrics["energy_balance_relative_error"]
    print(f"energy balance: plain {balance():.2e}; damped clamp (1e9 N/m, 2e4 N s/m) "
          f"{balance(clamp_extension.add_clamp, stiffness_n_per_m=1e9, damping_n_s_per_m=2e4):.2e}; friction clamp "
          f"undeclared {balance(clamp_extension.add_friction_clamp, stiffness_n_per_m=1e9, damping_n_s_per_m=2e4, declare=False)}"
          f", declared {balance(clamp_extension.add_friction_clamp, stiffness_n_per_m=1e9, damping_n_s_per_m=2e4):.2e}")


def rate_law() -> None:
    values = SCENE.rock.completed()
    own = SCENE.with_({"rock": {"law": "rate_dependent_rock:RateDependentRock", "parameters": {
        "stiffness_n_per_m": values.stiffness_n_per_m, "threshold_n": values.threshold_n, "rate_n_s_per_m": 1e5}}})
    exact, ode = rate(rpdrill.simulate(own, formulation="exact")), rate(rpdrill.simulate(own, formulation="ode"))
    print(f"rate-dependent threshold (c_r 1e5 N s/m): exact {exact * 1e3:.6f} mm/s, ODE {abs(ode / exact - 1):.1e} from it")
    for step in (5e-5, 2e-5, 1e-5, 5e-6, 2.5e-6):
        run = rate(rpdrill.simulate(own.with_({"solver.preset": None, "solver.type": "rk44", "solver.step_s": step})))
        print(f"Exudyn rk44 at {step:<8g}: {run * 1e3:.6f} mm/s ({run / exact - 1:+.2e})", flush=True)


def study(tmp: Path) -> None:
    import yaml

    data = {"name": "clamp_scan", "base_scene": str(ROOT / "studies" / "scenes" / "paper_base.yaml"),
            "base_overrides": {"solver.end_time_s": 0.5, "extensions": {"clamp": {
                "function": "clamp_extension:add_clamp", "parameters": {"mass_kg": 300.0, "stiffness_n_per_m": 1e9}}}},
            "scan": {"extensions.clamp.parameters.mass_kg": [100.0, 300.0, 600.0]}, "metrics": ["penetration_rate_m_per_s"]}
    (tmp / "scan.yaml").write_text(yaml.safe_dump(data))
    table = rpdrill.run_study(rpdrill.load_study(tmp / "scan.yaml", allow_code=ALLOWED), workers=2)
    base = SCENE.with_({"extensions": data["base_overrides"]["extensions"]})
    worst = max(abs(row.penetration_rate_m_per_s / rate(rpdrill.simulate(
        base.with_({"extensions.clamp.parameters.mass_kg": mass}))) - 1)
        for mass, row in zip(table["extensions.clamp.parameters.mass_kg"], table.itertuples(), strict=True))
    print(f"clamp mass scan on 2 workers against single runs: largest relative difference {worst:.1e}")


def cost() -> None:
    def cpu(make) -> float:
        times = []
        for _ in range(5):
            model = make()
            start = time.process_time()
            model.run()
            times.append(time.process_time() - start)
        return statistics.median(times)

    plain = cpu(lambda: rpdrill.build_exudyn(SCENE))
    model = rpdrill.build_exudyn(SCENE)

    def with_clamp():
        built = rpdrill.build_exudyn(SCENE)
        clamp_extension.add_clamp(built, 300.0, 1e9)
        return built
    clamped = cpu(with_clamp)
    start = time.process_time()
    for _ in range(20):
        assembled_scales(model)
    sizing = (time.process_time() - start) / 20
    print(f"CPU s per run of 0.5 s: plain {plain:.3f}, with the 1e9 N/m clamp {clamped:.3f} "
          f"(steps {round(0.5 / prepare(SCENE).settings.step_s)} both); sizing the step from the assembled system "
          f"{sizing * 1e3:.2f} ms")


def steady() -> None:
    from rpdrill.models.steady import regimes

    frequency = 65.0
    joint = {"mass_kg": 300.0, "stiffness_n_per_m": 1e9, "damping_n_s_per_m": 2e4}
    drill = rpdrill.load_scene(ROOT / "tests" / "pipe_drill.yaml", allow_code=ALLOWED).with_({
        "solver.formulation": "exudyn", "impact.frequency_hz": frequency, "solver.steady_state": "periodic"})
    clamped = drill.with_({"extensions": {"clamp": {"function": "clamp_extension:add_clamp", "parameters": joint}}})
    start = time.process_time()
    orbit = rpdrill.simulate(clamped)
    cpu = time.process_time() - start
    print(f"periodic, the clamp in the section: {rate(orbit) * 1e3:.6f} mm/s ({orbit.steady_state.regime_name}, |mu|max "
          f"{orbit.steady_state.floquet_max_abs:.4f}, {orbit.steady_state.map_runs} map runs, {cpu:.2f} CPU s)")
    time_run = rpdrill.simulate(clamped.with_({"solver.steady_state": "time", "solver.end_time_s": 200 / frequency,
                                               "metrics.transient_blows": 190, "metrics.block_blows": 10}))
    body = drill.with_({"solver.formulation": "exact", "drill_string.bodies.clamp": {"mass_kg": joint["mass_kg"]},
                        "drill_string.connectors.clamp_joint": {"from": "collar", "to": "clamp", **{
                            key: joint[key] for key in ("stiffness_n_per_m", "damping_n_s_per_m")}}})
    exact = rpdrill.simulate(body)
    with_extension_coordinates = regimes.with_extension_coordinates
    regimes.with_extension_coordinates = lambda simulation: simulation  # the section without the clamp
    try:
        restarted = rpdrill.simulate(clamped)
    finally:
        regimes.with_extension_coordinates = with_extension_coordinates
    for label, other in (("time run, last 10 of 200 blows", time_run), ("the clamp as a scene body, exact orbit", exact),
                         ("the clamp left out of the section (restarted at rest every blow)", restarted)):
        print(f"{label}: {rate(other) * 1e3:.6f} mm/s (relative to the orbit {rate(other) / rate(orbit) - 1:+.2e})")


def start() -> None:
    from rpdrill.models.solvers.exudyn_start import solve_preload

    sys.path[:0] = [str(ROOT / "tests"), str(ROOT)]  # the tests' user module (user_rig.py, which imports examples.)
    feed = SCENE.feed.force_n
    loaded = SCENE.with_({"extensions": {"load": {"function": "user_rig:add_load", "parameters": {"force_n": feed}}}})
    doubled = SCENE.with_({"feed.force_n": 2 * feed})
    extended, fed = rpdrill.simulate(loaded), rpdrill.simulate(doubled)
    for label, result in (("the extension's load", extended), ("the feed doubled", fed)):
        print(f"{label}: pipe starts at {result.timeseries['pipe_position_m'].iloc[0] * 1e3:.4f} mm, "
              f"{rate(result) * 1e3:.6f} mm/s")
    print(f"rates relative: {rate(extended) / rate(fed) - 1:+.2e}")
    model = rpdrill.build_exudyn(loaded)
    times = []
    for _ in range(20):
        begin = time.process_time()
        solve_preload(model)
        times.append(time.process_time() - begin)
    print(f"solving the assembled system's start: {statistics.median(times) * 1e3:.2f} ms CPU (median of 20)")
    rigid = SCENE.with_({"solver.type": "generalized_alpha", "extensions": {"clamp": {
        "function": "clamp_extension:add_rigid_clamp", "parameters": {"mass_kg": 300.0}}}})
    heavier = rate(rpdrill.simulate(SCENE.with_({"drill_string.bodies.collar.mass_kg": COLLAR + 300.0}),
                                    formulation="exact"))
    joined = rpdrill.simulate(rigid)
    print(f"rigid clamp on generalized_alpha at {joined.raw.simulation.settings.step_s:.3g} s: {rate(joined) * 1e3:.6f} "
          f"mm/s; collar 300 kg heavier (exact) {heavier * 1e3:.6f} mm/s ({rate(joined) / heavier - 1:+.2e})")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--parts", default="clamp,solve,energy,rate_law,study,cost")
    parts = parser.parse_args().parts.split(",")
    import tempfile

    for part in parts:
        if part == "study":
            with tempfile.TemporaryDirectory() as tmp:
                study(Path(tmp))
        else:
            globals()[part]()


if __name__ == "__main__":
    main()
