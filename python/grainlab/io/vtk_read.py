"""Legacy VTK particle files (``.vtk``, ASCII), as LIGGGHTS' and LAMMPS'
``dump custom/vtk`` write them.

What is read and how: docs/file-formats.md, "Formats read from other codes".
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from grainlab.io._planar import check_z_policy
from grainlab.io._points import boundary_kind, snapshot_from_points
from grainlab.io._table import FileFormatError, integral_column, read_lines
from grainlab.snapshot import Snapshot

__all__ = ["is_legacy_vtk", "read_legacy_vtk"]

_MAGIC = "# vtk datafile"
_CELL_SECTIONS = ("VERTICES", "LINES", "POLYGONS", "TRIANGLE_STRIPS", "CELLS")


def is_legacy_vtk(first_line: str) -> bool:
    """True for the first line of a legacy VTK file (``# vtk DataFile Version x.y``)."""
    return first_line.strip().lower().startswith(_MAGIC)


class _Tokens:
    """The file's whitespace-separated words with the line of each."""

    def __init__(self, path: Path, lines: list[str], start: int) -> None:
        self.path = path
        self.words: list[str] = []
        self.line: list[int] = []
        for k in range(start, len(lines)):
            parts = lines[k].split()
            self.words.extend(parts)
            self.line.extend([k + 1] * len(parts))
        self.pos = 0

    def done(self) -> bool:
        return self.pos >= len(self.words)

    def where(self) -> int | None:
        if not self.words:
            return None
        return self.line[min(self.pos, len(self.words) - 1)]

    def word(self, what: str) -> str:
        if self.done():
            raise FileFormatError(self.path, self.where(), f"file ends where {what} was expected")
        w = self.words[self.pos]
        self.pos += 1
        return w

    def integer(self, what: str) -> int:
        line = self.where()
        w = self.word(what)
        try:
            value = int(w)
        except ValueError:
            raise FileFormatError(self.path, line, f"{what}: cannot read {w!r} as an integer") from None
        if value < 0:
            raise FileFormatError(self.path, line, f"{what}: {value} is negative")
        return value

    def numbers(self, count: int, what: str) -> NDArray[np.float64]:
        line = self.where()
        if self.pos + count > len(self.words):
            raise FileFormatError(
                self.path, line, f"{what}: expected {count} values, the file ends after "
                f"{len(self.words) - self.pos}"
            )
        chunk = self.words[self.pos : self.pos + count]
        try:
            values = np.array(chunk, dtype=np.float64)
        except ValueError:
            for k, w in enumerate(chunk):  # error path only: name the culprit's line
                try:
                    float(w)
                except ValueError:
                    raise FileFormatError(
                        self.path, self.line[self.pos + k], f"{what}: cannot read {w!r} as a number"
                    ) from None
            raise
        bad = ~np.isfinite(values)
        if bad.any():
            k = int(np.argmax(bad))
            raise FileFormatError(self.path, self.line[self.pos + k], f"{what}: value {chunk[k]} is not finite")
        self.pos += count
        return values

    def skip_metadata(self) -> None:
        """VTK 9 may follow an array by ``METADATA`` and ``INFORMATION k`` blocks: skip them."""
        if not self.done() and self.words[self.pos].upper() == "METADATA":
            self.pos += 1
            while not self.done() and self.words[self.pos].upper() in ("COMPONENT_NAMES", "INFORMATION"):
                if self.words[self.pos].upper() == "INFORMATION":
                    self.pos += 1
                    n = self.integer("INFORMATION count")
                    if n:
                        raise FileFormatError(
                            self.path, self.where(), "array INFORMATION entries are not supported"
                        )
                else:
                    raise FileFormatError(self.path, self.where(), "array COMPONENT_NAMES are not supported")


def _skip_cells(tok: _Tokens, keyword: str, version: float) -> None:
    n = tok.integer(f"{keyword} count")
    size = tok.integer(f"{keyword} size")
    if version >= 5.0 and keyword != "CELL_TYPES":
        for block, count in (("OFFSETS", n), ("CONNECTIVITY", size)):
            name = tok.word(block).upper()
            if name != block:
                raise FileFormatError(tok.path, tok.where(), f"{keyword}: expected {block}, found {name!r}")
            tok.word(f"{block} type")
            tok.numbers(count, f"{keyword} {block}")
    else:
        tok.numbers(size, keyword)


def _read_arrays(tok: _Tokens, n: int, into: dict[str, NDArray[np.float64]] | None) -> None:
    """Arrays of a POINT_DATA / CELL_DATA section (of n tuples) until the next section."""
    while not tok.done():
        key = tok.words[tok.pos].upper()
        if key in ("POINT_DATA", "CELL_DATA"):
            return
        line = tok.where()
        tok.pos += 1
        if key == "SCALARS":
            name = tok.word("SCALARS name")
            tok.word("SCALARS type")
            ncomp = 1
            if not tok.done() and tok.line[tok.pos] == line:  # the optional component count
                ncomp = tok.integer("SCALARS components")
            if not tok.done() and tok.words[tok.pos].upper() == "LOOKUP_TABLE":
                tok.pos += 2
            values = tok.numbers(n * ncomp, f"SCALARS {name}").reshape(n, ncomp)
        elif key in ("VECTORS", "NORMALS"):
            name = tok.word(f"{key} name")
            tok.word(f"{key} type")
            values = tok.numbers(3 * n, f"{key} {name}").reshape(n, 3)
        elif key == "FIELD":
            tok.word("FIELD name")
            for _ in range(tok.integer("FIELD array count")):
                name = tok.word("FIELD array name")
                ncomp = tok.integer(f"{name} components")
                ntuples = tok.integer(f"{name} tuples")
                kind = tok.word(f"{name} type")
                if kind.lower() == "string":
                    raise FileFormatError(tok.path, tok.where(), f"array {name!r}: string arrays are not supported")
                values = tok.numbers(ncomp * ntuples, f"array {name}").reshape(ntuples, ncomp)
                tok.skip_metadata()
                if ntuples != n:
                    raise FileFormatError(tok.path, line, f"array {name!r}: {ntuples} tuples for {n} points")
                if into is not None:
                    into[name] = values[:, 0] if ncomp == 1 else values
            continue
        elif key == "LOOKUP_TABLE":
            tok.word("LOOKUP_TABLE name")
            tok.numbers(4 * tok.integer("LOOKUP_TABLE size"), "LOOKUP_TABLE")
            continue
        else:
            raise FileFormatError(tok.path, line, f"unexpected {tok.words[tok.pos - 1]!r} in the data arrays")
        tok.skip_metadata()
        if into is not None:
            into[name] = values[:, 0] if values.shape[1] == 1 else values


def _vtk_header(p: Path) -> tuple[float, _Tokens]:
    """A legacy VTK file's version and its tokens from the ``DATASET`` line on,
    checked: ASCII, and a dataset of points (POLYDATA or UNSTRUCTURED_GRID)."""
    lines = read_lines(p)
    if len(lines) < 4 or not is_legacy_vtk(lines[0]):
        raise FileFormatError(p, 1, "not a legacy VTK file (first line '# vtk DataFile Version x.y')")
    try:
        version = float(lines[0].split()[-1])
    except ValueError:
        raise FileFormatError(p, 1, f"cannot read the file version from {lines[0].strip()!r}") from None
    encoding = lines[2].strip().upper()
    if encoding != "ASCII":
        raise FileFormatError(
            p, 3, f"{encoding or 'no'} encoding: only ASCII legacy VTK files are read (LAMMPS: dump_modify "
            "binary no; VTK writers: SetFileTypeToASCII)"
        )
    tok = _Tokens(p, lines, 3)
    if tok.word("DATASET").upper() != "DATASET":
        raise FileFormatError(p, tok.line[0], "expected 'DATASET' after the header")
    dataset = tok.word("dataset type").upper()
    if dataset not in ("POLYDATA", "UNSTRUCTURED_GRID"):
        raise FileFormatError(p, tok.line[1], f"DATASET {dataset}: particles are POLYDATA or UNSTRUCTURED_GRID")
    return version, tok


def _vtk_sections(
    p: Path, tok: _Tokens, version: float
) -> tuple[NDArray[np.float64] | None, NDArray[np.int64], int | None, dict[str, NDArray[np.float64]]]:
    """The points (N, 3), each point's file line, the POINTS line and the point
    arrays of the sections after ``DATASET`` (cells and field data skipped)."""
    points: NDArray[np.float64] | None = None
    point_lines = np.zeros(0, dtype=np.int64)
    points_line = None
    arrays: dict[str, NDArray[np.float64]] = {}
    while not tok.done():
        line = tok.where()
        key = tok.word("a section").upper()
        if key == "POINTS":
            points_line = line
            n = tok.integer("POINTS count")
            tok.word("POINTS type")
            first = tok.pos
            points = tok.numbers(3 * n, "POINTS").reshape(n, 3)
            point_lines = np.array(tok.line[first : first + 3 * n : 3], dtype=np.int64)
            tok.skip_metadata()
        elif key in _CELL_SECTIONS or key == "CELL_TYPES":
            if key == "CELL_TYPES":
                tok.numbers(tok.integer("CELL_TYPES count"), "CELL_TYPES")
            else:
                _skip_cells(tok, key, version)
        elif key in ("POINT_DATA", "CELL_DATA"):
            n = tok.integer(f"{key} count")
            if key == "POINT_DATA" and (points is None or n != points.shape[0]):
                raise FileFormatError(p, line, f"POINT_DATA {n} does not match the POINTS count")
            _read_arrays(tok, n, arrays if key == "POINT_DATA" else None)
        elif key == "FIELD":  # dataset-level field data (TIME, CYCLE): not per particle
            _skip_field_data(tok)
        else:
            raise FileFormatError(p, line, f"unexpected section {key!r}")
    return points, point_lines, points_line, arrays


def _skip_field_data(tok: _Tokens) -> None:
    """A ``FIELD`` section's arrays, read past."""
    tok.word("FIELD name")
    for _ in range(tok.integer("FIELD array count")):
        name = tok.word("FIELD array name")
        ncomp, ntuples = tok.integer(f"{name} components"), tok.integer(f"{name} tuples")
        tok.word(f"{name} type")
        tok.numbers(ncomp * ntuples, f"array {name}")
        tok.skip_metadata()


def _point_fields(p: Path, arrays: dict[str, NDArray[np.float64]], numbers: NDArray[np.int64],
                  radius_array: str) -> dict[str, NDArray[Any]]:
    """The particle fields of the point arrays but ``id`` and the radius: vectors in
    the plane, ``type`` as integers."""
    fields: dict[str, NDArray[Any]] = {}
    for name, values in arrays.items():
        if name in ("id", radius_array):
            continue
        fields[name] = values[:, :2].copy() if values.ndim == 2 and values.shape[1] == 3 else values
    if "type" in fields:
        fields["type"] = integral_column(p, arrays["type"], numbers, "type")
    return fields


def read_legacy_vtk(
    path: str | Path,
    *,
    tolerance: float = 0.0,
    boundary_types: Sequence[int] = (),
    radius_array: str = "radius",
    z_policy: str = "refuse",
    z0: float | None = None,
) -> Snapshot:
    """Read an ASCII legacy VTK particle file (LIGGGHTS / LAMMPS ``dump custom/vtk``).

    The particles are the points, with the radius array ``radius_array``;
    see the module documentation for ids, kinds, fields and z.
    """
    check_z_policy(z_policy, z0)
    p = Path(path)
    version, tok = _vtk_header(p)
    points, point_lines, points_line, arrays = _vtk_sections(p, tok, version)
    if points is None:
        raise FileFormatError(p, None, "no POINTS section")
    if radius_array not in arrays:
        raise FileFormatError(
            p, points_line, f"no point array {radius_array!r} (arrays: {', '.join(arrays) or 'none'}); "
            "dump the radius, or name its array with radius_array="
        )
    numbers = point_lines
    kind = None
    if len(boundary_types):
        if "type" not in arrays:
            raise FileFormatError(p, None, "boundary_types needs a point array 'type'")
        kind = boundary_kind(arrays["type"], boundary_types)
    fields = _point_fields(p, arrays, numbers, radius_array)
    return snapshot_from_points(
        p,
        numbers,
        points[:, :2].copy(),
        points[:, 2].copy(),
        arrays[radius_array],
        arrays.get("id"),
        kind=kind,
        fields=fields,
        metadata={"source": str(p), "format": "legacy-vtk", "vtk_version": version},
        tolerance=tolerance,
        z_policy=z_policy,
        z0=z0,
    )
