"""The figures and numbers of docs/steady_state.md: the bifurcation diagrams of the paper's drill and of the
test drill's period doubling.

    python docs/steady_state_figures.py      # writes docs/steady_state/*.png (and .svg), prints the numbers

Each diagram: studies.scan.bifurcation_diagram (exact formulation, 200-blow time runs for the brute force),
drawn by studies.figures.bifurcation_figure.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

import rpdrill
from rpdrill.studies.figures.bifurcation_figure import plot_bifurcation
from rpdrill.studies.scan.bifurcation_diagram import bifurcation_data

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "steady_state"
PAPER = ROOT / "studies" / "scenes" / "paper_base.yaml"
sys.path.insert(0, str(ROOT / "tests"))


def diagram(name: str, scene: rpdrill.Scene, axis: str, values: list[float], title: str) -> None:
    start = time.process_time()
    data = bifurcation_data(scene, axis, values)
    cpu = time.process_time() - start
    plot_bifurcation(data, OUT / f"{name}.png", title)
    regimes = {}
    for figure in data.up:
        regimes[figure.regime] = regimes.get(figure.regime, 0) + 1
    unstable = [f.value for f in data.period_one if not f.stable]
    spread = max(np.ptp(f.advance_m) / max(np.mean(f.advance_m), 1e-30) for f in data.brute_force)
    print(f"{name}: {len(values)} values of {axis}, regimes up the axis {regimes}; period-1 orbit followed over "
          f"{len(data.period_one)} values, unstable at {unstable or 'none'}; largest spread of the brute force's "
          f"last 40 blows (max - min over mean advance) {spread:.3g}; {cpu:.1f} CPU s")


def main() -> None:
    OUT.mkdir(exist_ok=True)
    paper = rpdrill.load_scene(PAPER)
    frequencies = [float(f) for f in range(10, 121)]
    diagram("paper_frequency", paper, "impact.frequency_hz", frequencies,
            "paper_base (exact), 220 kN: the paper's frequency scan, every 1 Hz")
    for amplitude in (120e3, 160e3, 280e3):
        diagram(f"paper_frequency_{amplitude / 1e3:.0f}kN", paper.with_({"impact.amplitude_n": amplitude}),
                "impact.frequency_hz", frequencies, f"paper_base (exact), {amplitude / 1e3:.0f} kN: the impulse scan")
    diagram("paper_impulse_65Hz", paper, "impact.amplitude_n", [float(a) for a in np.arange(100e3, 300.1e3, 5e3)],
            "paper_base (exact) at 65 Hz: impact amplitude")
    from scenes import scene  # the frozen test drill (tests/test_drill.yaml)

    test_drill = scene().with_solver("exact").with_({"impact.amplitude_n": 400e3, "solver.end_time_s": 1.5,
                                                     "drill_string.connectors.shock_absorber.damping_n_s_per_m": 2e3})
    diagram("test_drill_period_doubling", test_drill, "impact.frequency_hz",
            [float(f) for f in np.arange(24.0, 36.01, 0.25)],
            "tests/test_drill.yaml, 400 kN, shock absorber 2 kN s/m: the test's period doubling at 28 Hz")


if __name__ == "__main__":
    main()
