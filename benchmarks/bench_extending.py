"""The step a non-paper string needs (docs/extending.md): Exudyn against the ODE and the exact formulation.

Usage: python benchmarks/bench_extending.py [--parts joint,string,couplings]
Prints (joint) for the worked example of docs/extending.md (the threaded joint with play, executed
from the page as tests/test_extending.py does, on the test drill at 400 kN and 45 Hz): Exudyn rk44 at
several steps against the ODE formulation (DOP853, rtol 1e-10), the bit velocity's largest difference
relative to its range over the first blow and over two blows, and the borehole bottom after two
blows relative to max(|x_n|, F_th / k_n); (string) the penetration rate of
studies/scenes/four_rod_string.yaml with Exudyn rk44 at several steps, at the standard preset and
with the exact formulation; (couplings) the same string with compression-only couplings
(``type: coupling`` for every rod joint), Exudyn rk44 against the exact formulation.
"""

from __future__ import annotations

import os

# one BLAS thread, as in a study's workers: set before NumPy loads
for _variable in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_variable, "1")

import argparse
import re
import sys
from pathlib import Path

from rpdrill.models.definition.links import LINK_TYPES
from rpdrill.models.definition.scene import Scene
from rpdrill.models.evaluation.compare import compare_bottom_at, compare_histories
from rpdrill.models.evaluation.metrics import summary_metrics
from rpdrill.models.solvers.simulation import prepare
from rpdrill.studies.inputs.reading import parse_yaml, read_yaml

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
from scenes import scene_dict  # the frozen test drill with overrides

from rpdrill.models.runs.scene_run import run as run_simulation

DOC = ROOT / "docs" / "extending.md"
STRING = ROOT / "studies" / "scenes" / "four_rod_string.yaml"
JOINT_STEPS = (2e-5, 5e-6, 1e-6)
STRING_STEPS = (2e-5, 1e-5, 5e-6, 2.5e-6)
COUPLING_STEPS = (2e-5, 1e-5, 5e-6, 2.5e-6, 1.25e-6)


def _block(language: str, test: str) -> str:
    blocks = re.findall(rf"```{language}\n(.*?)```", DOC.read_text(), flags=re.DOTALL)
    return next(b for b in blocks if test(b))


def joint() -> None:
    source = _block("python", lambda b: "class JointWithPlay" in b)
    # as printed: without this module's `from __future__ import annotations` (ClassVar must stay a ClassVar)
    exec(compile(source, str(DOC), "exec", dont_inherit=True), {})  # noqa: S102 - registers the type
    connector = parse_yaml(_block("yaml", lambda b: b.startswith("collar_bit_joint:")), str(DOC))
    data = scene_dict(**{"impact.amplitude_n": 400e3, "impact.frequency_hz": 45.0,
                         "drill_string.connectors.collar_bit_joint": connector["collar_bit_joint"]})
    data.pop("effects", None)
    data.pop("outputs", None)
    data["metrics"] = {"transient_blows": 0, "block_blows": 2}
    blow = 1 / 45.0

    def run(solver: dict):
        return run_simulation(prepare(Scene.model_validate({**data, "solver": {"end_time_s": 0.045, **solver}}))).raw

    ode = run({"formulation": "ode", "relative_tolerance": 1e-10, "absolute_tolerance": 1e-13})
    print("joint with play: Exudyn rk44 against the ODE (DOP853, rtol 1e-10)")
    print("step [s]   bit velocity / range, 1st blow   2 blows   bottom after 2 blows (rel)")
    for step in JOINT_STEPS:
        exudyn = run({"type": "rk44", "step_s": step})
        first = compare_histories(ode, exudyn, blow)["bit_velocity_m_per_s"]["max_rel_to_range"]
        two = compare_histories(ode, exudyn, 2 * blow - 1e-4)["bit_velocity_m_per_s"]["max_rel_to_range"]
        bottom = compare_bottom_at(ode, exudyn, 2 * blow - 1e-4)["rel"]
        print(f"{step:<11g}{first:<33.2e}{two:<10.2e}{bottom:.2e}", flush=True)
    LINK_TYPES.pop("joint_with_play", None)


def rate(data: dict, solver: dict) -> float:
    scene = Scene.model_validate({**data, "solver": {**data["solver"], **solver}})
    return summary_metrics(run_simulation(prepare(scene)).raw)["penetration_rate_m_per_s"] * 1e3


def string(couplings: bool) -> None:
    data = read_yaml(STRING)
    data["solver"].pop("preset")
    if couplings:
        for name, connector in data["drill_string"]["connectors"].items():
            if name != "shock_absorber":
                connector["type"] = "coupling"
    title = "four_rod_string with compression-only couplings" if couplings else "four_rod_string"
    print(f"\n{title}: penetration rate [mm/s]")
    print(f"exact formulation   {rate(data, {'formulation': 'exact'}):.4f}", flush=True)
    if not couplings:
        print(f"standard preset     {rate(data, {'preset': 'standard'}):.4f}", flush=True)
    for step in COUPLING_STEPS if couplings else STRING_STEPS:
        print(f"rk44 at {step:<12g}{rate(data, {'type': 'rk44', 'step_s': step}):.4f}", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--parts", default="joint,string,couplings")
    parts = parser.parse_args().parts.split(",")
    if "joint" in parts:
        joint()
    if "string" in parts:
        string(couplings=False)
    if "couplings" in parts:
        string(couplings=True)


if __name__ == "__main__":
    main()
