"""What a run's figures cost: the files ``rpdrill simulate`` writes and its ``--animate`` movie.

Usage: python benchmarks/bench_figures.py [--base REV] [--repeats 5]
In a fresh process (rpdrill from this checkout, or from REV too): one exact run of paper_base (0.4 s of drill),
then, each the median CPU of ``--repeats`` after one warm-up and with the figure draws counted
(``matplotlib.figure.Figure.draw``): the timeseries figure (PNG and SVG), the drawing of the drill, and the
animation of the run's last blow (20 frames) and of its Exudyn model (every item drawn from its graphics).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

# In the fresh process: each figure timed and its draws counted.
FIGURES = """
import statistics, sys, tempfile, time
from pathlib import Path
from matplotlib.figure import Figure
import rpdrill
from rpdrill.studies.drawings.drill_animation import write_animation
from rpdrill.studies.figures.timeseries_figure import plot_timeseries

draws = [0]
plain_draw = Figure.draw
def counted(self, renderer):
    draws[0] += 1
    return plain_draw(self, renderer)
Figure.draw = counted
scene = rpdrill.load_scene("paper_base").with_({"solver.end_time_s": 0.4, "metrics.transient_blows": 5,
                                                "metrics.block_blows": 5})
result = rpdrill.simulate(scene, formulation="exact")
columns = {name: values.to_numpy() for name, values in result.timeseries.items()}
model = rpdrill.build_exudyn(scene.with_({"solver.end_time_s": 0.1, "metrics.transient_blows": 1,
                                          "metrics.block_blows": 1}))
model.write_solution(Path(tempfile.mkdtemp()) / "solution.txt")
model.run()
print(rpdrill.__file__)
with tempfile.TemporaryDirectory() as folder:
    out = Path(folder)
    for name, draw in [("timeseries figure, PNG and SVG", lambda: plot_timeseries(columns, scene, out / "t.png")),
                       ("drawing of the drill", lambda: rpdrill.draw(scene, out / "drill.png")),
                       ("animation of a run, 20 frames", lambda: write_animation(result.raw, out / "a.gif", blows=1)),
                       ("animation of its Exudyn model, 20 frames", lambda: write_animation(model, out / "m.gif",
                                                                                            blows=1))]:
        draw()
        times, counts = [], []
        for _ in range(REPEATS):
            draws[0], start = 0, time.process_time()
            draw()
            times.append(time.process_time() - start)
            counts.append(draws[0])
        print(f"| {name} | {statistics.median(times):.3f} | {max(counts)} |")
"""


def figures(tree: Path, repeats: int) -> None:
    """The table's rows with rpdrill imported from ``tree``."""
    env = {**os.environ, "PYTHONPATH": str(tree)}
    out = subprocess.run([sys.executable, "-c", FIGURES.replace("REPEATS", str(repeats))], env=env, cwd=tree,
                         check=True, capture_output=True, text=True).stdout.splitlines()
    if not out[0].startswith(str(tree)):
        raise SystemExit(f"rpdrill imported from {out[0]}, not from {tree}")
    print("\n".join(out[1:]), flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--base", help="also at this git revision")
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    print("| figure | CPU s (median) | figure draws |")
    print("|---|---|---|")
    sys.path.insert(0, str(Path(__file__).parent))
    from bench_same_results import at_base_and_here

    at_base_and_here(args.base, lambda tree: figures(tree, args.repeats), 3)


if __name__ == "__main__":
    main()
