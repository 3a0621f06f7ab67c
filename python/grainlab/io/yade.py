"""YADE's sphere text export (``yade.export.text`` / ``export.textExt``).

Its formats, ids, materials and boundary spheres: docs/file-formats.md, "Formats
read from other codes".
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from grainlab.io._planar import check_z_policy
from grainlab.io._points import boundary_kind, snapshot_from_points
from grainlab.io._table import FileFormatError, integral_column, parse_float_table, read_lines
from grainlab.io.csv import warn_missing_kind
from grainlab.snapshot import Snapshot

__all__ = ["YADE_FORMATS", "read_yade_text"]

#: Column names of each YADE ``#format`` (``x_y_z_r_attrs`` adds the comment's names).
YADE_FORMATS: dict[str, tuple[str, ...]] = {
    "x_y_z_r": ("x", "y", "z", "radius"),
    "x_y_z_r_matId": ("x", "y", "z", "radius", "material_id"),
    "id_x_y_z_r_matId": ("id", "x", "y", "z", "radius", "material_id"),
    "x_y_z_r_attrs": ("x", "y", "z", "radius"),
}


def _layout(path: Path, lines: list[str]) -> tuple[str, tuple[str, ...], list[int]]:
    """The format name, the column names and the 0-based indices of the data lines."""
    fmt = None
    fmt_line = None
    comments: list[str] = []
    data: list[int] = []
    for k, text in enumerate(lines):
        stripped = text.strip()
        if not stripped:
            continue
        if stripped.startswith("#"):
            words = stripped[1:].split()
            if stripped.startswith("#format") and fmt is None and not data:
                fmt = words[1] if len(words) > 1 else ""
                fmt_line = k + 1
            elif not data:
                comments.append(stripped[1:].strip())
            continue
        data.append(k)
    if fmt is None:
        raise FileFormatError(
            path, 1, "no '#format NAME' line: not a YADE text export (export.text writes '#format x_y_z_r' first)"
        )
    if fmt not in YADE_FORMATS:
        raise FileFormatError(
            path, fmt_line, f"YADE format {fmt!r} not supported (supported: {', '.join(YADE_FORMATS)})"
        )
    names = YADE_FORMATS[fmt]
    if fmt == "x_y_z_r_attrs":
        extra = comments[-1].split() if comments else []
        if not extra:
            raise FileFormatError(
                path, fmt_line, "format x_y_z_r_attrs needs a comment line naming the extra columns"
            )
        names = names + tuple(extra)
    return fmt, names, data


def read_yade_text(
    path: str | Path,
    *,
    tolerance: float = 0.0,
    boundary_materials: Sequence[int] = (),
    z_policy: str = "refuse",
    z0: float | None = None,
) -> Snapshot:
    """Read a YADE sphere text export into a :class:`~grainlab.snapshot.Snapshot`.

    Contacts are detected from the geometry (centre distance < r_i + r_j +
    ``tolerance``, m). ``boundary_materials``: material ids of the spheres
    that bound the sample (kind MEMBRANE); needs a ``matId`` column.
    """
    check_z_policy(z_policy, z0)
    p = Path(path)
    lines = read_lines(p)
    fmt, names, data = _layout(p, lines)
    numbers = np.array(data, dtype=np.int64) + 1
    table = parse_float_table(
        p, [lines[k] for k in data], numbers, len(names), delimiter=None, column_names=names
    )
    if table.shape[0] == 0:
        raise FileFormatError(p, None, "no sphere lines after the header")
    col = {n: table[:, k] for k, n in enumerate(names)}
    fields: dict[str, NDArray[np.generic]] = {
        n: v for n, v in col.items() if n not in ("id", "x", "y", "z", "radius")
    }
    kind = None
    if "material_id" in col:
        fields["material_id"] = integral_column(p, col["material_id"], numbers, "material_id")
    if len(boundary_materials):
        if "material_id" not in col:
            raise FileFormatError(
                p, None, f"boundary_materials needs a material id column (format {fmt} has none)"
            )
        kind = boundary_kind(fields["material_id"], boundary_materials)
    else:
        warn_missing_kind(p)
    return snapshot_from_points(
        p,
        numbers,
        np.c_[col["x"], col["y"]],
        col["z"],
        col["radius"],
        col.get("id"),
        kind=kind,
        fields=fields,
        metadata={"source": str(p), "format": "yade-text", "yade_format": fmt},
        tolerance=tolerance,
        z_policy=z_policy,
        z0=z0,
    )
