"""The commands the documentation names beside its numbers still run as written: every ``python -c "..."`` of
docs/*.md (a block, or inline in the prose, as the page shows it) is valid Python and finds every name it
imports from rpdrill, and every benchmark script imports. (Two had drifted: docs/model.md's start snippet and
benchmarks/bench_exact.py called methods that are gone, found when their numbers were rerun; what the commands
do beyond their imports runs where their numbers are rerun.)"""

import ast
import importlib
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
INLINE = re.compile(r'`python -c "(.*?)"`', re.DOTALL)  # in the prose: a wrapped line reads as a space
BLOCK = re.compile(r'^( {4,})python -c "\n?(.*?)"$', re.DOTALL | re.MULTILINE)  # indented, as a code block


def commands() -> list[tuple[str, str]]:
    """(page:line, code) of every ``python -c`` command of docs/*.md, the code as a copy from the page gives it."""
    found = []
    for page in sorted((ROOT / "docs").glob("*.md")):
        text = page.read_text(encoding="utf-8")
        for match in INLINE.finditer(text):
            code = re.sub(r"\s*\n\s*", " ", match.group(1))  # as the page shows it
            found.append((f"{page.name}:{text.count(chr(10), 0, match.start()) + 1}", code))
        for match in BLOCK.finditer(text):
            indent = match.group(1)
            code = "\n".join(line.removeprefix(indent) for line in match.group(2).split("\n"))
            found.append((f"{page.name}:{text.count(chr(10), 0, match.start()) + 1}", code))
    return found


COMMANDS = commands()


def test_the_pages_name_their_commands():
    pages = {where.split(":")[0] for where, _ in COMMANDS}
    assert {"crosscheck.md", "model.md", "stability.md", "top_hammer.md"} <= pages


@pytest.mark.parametrize("where, code", COMMANDS, ids=[where for where, _ in COMMANDS])
def test_a_documented_command_is_python_and_finds_what_it_imports(where, code):
    tree = ast.parse(code, filename=where)  # a SyntaxError names the page and line
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("rpdrill"):
            module = importlib.import_module(node.module)
            missing = [alias.name for alias in node.names if not hasattr(module, alias.name)]
            assert not missing, f"{where}: {node.module} has no {missing}"
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.startswith("rpdrill"):
                    importlib.import_module(alias.name)


@pytest.mark.slow
def test_every_benchmark_imports():
    """In a process of its own: a benchmark sets BLAS's thread count before NumPy loads, as it runs."""
    names = sorted(path.stem for path in (ROOT / "benchmarks").glob("bench_*.py"))
    code = f"import sys; sys.path.insert(0, {str(ROOT / 'benchmarks')!r})\nfor name in {names!r}: __import__(name)"
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=300,
                          check=False)
    assert done.returncode == 0, done.stderr[-2000:]
