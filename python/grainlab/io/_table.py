"""Shared text-table parsing with error messages that name file and line."""

from __future__ import annotations

from collections.abc import Callable, Sequence
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


#: Largest coordinate or radius magnitude read, m: far beyond any granular sample in SI
#: units, and small enough that squared distances stay finite in float64.
MAX_LENGTH_M = 1.0e12


def plain(value: float) -> str:
    """A number as a message shows it: ``1e-300``, ``nan``, ``3`` (never ``np.float64(...)``).

    >>> import numpy as np
    >>> plain(np.float64("nan")), plain(np.float64(1e-300)), plain(np.int64(3)), plain(0.5)
    ('nan', '1e-300', '3', '0.5')
    """
    number = float(value)
    return str(int(number)) if number.is_integer() and abs(number) < 2.0**53 else repr(number)


def read_lines(path: str | Path) -> list[str]:
    """All lines of a text file (no line endings); a clear error if unreadable.

    A UTF-8 byte-order mark at the start (spreadsheet programs write one) is dropped.
    """
    p = Path(path)
    try:
        return p.read_text(encoding="utf-8-sig", errors="strict").splitlines()
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
            f"column {column_names[c]!r}: value {plain(data[r, c])} is not finite",
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


def refuse_first(
    path: str | Path,
    bad: NDArray[np.bool_],
    line_numbers: NDArray[np.int64],
    problem: Callable[[int], str],
) -> None:
    """A :class:`FileFormatError` naming the line of the first row ``k`` where ``bad``
    holds, with the message ``problem(k)``; nothing when no row is bad."""
    if bad.any():
        k = int(np.argmax(bad))
        raise FileFormatError(path, int(line_numbers[k]), problem(k))


def _first_repeat(order: NDArray[np.int64], repeated: NDArray[np.bool_]) -> tuple[int, int] | None:
    """The rows (first, second) of the first pair of neighbours in ``order`` that
    ``repeated`` marks, in file order; None when there is none."""
    if not repeated.any():
        return None
    k = int(np.argmax(repeated))
    first, second = sorted((int(order[k]), int(order[k + 1])))
    return first, second


def integral_column(
    path: str | Path, values: NDArray[np.float64], line_numbers: NDArray[np.int64], name: str
) -> NDArray[np.int64]:
    """Check that a parsed column holds integers (exactly representable) and convert."""
    bad = (values != np.round(values)) | (np.abs(values) > 2.0**53)
    refuse_first(path, bad, line_numbers,
                 lambda k: f"column {name!r}: {plain(values[k])} is not an integer id")
    return values.astype(np.int64)


def label_column(
    path: str | Path, values: NDArray[np.float64], line_numbers: NDArray[np.int64], name: str, what: str, least: int
) -> NDArray[np.int64]:
    """An integer column of ``what`` labels (``"body"``, ``"grain"``), each >= ``least``; the
    error names the line of the first that is not."""
    labels = integral_column(path, values, line_numbers, name)
    refuse_first(path, labels < least, line_numbers,
                 lambda k: f"column {name!r}: {int(labels[k])} is not a {what} label (>= {least})")
    return labels


def check_unique_ids(
    path: str | Path, ids: NDArray[np.int64], line_numbers: NDArray[np.int64]
) -> None:
    """Raise naming the line of the second occurrence of a duplicate id."""
    order = np.argsort(ids, kind="stable")
    pair = _first_repeat(order, ids[order[1:]] == ids[order[:-1]])
    if pair is not None:
        first, second = pair
        raise FileFormatError(
            path,
            int(line_numbers[second]),
            f"duplicate particle id {int(ids[second])} "
            f"(first seen on line {int(line_numbers[first])})",
        )


def check_geometry(
    path: str | Path,
    positions: NDArray[np.float64],
    radii: NDArray[np.float64],
    line_numbers: NDArray[np.int64],
    position_columns: tuple[str, str] = ("x", "y"),
) -> None:
    """Raise naming the line of a coordinate or radius beyond :data:`MAX_LENGTH_M`
    or of a particle whose centre another particle has already (the contact
    normal between them would be undefined)."""
    for values, name in ((positions[:, 0], position_columns[0]), (positions[:, 1], position_columns[1]),
                         (radii, "radius")):
        refuse_first(  # the message is made at once: the loop's names are current
            path, np.abs(values) > MAX_LENGTH_M, line_numbers,
            lambda k: f"column {name!r}: {plain(values[k])} m is beyond the "  # noqa: B023
            f"{MAX_LENGTH_M:g} m grainlab reads (lengths are in metres)",
        )
    if len(radii) < 2:
        return
    order = np.lexsort((positions[:, 1], positions[:, 0]))
    pair = _first_repeat(order, np.all(positions[order[1:]] == positions[order[:-1]], axis=1))
    if pair is not None:
        first, second = pair
        raise FileFormatError(
            path,
            int(line_numbers[second]),
            f"this particle's centre ({plain(positions[second, 0])}, {plain(positions[second, 1])}) is the "
            f"centre of the particle on line {int(line_numbers[first])} too: coincident disks have no contact normal",
        )
