"""Shared text-table parsing with error messages that name file and line."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
from numpy.typing import NDArray


class FileFormatError(ValueError):
    """A malformed input file; the message reads ``FILE:LINE: problem``."""

    def __init__(self, path: str | Path, line: int | None, problem: str) -> None:
        self.path = str(path)
        self.line = line
        self.problem = problem
        where = f"{self.path}:{line}" if line is not None else self.path
        super().__init__(f"{where}: {problem}")


def read_lines(path: str | Path) -> list[str]:
    """All lines of a text file (no line endings); a clear error if unreadable."""
    p = Path(path)
    try:
        return p.read_text(encoding="utf-8", errors="strict").splitlines()
    except FileNotFoundError:
        raise FileFormatError(p, None, "file not found") from None
    except IsADirectoryError:
        raise FileFormatError(p, None, "is a directory, not a file") from None
    except UnicodeDecodeError as error:
        raise FileFormatError(
            p, None, f"not a UTF-8 text file ({error.reason} at byte {error.start})"
        ) from None


def parse_float_table(
    path: str | Path,
    lines: Sequence[str],
    line_numbers: NDArray[np.int64],
    n_columns: int,
    *,
    delimiter: str | None,
    column_names: Sequence[str],
) -> NDArray[np.float64]:
    """Parse rows of numbers; (rows, n_columns) float64.

    Fast path: one NumPy parse of all rows. If it fails, the rows are scanned
    one by one to report the first bad line (1-based ``line_numbers``) with
    its problem: wrong number of fields or a field that is not a number.
    Non-finite values (nan, inf) are reported too.
    """
    if len(lines) == 0:
        return np.zeros((0, n_columns))
    try:
        if delimiter is None:
            tokens = " ".join(lines).split()
        else:
            tokens = delimiter.join(lines).split(delimiter)
        if len(tokens) != len(lines) * n_columns:
            raise ValueError("field count")
        data = np.array(tokens, dtype=np.float64).reshape(len(lines), n_columns)
    except ValueError:
        _report_bad_row(path, lines, line_numbers, n_columns, delimiter, column_names)
        raise  # _report_bad_row always raises; keeps type checkers happy
    bad = ~np.isfinite(data)
    if bad.any():
        r, c = np.argwhere(bad)[0]
        raise FileFormatError(
            path,
            int(line_numbers[r]),
            f"column {column_names[c]!r}: value {data[r, c]!r} is not finite",
        )
    return data


def _report_bad_row(
    path: str | Path,
    lines: Sequence[str],
    line_numbers: NDArray[np.int64],
    n_columns: int,
    delimiter: str | None,
    column_names: Sequence[str],
) -> None:
    for text, number in zip(lines, line_numbers, strict=True):  # error path only: find the culprit
        fields = text.split(delimiter) if delimiter is not None else text.split()
        if len(fields) != n_columns:
            raise FileFormatError(
                path, int(number), f"expected {n_columns} fields, found {len(fields)}"
            )
        for name, field in zip(column_names, fields, strict=True):
            try:
                float(field)
            except ValueError:
                raise FileFormatError(
                    path, int(number), f"column {name!r}: cannot read {field.strip()!r} as a number"
                ) from None
    raise FileFormatError(path, None, "could not parse the numeric table")


def integral_column(
    path: str | Path, values: NDArray[np.float64], line_numbers: NDArray[np.int64], name: str
) -> NDArray[np.int64]:
    """Check that a parsed column holds integers (exactly representable) and convert."""
    bad = (values != np.round(values)) | (np.abs(values) > 2.0**53)
    if bad.any():
        k = int(np.argmax(bad))
        raise FileFormatError(
            path, int(line_numbers[k]), f"column {name!r}: {values[k]!r} is not an integer id"
        )
    return values.astype(np.int64)


def check_unique_ids(
    path: str | Path, ids: NDArray[np.int64], line_numbers: NDArray[np.int64]
) -> None:
    """Raise naming the line of the second occurrence of a duplicate id."""
    order = np.argsort(ids, kind="stable")
    dup = ids[order[1:]] == ids[order[:-1]]
    if dup.any():
        k = int(np.argmax(dup))
        first, second = sorted((int(order[k]), int(order[k + 1])))
        raise FileFormatError(
            path,
            int(line_numbers[second]),
            f"duplicate particle id {int(ids[second])} "
            f"(first seen on line {int(line_numbers[first])})",
        )
