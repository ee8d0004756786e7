"""The checkpoint of a search (``rpdrill calibrate``, ``rpdrill advise``): every evaluation as one
JSON line, as soon as it finishes.

``OUT/evaluations.jsonl`` holds the evaluations (what the search's own records hold: a point, what
was measured there); ``OUT/checkpoint.json`` the hash of everything that determines them (the
search's inputs) and one entry per session. A rerun into the same OUT replays the recorded
evaluations (by their exact point) instead of recomputing them, so a seeded search retraces its path
and continues where it stopped; a different search is refused (InputError; with ``overwrite`` it
starts afresh). A line cut by a kill is dropped.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Generic, TextIO, TypeVar

from pydantic import BaseModel, ValidationError

from ...models.definition.validation import InputError
from .output_files import json_text, write_atomic, write_json
from .resumable import checked_record

RecordT = TypeVar("RecordT", bound=BaseModel)  # a search's typed evaluation (calibration, advice)
EVALUATIONS = "evaluations.jsonl"
CHECKPOINT = "checkpoint.json"


def unit_key(unit: Any) -> tuple[float, ...]:
    """The memo key of a unit point: its exact coordinates."""
    return tuple(float(u) for u in unit)


def _not_json(constant: str) -> None:
    raise json.JSONDecodeError(f"{constant} is not JSON", constant, 0)


def _complete_records(path: Path, kind: type[RecordT]) -> list[RecordT]:
    """The records of whole lines as ``kind`` (a last line cut by a kill is left out); InputError naming the
    file and line when a whole line is not such a record."""
    records = []
    try:
        lines = path.read_text(encoding="utf-8").splitlines(keepends=True) if path.exists() else []
    except UnicodeDecodeError:
        raise InputError(f"--out: {path}: not evaluations rpdrill wrote (not UTF-8 text)") from None
    for number, line in enumerate(lines, 1):
        try:  # (rpdrill writes null for a number that is not finite: a NaN or Infinity was edited in)
            records.append(kind.model_validate(json.loads(line, parse_constant=_not_json)))
        except (json.JSONDecodeError, ValidationError):
            if line.endswith("\n"):
                raise InputError(f"--out: {path}: line {number} is not an evaluation rpdrill wrote") from None
    return records


class EvaluationLog(Generic[RecordT]):
    """The recorded evaluations (of type ``kind``) of one search in one output directory (close it when
    done): ``identity`` names the search and holds its ``hash``; ``source`` is the input file messages name."""

    def __init__(self, out: Path, identity: dict[str, Any], source: Path, kind: type[RecordT],
                 overwrite: bool = False) -> None:
        self.out = out
        self.checkpoint, resumed = self._checkpoint(identity, source, overwrite)
        path = out / EVALUATIONS
        self.records: list[RecordT] = _complete_records(path, kind) if resumed else []
        write_atomic(path, "".join(json_text(r) + "\n" for r in self.records))
        self._handle: TextIO = path.open("a", encoding="utf-8")

    def _checkpoint(self, identity: dict[str, Any], source: Path, overwrite: bool) -> tuple[dict[str, Any], bool]:
        """The checkpoint (this search's, or a fresh one) and whether it resumes an earlier run."""
        self.out.mkdir(parents=True, exist_ok=True)
        fresh = {**identity, "sessions": []}
        checkpoint = checked_record(self.out / CHECKPOINT, fresh, source, [self.out / EVALUATIONS], overwrite)
        write_json(self.out / CHECKPOINT, checkpoint)
        return checkpoint, checkpoint is not fresh

    def append(self, record: RecordT) -> None:
        """Record an evaluation now (one line, flushed)."""
        self._handle.write(json_text(record) + "\n")
        self._handle.flush()
        self.records.append(record)

    def add_session(self, session: dict[str, Any]) -> None:
        self.checkpoint["sessions"].append(session)
        write_json(self.out / CHECKPOINT, self.checkpoint)

    def close(self) -> None:
        self._handle.close()
