"""The strict YAML reader's cost (studies.inputs.strict_yaml, on ruamel.yaml's pure-Python reader).

Usage: python benchmarks/bench_reader.py [--repeats 7]
Prints the median CPU time to read every shipped input (studies/**/*.yaml), the first time and again (a
text's parse is kept for its next read: the second read is a copy), and what the reader's limits cost: a file beyond MAX_FILE_BYTES (refused by its size before it is read), a list of more
than MAX_VALUES values (refused while it is composed), aliases that expand beyond MAX_VALUES, and a
file of MAX_VALUES plain values that is read (the most an input may hold).
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

from rpdrill.studies.inputs.reading import MAX_FILE_BYTES, MAX_VALUES, InputError, parse_yaml, read_yaml
from rpdrill.studies.inputs.strict_yaml import _kept_document

ROOT = Path(__file__).resolve().parents[1]


def cpu_s(action: Callable[[], object], repeats: int, kept: bool = False) -> float:
    """Median CPU seconds of ``action`` (an InputError is the outcome measured, not a failure); the kept parses
    dropped before each repeat unless ``kept``."""
    times = []
    for _ in range(repeats):
        if not kept:
            _kept_document.cache_clear()
        start = time.process_time()
        try:
            action()
        except InputError:
            pass
        times.append(time.process_time() - start)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args()
    inputs = [(str(p), p.read_text(encoding="utf-8")) for p in sorted((ROOT / "studies").rglob("*.yaml"))]
    shipped = cpu_s(lambda: [parse_yaml(text, name) for name, text in inputs], args.repeats)
    print(f"{len(inputs)} shipped inputs: {shipped * 1e3:.1f} ms CPU ({shipped / len(inputs) * 1e3:.1f} ms a file)")
    again = cpu_s(lambda: [parse_yaml(text, name) for name, text in inputs], args.repeats, kept=True)
    print(f"the same read again (their parses kept): {again * 1e3:.1f} ms CPU ({again / len(inputs) * 1e3:.2f} ms a file)")
    with tempfile.TemporaryDirectory() as folder:
        big = Path(folder) / "big.yaml"
        big.write_bytes(b"name: big\n" + b"# padding\n" * (MAX_FILE_BYTES // 10 * 10))
        print(f"a file of {big.stat().st_size} bytes, refused by its size: {cpu_s(lambda: read_yaml(big), 3) * 1e3:.2f} ms")
    many = "values: [" + ", ".join(["0"] * (25 * MAX_VALUES)) + "]\n"
    print(f"a list of {25 * MAX_VALUES} values, refused while read: {cpu_s(lambda: parse_yaml(many, 'many'), 3):.2f} s")
    laughs = "l0: &l0 [a]\n" + "".join(f"l{i}: &l{i} [{', '.join([f'*l{i - 1}'] * 10)}]\n" for i in range(1, 9))
    print(f"aliases expanding to 1e8 values, refused: {cpu_s(lambda: parse_yaml(laughs, 'laughs'), 3) * 1e3:.1f} ms")
    most = "values: [" + ", ".join(["0"] * (MAX_VALUES - 10)) + "]\n"
    print(f"{MAX_VALUES - 10} values, read: {cpu_s(lambda: parse_yaml(most, 'most'), 3):.2f} s")


if __name__ == "__main__":
    main()
