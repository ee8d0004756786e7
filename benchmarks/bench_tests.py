"""Where the test suite's CPU goes: every test's CPU seconds, its own and its subprocesses'.

Usage: python benchmarks/bench_tests.py [--save CSV] [PYTEST ARGS ...]   (default: the whole suite, as the README runs it)
Runs ``python -m pytest -q -p bench_tests PYTEST ARGS`` from the checkout with this file as a pytest plugin
(loaded by every xdist worker too): each test's ``time.process_time()`` of the process that ran it plus
``resource.getrusage(RUSAGE_CHILDREN)`` (the subprocesses and pool workers it waited for), setup and
teardown included. Prints each pytest worker's busy seconds and when its last test ended (a suite whose workers end
together is CPU-bound), the 40 costliest tests, the CPU per test file and the total; ``--save CSV`` writes every
test's row (cpu_s, own_s, children_s, wall_s, test).
"""

from __future__ import annotations

import os
import resource
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
RECORDS = "RPDRILL_BENCH_TESTS_DIR"


def _cpu_s() -> tuple[float, float]:
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return time.process_time(), children.ru_utime + children.ru_stime


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item: pytest.Item, nextitem: pytest.Item | None):
    """Record ``item``'s CPU seconds (own, children), wall seconds and end (epoch seconds) to this process's file."""
    own, children, wall = *_cpu_s(), time.monotonic()
    yield
    own_after, children_after = _cpu_s()
    folder = os.environ.get(RECORDS)
    if folder:
        with open(Path(folder) / f"{os.getpid()}.txt", "a", encoding="utf-8") as handle:
            handle.write(f"{own_after - own:.3f} {children_after - children:.3f} {time.monotonic() - wall:.3f} "
                         f"{time.time():.3f} {item.nodeid}\n")


def main(arguments: list[str]) -> int:
    save = None
    if arguments[:1] == ["--save"]:
        save, arguments = Path(arguments[1]), arguments[2:]
    with tempfile.TemporaryDirectory() as folder:
        env = {**os.environ, RECORDS: folder,
               "PYTHONPATH": os.pathsep.join(filter(None, [str(Path(__file__).parent), os.environ.get("PYTHONPATH")]))}
        status = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "bench_tests", *arguments], cwd=ROOT,
                                env=env, check=False).returncode
        files = {path.stem: path.read_text().splitlines() for path in Path(folder).glob("*.txt")}
    rows = [line.split(" ", 4) for lines in files.values() for line in lines]
    tests = sorted(((float(own) + float(children), float(own), float(children), node.split("@")[0], float(wall))
                    for own, children, wall, _, node in rows), reverse=True)
    first = min(float(end) - float(wall) for _, _, wall, end, _ in rows)
    for pid, lines in sorted(files.items()):  # each pytest worker: how long its tests ran, and its last one's end
        busy = sum(float(line.split(" ", 4)[2]) for line in lines)
        last = max(float(line.split(" ", 4)[3]) for line in lines) - first
        print(f"worker process {pid}: {len(lines)} tests, {busy:.1f} s of tests, the last ended {last:.1f} s "
              "after the first began")
    if save is not None:
        save.write_text("cpu_s,own_s,children_s,wall_s,test\n" + "".join(
            f"{total:.3f},{own:.3f},{children:.3f},{wall:.3f},{node}\n" for total, own, children, node, wall in tests))
    print(f"\n{'CPU s':>8} {'own':>8} {'children':>8}  test")
    for total, own, children, node, _ in tests[:40]:
        print(f"{total:8.2f} {own:8.2f} {children:8.2f}  {node}")
    files: dict[str, float] = defaultdict(float)
    for total, _, _, node, _ in tests:
        files[node.split("::")[0]] += total
    print(f"\n{'CPU s':>8}  file")
    for name, total in sorted(files.items(), key=lambda item: -item[1]):
        print(f"{total:8.2f}  {name}")
    print(f"\n{len(tests)} tests, {sum(t[0] for t in tests):.1f} CPU s in the tests (collection and worker start aside)")
    return status


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
