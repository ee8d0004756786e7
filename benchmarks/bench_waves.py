"""Rods as waves (models.waves, issue #38): the closed-form checks in the exact and the Exudyn formulation
with each blow's CPU time, and the wave and lumped models side by side on the shipped top-hammer scene
and the four-rod string.

    python benchmarks/bench_waves.py [--checks] [--strings] [--lumped-lundberg]

``--checks`` (default when nothing is given): Lundberg's efficiency of a rectangular pulse into a bilinear
rock, eta(alpha) = 2 (1 - exp(-alpha))^2 / alpha (rigid unloading: k_u = 1e4 k_l, against eta (1 - 1e-4);
elastic: k_u = 10 k_l, against eta (1 - k_l / k_u); stiffer: k_u = 1e5 and 1e6 k_l at alpha 1.256); the rigid
4.5 kg piston at 9 m/s on the 45 mm rod through a contact ten times a 240-segment rod's segment stiffness
(against the contact-spring closed form) and with a rigid impact (against Z v_p exp(-Z t / m_p)); the
equal-impedance rod piston's rectangular pulse; an impedance step 45 -> 55 mm. CPU: the run of the check's
blow, after one warm-up run (numba's compiled kernels load from disk once per process).
``--strings``: studies/scenes/top_hammer_waves.yaml (and its lumped twin top_hammer_piston.yaml at 4 and 16
segments per rod, the piston at twice that) and four_rod_string.yaml with wave rods (and lumped at 4 and 16):
penetration rate, largest rod stress, the rock's share of the blow energy, peak rock force, CPU (64 segments
per rod would take Exudyn's standard preset about an hour per run on this machine).
``--strings --fine [--segments 16,32,64] [--scenes top_hammer_piston,four_rod_string]``: the lumped rods of
the scenes at these segments per rod in the exact formulation (the convergence of the lumped model towards
the waves).
``--lumped-lundberg``: Lundberg's check on lumped rods of 64 to 512 segments (Exudyn, reference preset),
the dispersion the wave element removes.
``--cost --base REV [--repeat N] [--formulation exact|exudyn] [--blows B]``: the same in one formulation (default
exact; the scene's first B blows if given) at git revision REV and at this checkout, in turns, each a process of its
own (N rounds; each round's ratio and their median), and whether both gave the same run to the bit.
``--cost [--repeat N]``: the CPU per blow of studies/scenes/top_hammer_waves.yaml as shipped (20 blows) in each
formulation, the median of N runs (default 3) after a warm-up, the process's CPU.
``--fronts``: tests/test_wave_fronts.py's cases against its independent characteristics solution
(tests/wave_reference.py): the rigid piston's re-strike within a step (the largest error of the blows' peaks,
tension, rebound and rock energy, as shares of Z v_p and of the blow energy) at T / 356 and T / 1424 in each
formulation, and the energy balance of a stiff spring (8e9 N/m) between the rod's foot and an 8 kg bit at each
Exudyn preset.
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from rpdrill.models.definition.scene import Scene
from rpdrill.models.drill.piston import rigid_piston_pulse_n
from rpdrill.models.drill.wave_rod import reflected_force_share, transmitted_force_share
from rpdrill.models.evaluation.metrics import summary_metrics
from rpdrill.models.runs.scene_run import run as run_simulation
from rpdrill.models.solvers.simulation import prepare
from rpdrill.studies.inputs.reading import read_yaml

E_PA, RHO, D = 2.1e11, 7850.0, 0.045
STEEL = {"diameter_m": D, "youngs_modulus_pa": E_PA, "density_kg_per_m3": RHO}
AREA = math.pi * D**2 / 4
Z = AREA * math.sqrt(E_PA * RHO)
C = math.sqrt(E_PA / RHO)
SPEED, PULSE_S = 9.0, 200e-6


def one_blow(bodies: dict, impact: dict, rock: dict, end_time_s: float, formulation: str, connectors=None,
             impact_body: str = "rod", rock_body: str = "rod", **solver: Any) -> Scene:
    return Scene.model_validate({
        "name": "wave_check", "drill_string": {"bodies": bodies, "connectors": connectors or {},
                                               "impact_body": impact_body, "rock_body": rock_body},
        "feed": {"force_n": 0.0}, "impact": {"frequency_hz": 1 / end_time_s, **impact}, "rock": rock,
        "solver": {"formulation": formulation, "end_time_s": end_time_s, "output_interval_s": 1e-6, **solver},
        "metrics": {"transient_blows": 0, "block_blows": 1}})


def rod(length_m: float, **more: Any) -> dict:
    return {"length_m": length_m, "model": "waves", **STEEL, **more}


def timed(scene: Scene) -> tuple[Any, float]:
    start = time.process_time()
    result = run_simulation(prepare(scene)).raw
    return result, time.process_time() - start


def lundberg(alpha: float, ratio: float, formulation: str, model: str = "waves", segments: int = 1,
             preset: str = "standard") -> tuple[float, float, float]:
    """(efficiency, closed form, CPU s): tests/test_waves.py's check (a rod of 7.5 c T, run for 14 T)."""
    loading = alpha * Z / PULSE_S
    body = rod(7.5 * C * PULSE_S) if model == "waves" else {"length_m": 7.5 * C * PULSE_S, "segments": segments, **STEEL}
    scene = one_blow({"rod": body}, {"amplitude_n": 1e5, "duration_s": PULSE_S, "shape": "rectangular"},
                     {"law": "bilinear", "loading_stiffness_n_per_m": loading,
                      "unloading_stiffness_n_per_m": ratio * loading}, 14 * PULSE_S, formulation, preset=preset)
    result, cpu = timed(scene)
    efficiency = summary_metrics(result)["rock_transfer_efficiency"]
    return efficiency, 2 * (1 - math.exp(-alpha)) ** 2 / alpha * (1 - 1 / ratio), cpu


def rigid_piston(contact: float | None, formulation: str, step_s: float | None = None) -> tuple[float, ...]:
    """(peak / Z v_p - 1, largest excess over the closed form / Z v_p, peak / closed-form peak - 1, CPU s), the
    peak the largest sample (every step: the preset's, 0.7 us, or ``step_s``)."""
    piston = {"mass_kg": 4.5, "velocity_m_per_s": SPEED, **({"contact_stiffness_n_per_m": contact} if contact else {})}
    step = {} if step_s is None else {"wave_step_s": step_s} if formulation == "exact" else {"step_s": step_s}
    result, cpu = timed(one_blow({"rod": rod(0.5)}, {"piston": piston}, {"name": "sandstone"}, 1e-3, formulation,
                                 output_interval_s=1e-7, **step))
    t, force = result.time_s, result.piston.contact_force_n
    before = t < 2 * 0.5 / C - 1e-6
    before[0] = False  # the sample before the strike
    closed = rigid_piston_pulse_n(t[before], 4.5, SPEED, Z, contact or math.inf)
    peak = rigid_piston_pulse_n(np.linspace(0, 5e-6, 50001), 4.5, SPEED, Z, contact or math.inf).max()
    return (force[before].max() / (Z * SPEED) - 1, float(np.max(force[before] - closed)) / (Z * SPEED),
            force[before].max() / peak - 1, cpu)


def rod_piston(formulation: str) -> tuple[float, float, float, float]:
    """(plateau / (Z v_p / 2) - 1, length / (2 L_p / c) - 1, largest / plateau - 1, CPU s)."""
    result, cpu = timed(one_blow({"rod": rod(4.0)}, {"piston": {**rod(0.5), "velocity_m_per_s": SPEED}},
                                 {"name": "sandstone"}, 2e-3, formulation, output_interval_s=1e-7))
    t, force = result.time_s, result.piston.contact_force_n
    duration = 2 * 0.5 / C
    plateau = float(np.mean(force[(t > 0.25 * duration) & (t < 0.75 * duration)]))
    above = t[(force > 0.5 * plateau) & (t < 2 * duration)]
    return plateau / (Z * SPEED / 2) - 1, (above.max() - above.min()) / duration - 1, force.max() / plateau - 1, cpu


def impedance_step(formulation: str, upper: float = 0.045, lower: float = 0.055) -> tuple[float, float, float]:
    """(transmitted force / 2 Z2 / (Z1 + Z2) - 1, crossing energy / (1 - R^2) - 1, CPU s)."""
    length = 2 * C * 100e-6
    z1, z2 = (math.pi * d**2 / 4 * math.sqrt(E_PA * RHO) for d in (upper, lower))
    scene = one_blow({"upper": {**rod(length), "diameter_m": upper}, "lower": {**rod(length), "diameter_m": lower}},
                     {"amplitude_n": 1e5, "duration_s": 100e-6, "shape": "rectangular"}, {"name": "sandstone"},
                     3 * length / C - 10e-6, formulation, connectors={"joint": {"from": "upper", "to": "lower"}},
                     impact_body="upper", rock_body="lower")
    result, cpu = timed(scene)
    waves = result.waves
    arrived = (result.time_s > length / C + 25e-6) & (result.time_s < length / C + 75e-6)
    transmitted = float(np.mean(waves.compression_n[arrived, waves.port("lower", "top")])) / 1e5
    crossed = waves.blow_energy_j[0, waves.port("lower", "top")] / waves.blow_energy_j[0, waves.port("upper", "top")]
    return (transmitted / transmitted_force_share(z1, z2) - 1, crossed / (1 - reflected_force_share(z1, z2) ** 2) - 1,
            cpu)


def checks() -> None:
    for formulation in ("exact", "exudyn"):  # warm-up: the compiled kernels and Exudyn load once per process
        lundberg(1.0, 10.0, formulation)
    print("| check | formulation | figure | error | CPU s |")
    print("|---|---|---|---|---|")
    for formulation in ("exact", "exudyn"):
        for ratio, label in ((1e4, "rigid (k_u = 1e4 k_l)"), (10.0, "k_u = 10 k_l")):
            for alpha in (0.3, 1.256, 4.0):
                efficiency, closed, cpu = lundberg(alpha, ratio, formulation)
                print(f"| Lundberg, {label}, alpha {alpha:g} | {formulation} | eta {efficiency:.6f} "
                      f"(closed form {closed:.6f}) | {efficiency - closed:+.1e} | {cpu:.2f} |")
        for ratio in (1e5, 1e6):  # stiffer unloadings: the works' integral of a stiffer mode loses digits
            efficiency, closed, cpu = lundberg(1.256, ratio, formulation)
            print(f"| Lundberg, k_u = 1e{round(math.log10(ratio))} k_l, alpha 1.256 | {formulation} | eta {efficiency:.6f} "
                  f"(closed form {closed:.6f}) | {efficiency - closed:+.1e} | {cpu:.2f} |")
    for formulation in ("exact", "exudyn"):
        for contact, label in ((10 * E_PA * AREA * 240 / 0.5, "contact 10 x a 240-segment rod's segment"),
                               (None, "rigid impact")):
            for step_s in (None, 1e-7):
                peak, excess, against, cpu = rigid_piston(contact, formulation, step_s)
                reference = "closed form" if contact else "Z v_p"
                sampled = "preset step" if step_s is None else f"step {step_s * 1e6:g} us"
                print(f"| rigid piston, {label}, {sampled} | {formulation} | peak - {reference} "
                      f"{against if contact else peak:+.2e}, peak - Z v_p {peak:+.2%} | largest excess over the "
                      f"closed form {excess:+.1e} Z v_p | {cpu:.2f} |")
        plateau, length, largest, cpu = rod_piston(formulation)
        print(f"| rod piston, equal impedance | {formulation} | plateau - Z v_p/2 {plateau:+.1e}, length - 2 L_p/c "
              f"{length:+.2%} | largest force - plateau {largest:+.1e} | {cpu:.2f} |")
        transmitted, crossed, cpu = impedance_step(formulation)
        print(f"| impedance step 45 -> 55 mm | {formulation} | transmitted force - 2 Z2/(Z1+Z2) {transmitted:+.1e} | "
              f"crossing energy - (1 - R^2) {crossed:+.1e} | {cpu:.2f} |")


def strings(fine: bool = False, refined: tuple[int, ...] = (16, 32, 64),
            scenes: tuple[str, ...] = ("top_hammer_piston", "four_rod_string")) -> None:
    print("| scene | model | formulation | penetration rate mm/s | largest rod stress MPa | rock energy / blow energy "
          "| peak rock force kN | CPU s |")
    print("|---|---|---|---|---|---|---|---|")
    cases = [("top_hammer_waves", "waves", "exact", None), ("top_hammer_waves", "waves", "exudyn", None),
             ("top_hammer_piston", "lumped", "exact", 4)]
    cases += [("top_hammer_piston", "lumped", "exudyn", n) for n in (4, 16)]
    cases += [("four_rod_string", "waves", "exact", None), ("four_rod_string", "waves", "exudyn", None),
              ("four_rod_string", "lumped", "exact", 4)]
    cases += [("four_rod_string", "lumped", "exudyn", n) for n in (4, 16)]
    if fine:  # the lumped rods refined in the exact formulation: do they go to the waves?
        cases = [(name, "lumped", "exact", n) for name in scenes for n in refined]
    for name, model, formulation, segments in cases:
        data = read_yaml(f"studies/scenes/{name}.yaml")
        bodies = data["drill_string"]["bodies"]
        for body in bodies.values():
            if "diameter_m" in body and "length_m" in body:
                body.pop("segments", None)
                body.update({"model": "waves"} if model == "waves" else {"segments": segments})
        piston = data["impact"].get("piston")
        if piston is not None and segments:
            piston.update({"segments": 2 * segments})
        data["solver"] = {**data["solver"], "formulation": formulation}
        result, cpu = timed(Scene.model_validate(data))
        m = summary_metrics(result)
        share = m["rock_transfer_efficiency"]
        print(f"| {name} | {model}{f' ({segments} per rod)' if segments else ''} | {formulation} | "
              f"{1e3 * m['penetration_rate_m_per_s']:.4f} | {1e-6 * m['rod_stress_max_pa']:.1f} | {share:.4f} | "
              f"{1e-3 * m['rock_force_max_n']:.1f} | {cpu:.1f} |", flush=True)


def lumped_lundberg() -> None:
    print("| segments | alpha | eta - closed form | CPU s |")
    print("|---|---|---|---|")
    for segments in (64, 128, 256, 512):
        for alpha in (0.3, 1.256, 4.0):
            efficiency, closed, cpu = lundberg(alpha, 1e4, "exudyn", "lumped", segments, "reference")
            print(f"| {segments} | {alpha:g} | {efficiency - closed:+.4f} | {cpu:.1f} |", flush=True)


def cost(repeat: int = 3) -> None:
    print("| scene | formulation | CPU s per blow (median of runs) | runs |")
    print("|---|---|---|---|")
    data = read_yaml("studies/scenes/top_hammer_waves.yaml")
    blows = round(data["solver"]["end_time_s"] * data["impact"]["frequency_hz"])
    for formulation in ("exact", "exudyn"):
        scene = Scene.model_validate({**data, "solver": {**data["solver"], "formulation": formulation}})
        timed(scene.with_({"solver.end_time_s": 0.02, "metrics.transient_blows": 0, "metrics.block_blows": 1}))
        times = sorted(timed(scene)[1] for _ in range(repeat))
        print(f"| top_hammer_waves | {formulation} | {times[len(times) // 2] / blows:.4f} | "
              f"{', '.join(f'{t:.2f}' for t in times)} |", flush=True)


# One formulation's CPU per blow of the shipped top-hammer wave scene, in a process of its own (rpdrill imported
# from PYTHONPATH: this checkout, or a revision exported by --base), after a warm-up run; through the public API.
PER_BLOW = """
import hashlib, statistics, sys, time, warnings
warnings.simplefilter("ignore")
import numpy as np
import rpdrill
formulation, repeat, blows = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
scene = rpdrill.load_scene("studies/scenes/top_hammer_waves.yaml").with_({"solver.formulation": formulation})
if blows:
    scene = scene.with_({"solver.end_time_s": blows / scene.impact.frequency_hz, "metrics.transient_blows": blows - 1,
                         "metrics.block_blows": 1})
blows = round(scene.solver.end_time_s * scene.impact.frequency_hz)
rpdrill.simulate(scene)
times = []
for _ in range(repeat):
    start = time.process_time()
    result = rpdrill.simulate(scene)
    times.append(time.process_time() - start)
digest = hashlib.sha256()  # every column of the time series, every figure but the run's CPU time, to the bit
for name, column in sorted(result.columns().items()):
    digest.update(name.encode() + np.ascontiguousarray(column, dtype=float).tobytes())
for name, value in sorted(result.metrics.items()):
    if name != "cpu_time_s":
        digest.update(f"{name}={value!r}".encode())
print(rpdrill.__file__, statistics.median(times) / blows, digest.hexdigest()[:16])
"""


def cost_against(base: str, rounds: int, formulation: str = "exact", blows: int = 0) -> None:
    """CPU per blow of the shipped top-hammer wave scene (its first ``blows`` blows, if given) at revision ``base``
    and at this checkout, in turns (base, then here, ``rounds`` times; each a process of 3 runs after a warm-up,
    its median): each round's ratio and the median of the rounds', and whether both gave the same run to the bit
    (a digest of every time-series column and every figure but the CPU time)."""
    sys.path.insert(0, str(Path(__file__).parent))
    from bench_same_results import ROOT, export

    with tempfile.TemporaryDirectory() as folder:
        trees = {"base": export(base, Path(folder)), "here": ROOT}
        print(f"| round | {base} CPU s per blow | this checkout | ratio | the same run to the bit |")
        print("|---|---|---|---|---|")
        ratios = []
        for n in range(rounds):
            per_blow, digests = {}, {}
            for name, tree in trees.items():
                env = {**os.environ, "PYTHONPATH": str(tree)}
                cwd = tree / "rpdrill" if name == "base" else tree
                out = subprocess.run([sys.executable, "-c", PER_BLOW, formulation, "3", str(blows)], env=env, cwd=cwd,
                                     check=True, capture_output=True, text=True).stdout.split()
                if not out[0].startswith(str(tree)):
                    raise SystemExit(f"rpdrill imported from {out[0]}, not from {tree}")
                per_blow[name], digests[name] = float(out[1]), out[2]
            ratios.append(per_blow["here"] / per_blow["base"])
            same = "yes" if digests["here"] == digests["base"] else f"no ({digests['base']} against {digests['here']})"
            print(f"| {n + 1} | {per_blow['base']:.4f} | {per_blow['here']:.4f} | {ratios[-1]:.3f} | {same} |", flush=True)
        print(f"median ratio {statistics.median(ratios):.3f} ({formulation})")


def fronts() -> None:
    sys.path.insert(0, "tests")
    import test_wave_fronts as cases  # the tests' scenes and their reference (tests/wave_reference.py)

    solution, top, foot = cases.rigid_piston_reference()
    scale, blow = cases.PISTON_Z * cases.PISTON_SPEED, 0.5 * cases.PISTON_MASS * cases.PISTON_SPEED**2
    print("| case | formulation | step | peaks (Z v_p) | tension (Z v_p) | rebound (blow) | rock energy (blow) | "
          "largest contact pull (Z v_p) |")
    print("|---|---|---|---|---|---|---|---|")
    for formulation in ("exact", "exudyn"):
        for steps in (356, 1424):
            result = cases.simulate(cases.rigid_piston_scene(formulation, steps))
            checks = cases.rod_end_checks(result, solution, scale, 1e-2 * cases.PISTON_T / steps)
            peaks = max(abs(v) for k, v in checks.items() if "compression" in k)
            tension = max(abs(v) for k, v in checks.items() if "tension" in k)
            rebound = np.max(np.abs(result.piston.rebounds[:, 1] - [e for _, e in top.rebounds])) / blow
            rock = np.max(np.abs(result.raw.waves.blow_rock_work_j - foot.blow_works(solution.states[1]))) / blow
            pull = max(-result.piston.contact_force_n.min(), 0.0) / scale
            print(f"| re-strike within a step | {formulation} | T / {steps} | {peaks:.1e} | {tension:.1e} | "
                  f"{rebound:.1e} | {rock:.1e} | {pull:.1e} |", flush=True)
    print()
    print("| stiff spring face - 8 kg bit (8e9 N/m) | preset | energy balance | stated error |")
    print("|---|---|---|---|")
    for preset in ("fast", "standard", "reference"):
        data = cases.rigid_piston_scene("exudyn", 356)
        data["drill_string"]["bodies"]["bit"] = {"mass_kg": 8.0}
        data["drill_string"]["connectors"] = {"spring": {"from": "rod", "to": "bit", "stiffness_n_per_m": 8e9}}
        data["drill_string"]["rock_body"] = "bit"
        data["solver"] = {"formulation": "exudyn", "preset": preset, "end_time_s": data["solver"]["end_time_s"]}
        result = cases.simulate(data)
        stated = {"fast": 5e-2, "standard": 3e-3, "reference": 3e-4}[preset]
        print(f"| exudyn | {preset} | {result.metrics['energy_balance_relative_error']:.1e} | {stated:g} |", flush=True)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--checks", action="store_true")
    parser.add_argument("--strings", action="store_true")
    parser.add_argument("--lumped-lundberg", action="store_true")
    parser.add_argument("--cost", action="store_true", help="CPU per blow of the shipped top-hammer wave scene")
    parser.add_argument("--repeat", type=int, default=3, help="--cost: runs per formulation (the median)")
    parser.add_argument("--base", help="--cost: against this git revision instead, in turns (--repeat rounds)")
    parser.add_argument("--formulation", choices=("exact", "exudyn"), default="exact", help="--cost --base: this one")
    parser.add_argument("--blows", type=int, default=0, help="--cost --base: the scene's first N blows (N >= 2)")
    parser.add_argument("--fronts", action="store_true", help="the model against the tests' characteristics solution")
    parser.add_argument("--fine", action="store_true", help="--strings: lumped rods refined (--segments), exact")
    parser.add_argument("--segments", type=lambda text: tuple(int(n) for n in text.split(",")), default=(16, 32, 64),
                        help="--fine: segments per rod (default 16,32,64)")
    parser.add_argument("--scenes", type=lambda text: tuple(text.split(",")),
                        default=("top_hammer_piston", "four_rod_string"), help="--fine: these scenes only")
    args = parser.parse_args(argv)
    warnings.simplefilter("ignore")  # Exudyn's printed notes
    if args.checks or not (args.strings or args.lumped_lundberg or args.cost or args.fronts):
        checks()
    if args.fronts:
        fronts()
    if args.cost and args.base:
        cost_against(args.base, args.repeat, args.formulation, args.blows)
    elif args.cost:
        cost(args.repeat)
    if args.strings:
        strings(args.fine, args.segments, args.scenes)
    if args.lumped_lundberg:
        lumped_lundberg()


if __name__ == "__main__":
    sys.exit(main())
