"""The corpus of malformed inputs (tests/bad_inputs/cases.yaml): every case is rejected cleanly.

Clean: the declared exit status (2 bad input, 1 a budget exceeded or a run that diverged), one
message on standard error that names the file (the ``--out`` folder, or the command-line argument,
where that is what is wrong) and contains the declared word, no traceback, and nothing written to
``--out`` (absent before: absent after; holding something: unchanged). Each
case runs in this process through ``rpdrill.studies.cli.main.main``; they are refused before anything
heavy runs, so the corpus is fast.
"""

from __future__ import annotations

import fcntl
import json
import os
from pathlib import Path

import pytest
import yaml
from commands import main

CORPUS = Path(__file__).resolve().parent / "bad_inputs"
CASES: dict[str, dict] = yaml.safe_load((CORPUS / "cases.yaml").read_text(encoding="utf-8"))
FOLDERS = ("scenes", "studies", "calibrations", "accuracy", "sensitivity", "outputs", "cli")
# what --out holds before a run (the files of another run)
HOLDINGS = {
    "other_run": {"timeseries.csv": "time_s,bit_position_m\n0,0\n", "summary.json": "{}\n"},
    "other_study": {"study.json": json.dumps({"hash": "0" * 64, "sessions": []}), "results.csv": "point,status\n"},
    "broken_record": {"study.json": "{\"hash\": ", "checkpoint.json": "[1, 2]\n"},
    "results_only": {"results.csv": "point,status\n"},  # a study's folder whose study.json was deleted
}
LONGEST_LINE = 1000  # characters of a message line (values in it are shortened)


def prepared_out(kind: str | None, tmp: Path) -> Path:
    """The --out of a case: absent, an existing file, a path below a file, a folder of another run, a
    symbolic link to nowhere, or a folder another run holds the lock of."""
    if kind == "file":
        (tmp / "out").write_text("a file, not a folder\n")
        return tmp / "out"
    if kind == "below_file":
        (tmp / "a_file").write_text("a file\n")
        return tmp / "a_file" / "out"
    if kind == "dangling_link":
        (tmp / "out").symlink_to(tmp / "nowhere")
    if kind == "locked":  # another run writes there: it holds the lock (studies.runtime.out_lock)
        (tmp / "out").mkdir()
        lock = os.open(tmp / "out" / ".rpdrill.lock", os.O_RDWR | os.O_CREAT)
        os.write(lock, b"pid 1: rpdrill study other.yaml\n")
        fcntl.flock(lock, fcntl.LOCK_EX)
        HELD.append(lock)
    if kind in HOLDINGS:
        (tmp / "out").mkdir()
        for name, text in HOLDINGS[kind].items():
            (tmp / "out" / name).write_text(text)
    return tmp / "out"


HELD: list[int] = []  # lock files held by "another run"


@pytest.fixture(autouse=True)
def _release_locks():
    yield
    while HELD:
        os.close(HELD.pop())


def snapshot(path: Path) -> dict[str, bytes] | bytes | None:
    """What ``path`` holds (None if absent)."""
    if path.is_symlink():
        return f"link to {os.readlink(path)}".encode()
    if path.is_file():
        return path.read_bytes()
    if path.is_dir():
        return {str(p.relative_to(path)): p.read_bytes() if p.is_file() else b"" for p in sorted(path.rglob("*"))}
    return None


def command_line(path: str, case: dict, out: Path) -> list[str]:
    quiet = ["--quiet"] if case.get("quiet", True) else []  # a command with no progress has no --quiet
    return [case["command"], str(CORPUS / path), "--out", str(out), *quiet, *map(str, case.get("args", []))]


def problems(path: str, case: dict, status: int, message: str, out: Path, before: object) -> list[str]:
    """Why a finished case was not rejected cleanly (empty: clean)."""
    named = str(out) if case.get("out") in ("file", "below_file", "dangling_link", "locked", *HOLDINGS) else \
        Path(case["names"]).name if "names" in case else str(CORPUS / path)
    found = []
    if status != case["status"]:
        found.append(f"exit status {status}, expected {case['status']}")
    if "Traceback" in message or "internal error" in message:
        found.append("a traceback or an internal error")
    if str(case["word"]) not in message:
        found.append(f"no {case['word']!r} in the message")
    if named not in message:
        found.append(f"the message does not name {named}")
    if any(len(line) > LONGEST_LINE for line in message.splitlines()):
        found.append(f"a message line longer than {LONGEST_LINE} characters")
    if snapshot(out) != before and not case.get("runs"):  # (runs: a case whose points run, into --out)
        found.append(f"{out} changed")
    return found


@pytest.mark.parametrize("path", sorted(CASES))
def test_bad_input_is_rejected_cleanly(path, tmp_path, capsys):
    case = CASES[path]
    out = prepared_out(case.get("out"), tmp_path)
    before = snapshot(out)
    try:
        status = main(command_line(path, case, out))
    except SystemExit as stop:  # argparse refuses its own arguments this way
        status = stop.code
    message = capsys.readouterr().err
    assert not problems(path, case, status, message, out, before), message


def test_every_case_file_is_declared_and_every_category_is_covered():
    files = {str(p.relative_to(CORPUS)) for folder in FOLDERS for p in (CORPUS / folder).rglob("*") if p.is_file()}
    assert files <= set(CASES)
    undeclared_missing = [p for p in set(CASES) - files if os.path.isfile(CORPUS / p)]  # (a name too long: False)
    assert not undeclared_missing
    assert len(CASES) >= 100
    by_folder = {folder: sum(p.startswith(folder + "/") for p in CASES) for folder in FOLDERS}
    assert all(count > 0 for count in by_folder.values()), by_folder
