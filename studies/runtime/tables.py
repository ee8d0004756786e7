"""Results tables: typed pandas DataFrames in memory, CSV text on disk, and the one reader between them.

A table's file is CSV: a header of column names (units in the names), then one row per point, each
cell the text of its value (a number as Python writes it, or in its column's format, e.g. a wall time
to 4 significant digits; an empty cell for a value the point does not have: a failed point's
metrics). :func:`read_table` reads a file back into the typed table and :func:`typed` gives text cells
their types: numbers as numbers, text (status, error, a rock's name) as text. Nothing else in rpdrill
reads a number from text.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..inputs.reading import InputError

if TYPE_CHECKING:
    import pandas as pd

TEXT_COLUMNS = ("status", "error")  # text even where every cell reads as a number
NOT_A_NUMBER = ("nan", "+nan", "-nan")


def cell_text(value: Any, number_format: str | None = None) -> str:
    """A cell's text: nothing for None, a float in ``number_format`` when given, anything else as
    ``str`` gives it (a float's shortest text that reads back to it, 'nan' for NaN)."""
    if value is None:
        return ""
    if number_format is not None and isinstance(value, float):
        return format(value, number_format)
    return str(value)


def text_row(row: Mapping[str, Any], columns: Sequence[str], formats: Mapping[str, str]) -> list[str]:
    """A row's cells under ``columns`` (a column the row does not have: empty); ValueError for a value
    of a column the table does not have (it would be lost)."""
    extra = [name for name in row if name not in columns]
    if extra:
        raise ValueError(f"columns {', '.join(extra)} are not columns of the table ({', '.join(columns)})")
    return [cell_text(row.get(name), formats.get(name)) for name in columns]


def write_header(path: Path, columns: Sequence[str]) -> None:
    with path.open("w", newline="", encoding="utf-8") as handle:
        csv.writer(handle).writerow(columns)


def append_rows(path: Path, columns: Sequence[str], rows: Sequence[Mapping[str, Any]],
                formats: Mapping[str, str]) -> None:
    """Append rows (column name -> value) to a table's file, flushed at once."""
    with path.open("a", newline="", encoding="utf-8") as handle:
        csv.writer(handle).writerows(text_row(row, columns, formats) for row in rows)


def write_table(path: Path, table: pd.DataFrame, formats: Mapping[str, str] | None = None) -> None:
    """A table (e.g. an analysis of a results table) as its file: its columns, a row per row, numbers in
    their column's ``formats`` (else the shortest text that reads back to them, 'nan' for NaN)."""
    columns = [str(name) for name in table.columns]
    write_header(path, columns)
    append_rows(path, columns, table.to_dict("records"), formats or {})


def read_text(path: Path) -> tuple[list[str], list[tuple[int, list[str]]]]:
    """The header and the whole rows (line number, cells) of a table's file; a last line cut by a kill is
    left out. InputError when the file is not CSV text."""
    try:
        text = path.read_text(encoding="utf-8") if path.exists() else ""
        lines = list(csv.reader(io.StringIO(text[: text.rfind("\n") + 1], newline="")))
    except (UnicodeDecodeError, csv.Error) as error:
        raise InputError(f"--out: {path}: not a results table rpdrill wrote ({error}); use a new --out directory") \
            from None
    if not lines:
        return [], []
    return lines[0], list(enumerate(lines[1:], 2))


def is_number(text: str) -> bool:
    """Whether a cell's text is a number (NaN and infinities included)."""
    try:
        float(text)
    except ValueError:
        return False
    return True


def typed(frame: pd.DataFrame, text: Sequence[str] = ()) -> pd.DataFrame:
    """A table of text cells typed: a column whose every non-empty cell is a number becomes numbers
    (empty cells NaN), the others stay text; status, error and the ``text`` columns are text."""
    import pandas as pd  # 0.3 s to import: only where a table is asked for

    frame = frame.copy()
    for column in frame.columns:
        if column in TEXT_COLUMNS or column in text or frame[column].dtype != object:
            continue
        cells = frame[column].astype(str)
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
