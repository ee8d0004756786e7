"""Results tables: typed pandas DataFrames in memory, CSV text on disk, and the one reader between them.

A table's file is CSV: a header of column names (units in the names), then one row per point, each
cell the text of its value (a number as Python writes it, or in its column's format, e.g. a wall time
to 4 significant digits; an empty cell for a value the point does not have, a failed point's metrics,
and for a number that is not finite, its status says why: models.evaluation.run_status). :func:`read_table` reads a file back into the typed table and :func:`typed` gives text cells
their types: numbers as numbers, text (status, error, a rock's name) as text. Nothing else in rpdrill
reads a number from text.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any

from ..inputs.reading import InputError
from .output_files import atomic_file

if TYPE_CHECKING:
    import pandas as pd

TEXT_COLUMNS = ("status", "error", "steady_state", "regime")  # text even where every cell reads as a number or is empty
NOT_A_NUMBER = ("nan", "+nan", "-nan")


def cell_text(value: Any, number_format: str | None = None, finite: bool = True) -> str:
    """A cell's text: nothing for None (and, ``finite``, for a float that is not finite), a float in
    ``number_format`` when given, anything else as ``str`` gives it (a float's shortest text that reads
    back to it; 'nan' for NaN when not ``finite``)."""
    if value is None or (finite and isinstance(value, float) and not math.isfinite(value)):
        return ""
    if number_format is not None and isinstance(value, float):
        return format(value, number_format)
    return str(value)


def text_row(row: Mapping[str, Any], columns: Sequence[str], formats: Mapping[str, str],
             finite: bool = True) -> list[str]:
    """A row's cells under ``columns`` (a column the row does not have: empty); ValueError for a value
    of a column the table does not have (it would be lost)."""
    extra = [name for name in row if name not in columns]
    if extra:
        raise ValueError(f"columns {', '.join(extra)} are not columns of the table ({', '.join(columns)})")
    return [cell_text(row.get(name), formats.get(name), finite) for name in columns]


def write_rows(handle: IO[str], columns: Sequence[str], rows: Sequence[Mapping[str, Any]], formats: Mapping[str, str],
               header: bool = False, finite: bool = True) -> None:
    """Rows (column name -> value) as CSV into an open file, the header first when asked."""
    writer = csv.writer(handle)
    if header:
        writer.writerow(columns)
    writer.writerows(text_row(row, columns, formats, finite) for row in rows)


def append_rows(path: Path, columns: Sequence[str], rows: Sequence[Mapping[str, Any]],
                formats: Mapping[str, str]) -> None:
    """Append rows to a results table's file (its header already there), flushed at once."""
    with path.open("a", newline="", encoding="utf-8") as handle:
        write_rows(handle, columns, rows, formats)


def write_table(path: Path, table: pd.DataFrame, formats: Mapping[str, str] | None = None) -> None:
    """A table (an analysis of a results table) as its file, whole or not at all: its columns, a row per
    row, numbers in their column's ``formats`` (else the shortest text that reads back to them, 'nan' for
    NaN: a figure of the analysis, not a point's missing value)."""
    with atomic_file(path) as handle:
        write_rows(handle, [str(name) for name in table.columns], table.to_dict("records"), formats or {},
                   header=True, finite=False)


def read_text(path: Path) -> tuple[list[str], list[tuple[int, list[str]]]]:
    """The header and the whole rows (line number, cells) of a table's file; a last line cut by a kill is
    left out. InputError when the file is not CSV text."""
    try:
        text = path.read_text(encoding="utf-8") if path.exists() else ""
        lines = list(csv.reader(io.StringIO(text[: text.rfind("\n") + 1], newline="")))
    except (UnicodeDecodeError, csv.Error, OSError) as error:
        why = error.strerror if isinstance(error, OSError) and error.strerror else error
        raise InputError(f"--out: {path}: not a results table rpdrill wrote ({why}); use a new --out directory") \
            from None
    if not lines:
        return [], []
    return lines[0], list(enumerate(lines[1:], 2))


def is_finite(text: str) -> bool:
    """Whether a cell's text is a finite number."""
    try:
        return math.isfinite(float(text))
    except ValueError:
        return False


def typed(frame: pd.DataFrame, text: Sequence[str] = ()) -> pd.DataFrame:
    """A table of text cells typed: a column whose every non-empty cell is a number becomes numbers
    (empty cells NaN), one whose every cell is ``True`` or ``False`` (as Python writes a bool) booleans, the
    others stay text; status, error and the ``text`` columns are text."""
    import pandas as pd  # 0.3 s to import: only where a table is asked for

    frame = frame.copy()
    for column in frame.columns:
        if column in TEXT_COLUMNS or column in text or frame[column].dtype != object:
            continue
        cells = frame[column].astype(str)
        if len(cells) and cells.isin(("True", "False")).all():
            frame[column] = cells == "True"
            continue
        numbers = pd.to_numeric(cells, errors="coerce")
        number = numbers.notna() | cells.str.strip().str.lower().isin(NOT_A_NUMBER)
        if number.sum() == cells.ne("").sum():
            frame[column] = numbers
    return frame


def table_of(header: Sequence[str], rows: Sequence[Sequence[str]], text: Sequence[str] = ()) -> pd.DataFrame:
    """Text rows under ``header`` as the typed table (:func:`typed`), in point order and indexed by the
    point where the table has one."""
    import pandas as pd

    frame = typed(pd.DataFrame(list(rows), columns=list(header), dtype=object), text)
    if "point" in frame.columns and not frame.empty:
        frame = frame.sort_values("point", kind="stable").set_index("point", drop=False)
        frame.index.name = None
    return frame


def read_table(path: str | Path, text: Sequence[str] = ()) -> pd.DataFrame:
    """A table's file (a results.csv rpdrill wrote) as the typed table (:func:`table_of`; ``text``: columns
    that hold text even where they read as numbers, or are empty)."""
    header, rows = read_text(Path(path))
    return table_of(header, [cells for _, cells in rows if len(cells) == len(header)], text)
