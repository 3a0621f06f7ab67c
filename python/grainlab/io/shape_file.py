"""A grain shape from a file: one pebble per line, ``x, y, r`` (docs/bodies.md,
"Shapes"), in any frame and scale; the template is put about the union's
centroid and scaled to circumscribed radius 1 (:func:`grainlab.shapes.template_of`).

Commas or blanks separate the numbers; ``#`` starts a comment; an optional
first line of column names (``x, y, r``) is skipped.

>>> import tempfile, pathlib
>>> path = pathlib.Path(tempfile.mkdtemp()) / "dimer.csv"
>>> _ = path.write_text("x, y, r\\n-0.5, 0, 1\\n0.5, 0, 1\\n")
>>> t = read_shape_template(path)
>>> t.n_pebbles, round(t.eta, 6)
(2, 0.42265)
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from grainlab.io._table import FileFormatError, plain, read_lines
from grainlab.shapes import ShapeTemplate, template_of

__all__ = ["read_shape_template"]


def _numbers(path: Path, number: int, line: str) -> list[float] | None:
    """The three numbers of a pebble's line, None for a header; a bad line raises."""
    fields = [f for f in line.replace(",", " ").split() if f]
    try:
        values = [float(f) for f in fields]
    except ValueError:
        if number == 1 and [f.lower() for f in fields] == ["x", "y", "r"]:
            return None
        raise FileFormatError(path, number, f"expected three numbers x, y, r (m), got {line.strip()!r}") from None
    if len(values) != 3:
        raise FileFormatError(path, number, f"expected three numbers x, y, r (m), got {len(values)}")
    if not all(math.isfinite(v) for v in values) or values[2] <= 0.0:
        shown = ", ".join(plain(v) for v in values)
        raise FileFormatError(path, number, f"a pebble needs a finite centre and a radius > 0, got {shown}")
    return values


def read_shape_template(path: str | Path) -> ShapeTemplate:
    """The shape of the pebbles listed in ``path`` (``x, y, r`` per line)."""
    path = Path(path)
    rows = []
    for number, raw in enumerate(read_lines(path), start=1):
        line = raw.split("#", 1)[0]
        if line.strip():
            values = _numbers(path, number, line)
            if values is not None:
                rows.append(values)
    if not rows:
        raise FileFormatError(path, None, "no pebble (one line x, y, r per pebble)")
    table = np.array(rows, dtype=np.float64)
    return template_of(table[:, :2], table[:, 2])
