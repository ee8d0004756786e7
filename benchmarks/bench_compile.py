"""What numba's compilation costs a process on an empty cache: a fresh install's first runs, and a fresh clone's test
processes, each compile the kernels they call before the cache holds them.

Usage: python benchmarks/bench_compile.py [--base REV]
Three first calls, each alone in a fresh process with an empty numba cache (``NUMBA_CACHE_DIR``): an exact run of
paper_base, its periodic orbit (its time run's kernels and the monodromy kernel), an exact run of the shipped
top-hammer wave scene. Prints
each call's process CPU and every kernel's compile time over 0.1 s (numba's ``numba:compile`` events; a kernel's
time includes what it compiles inside it). ``--base REV``: the same at that git revision too, for a change's before.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

CALLS = {
    "exact run": 'rpdrill.simulate(paper, formulation="exact", budget=None)',
    "periodic orbit": 'rpdrill.simulate(paper.with_({"solver.steady_state": "periodic"}), formulation="exact", '
                      'budget=None)',
    "wave run": 'rpdrill.simulate(rpdrill.load_scene("top_hammer_waves").with_({"solver.end_time_s": 0.04, '
                '**short}), formulation="exact", budget=None)',
}

# In the fresh process: one call, timed.
FIRST_CALL = """
import sys, time
from numba.core import event
import rpdrill
compiled = []
class Timer(event.Listener):
    started = {{}}
    def on_start(self, e):
        self.started[id(e.data["dispatcher"])] = time.perf_counter()
    def on_end(self, e):
        compiled.append((time.perf_counter() - self.started[id(e.data["dispatcher"])],
                         e.data["dispatcher"].py_func.__qualname__))
short = {{"metrics.transient_blows": 1, "metrics.block_blows": 1}}
paper = rpdrill.load_scene("paper_base").with_({{"solver.end_time_s": 0.05, **short}})
event.register("numba:compile", Timer())
start = time.process_time()
{call}
print(rpdrill.__file__)
print(time.process_time() - start)
for seconds, name in compiled:
    if seconds > 0.1:
        print(f"{{seconds:.2f}} {{name}}")
"""


def first_calls(tree: Path, cwd: Path) -> None:
    """Each call of CALLS timed alone in a fresh process on an empty cache, rpdrill imported from ``tree``."""
    for name, call in CALLS.items():
        with tempfile.TemporaryDirectory() as cache:
            code = FIRST_CALL.format(call=call)
            env = {**os.environ, "PYTHONPATH": str(tree), "NUMBA_CACHE_DIR": cache}
            out = subprocess.run([sys.executable, "-c", code], env=env, cwd=cwd, check=True, capture_output=True,
                                 text=True).stdout.splitlines()
        if not out[0].startswith(str(tree)):
            raise SystemExit(f"rpdrill imported from {out[0]}, not from {tree}")
        kernels = ", ".join(f"{line.split()[1]} {line.split()[0]} s" for line in out[2:])
        print(f"| {name} | {float(out[1]):.2f} | {kernels} |", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--base", help="also at this git revision")
    args = parser.parse_args()
    print("| first call (empty cache) | CPU s | kernels compiled (over 0.1 s) |")
    print("|---|---|---|")
    sys.path.insert(0, str(Path(__file__).parent))
    from bench_same_results import at_base_and_here

    at_base_and_here(args.base, lambda tree: first_calls(tree, tree / "rpdrill" if tree != ROOT else ROOT), 3)


if __name__ == "__main__":
    main()
