"""The Python examples of the site's pages, run when the site is built (a Sphinx extension of docs/conf.py).

Every ```` ```python ```` block of a page named in ``page_examples`` (conf.py: a page's name without its
``.md`` -> the texts that mark a block not run alone, such as a class the page's test defines) runs as printed
from the root of the checkout, the page's blocks one after the other in one new Python process: each as
``python -c`` would run it (its own ``__main__`` namespace: a name a block does not import or define is a
NameError), each one's output and failure kept apart. One interpreter start and one import of the libraries per page, not one per block (docs/api.md:
55 CPU s in 18 processes, 31 in one). Running them in sequence in one process also checks what docs/api.md
promises: a call leaves the caller's process as it was, so the next block runs as it would alone.

A block that raises, or whose output holds a traceback (a worker's, printed by a library), is a warning at its
line of its page: the strict build (``sphinx-build -W``, .ci/run) fails on it. The pages' examples run here, in
the documentation's build, not in the test suite: they document calls that the tests check through the public
API (a block is documentation, not a physics check); the build runs them every time, in CI too.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

PYTHON_BLOCK = re.compile(r"^```python\n(.*?)^```", re.DOTALL | re.MULTILINE)

# Runs in the child: each block with its stdout and stderr (file descriptors 1 and 2, so that what its
# worker processes and Exudyn print is kept too) in a file of its own, its traceback when it raised.
_RUNNER = r"""
import json, os, sys, traceback

examples, folder = json.load(open(sys.argv[1])), sys.argv[2]
for i, code in enumerate(examples):
    sys.stdout.flush(); sys.stderr.flush()
    saved = os.dup(1), os.dup(2)
    with open(os.path.join(folder, f"{i}.out"), "w") as out, open(os.path.join(folder, f"{i}.err"), "w") as err:
        os.dup2(out.fileno(), 1); os.dup2(err.fileno(), 2)
        failed = False
        try:
            exec(compile(code, "<string>", "exec"), {"__name__": "__main__", "__builtins__": __builtins__})
        except BaseException:
            failed = True
            traceback.print_exc()
        finally:
            sys.stdout.flush(); sys.stderr.flush()
            os.dup2(saved[0], 1); os.dup2(saved[1], 2)
            os.close(saved[0]); os.close(saved[1])
    open(os.path.join(folder, f"{i}.status"), "w").write("1" if failed else "0")
"""


@dataclass
class Ran:
    """What one block did: ``failed`` (it raised, or it never ran), its stdout and its stderr."""

    failed: bool
    out: str
    err: str

    @property
    def problem(self) -> str:
        """Why the block does not run as printed ("" when it does): its traceback, or a traceback it printed."""
        return self.err if self.failed or "Traceback" in self.err else ""


@dataclass(frozen=True)
class Block:
    """A Python block of a page: its code and the line of the page its code starts on."""

    code: str
    line: int


def page_blocks(text: str, skip: tuple[str, ...] = ()) -> list[Block]:
    """The ```` ```python ```` blocks of a page's Markdown ``text``, but those holding a text of ``skip``."""
    return [Block(match.group(1), text.count("\n", 0, match.start(1)) + 1) for match in PYTHON_BLOCK.finditer(text)
            if not any(marker in match.group(1) for marker in skip)]


def run_examples(examples: list[str], cwd: Path, timeout_s: float = 1800) -> list[Ran]:
    """Every example of ``examples`` run in order in one new Python process from ``cwd``."""
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder)
        (path / "examples.json").write_text(json.dumps(examples), encoding="utf-8")
        done = subprocess.run([sys.executable, "-c", _RUNNER, str(path / "examples.json"), folder], cwd=cwd,
                              capture_output=True, text=True, check=False, timeout=timeout_s)
        ran = []
        for i in range(len(examples)):
            status = path / f"{i}.status"
            if not status.exists():  # the process died in or before this example
                ran.append(Ran(True, "", f"example {i} did not finish: the process ended ({done.returncode}): "
                                         f"{done.stderr}"))
                continue
            ran.append(Ran(status.read_text() == "1", (path / f"{i}.out").read_text(encoding="utf-8"),
                           (path / f"{i}.err").read_text(encoding="utf-8")))
        return ran


def page_problems(source: Path, pages: dict[str, tuple[str, ...]]) -> list[tuple[str, int, str]]:
    """(page, line, problem) of every block of ``pages`` (a page's name without ``.md`` in the folder ``source``
    -> the texts that mark a block not run alone) that does not run as printed from ``source``'s parent."""
    problems = []
    for page, skip in pages.items():
        blocks = page_blocks((source / f"{page}.md").read_text(encoding="utf-8"), tuple(skip))
        ran = run_examples([block.code for block in blocks], source.parent)
        problems += [(page, block.line, done.problem) for block, done in zip(blocks, ran, strict=True) if done.problem]
    return problems


def _run_pages(app) -> None:
    """Sphinx ``builder-inited``: every page of ``page_examples`` run; a block that fails, a warning at its line."""
    from sphinx.util import logging

    logger = logging.getLogger(__name__)
    logger.info(f"page_examples: running the Python blocks of {', '.join(app.config.page_examples)}")
    for page, line, problem in page_problems(Path(app.srcdir), app.config.page_examples):
        logger.warning(f"this Python block does not run as printed (from the root of the checkout):\n{problem}",
                       location=(page, line))


def setup(app) -> dict[str, bool]:
    app.add_config_value("page_examples", {}, "env")
    app.connect("builder-inited", _run_pages)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
