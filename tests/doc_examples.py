"""A page's Python examples run one after the other in one fresh process, each as ``python -c`` would run
it (its own ``__main__`` namespace, from the root of the checkout), each one's output and failure kept
apart: one interpreter start and one import of the libraries for the page, not one per example (the 18
examples of docs/api.md: 55 CPU s in 18 processes, 31 in one). Each example still starts from nothing of
the others (a fresh namespace: a name an example does not import or define is a NameError), and running
them in sequence in one process also checks what docs/api.md promises: a call leaves the caller's process
as it was, so the next example runs as it would alone."""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

# Runs in the child: each example with its stdout and stderr (file descriptors 1 and 2, so that what its
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
    """What one example did: ``failed`` (it raised, or it never ran), its stdout and its stderr."""

    failed: bool
    out: str
    err: str


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
