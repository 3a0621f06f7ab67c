"""Particles and contacts as CSV files, in grainlab's layout or any other through a column mapping.

Columns, units, roles and the ``kind`` warning: docs/analysis.md, "Files read and
written"; errors are :class:`~grainlab.io.FileFormatError` (``FILE:LINE: problem``).
"""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from grainlab.io._planar import check_z_policy, detected_snapshot, keep_planar_rows, planar
from grainlab.io._points import pair_indices
from grainlab.io._table import (
    FileFormatError,
    check_geometry,
    check_unique_ids,
    integral_column,
    label_column,
    parse_float_table,
    plain,
    read_lines,
    refuse_first,
)
from grainlab.snapshot import (
    BODY_FIELD,
    GRAIN_ANGLE_FIELD,
    GRAIN_CENTROID_FIELD,
    GRAIN_FIELD,
    ParticleKind,
    Snapshot,
)

__all__ = [
    "CONTACT_ROLES",
    "GRAIN_CENTROID_COLUMNS",
    "PARTICLE_ROLES",
    "MissingKindWarning",
    "check_column_map",
    "read_contacts_csv",
    "read_particles_csv",
    "write_contacts_csv",
    "write_particles_csv",
]

PARTICLE_COLUMNS = ("id", "x", "y", "radius")
CONTACT_COLUMNS = ("i", "j")
#: The columns of a grain's centroid, x and y (m).
GRAIN_CENTROID_COLUMNS = ("grain_x", "grain_y")
#: Roles a ``columns`` mapping may give to a particles file's columns.
PARTICLE_ROLES = (
    "id", "x", "y", "z", "radius", "rotation", "kind", BODY_FIELD, GRAIN_FIELD, *GRAIN_CENTROID_COLUMNS, GRAIN_ANGLE_FIELD
)
#: Roles a ``columns`` mapping may give to a contacts file's columns.
CONTACT_ROLES = ("i", "j", "normal_force", "shear_force")


class MissingKindWarning(UserWarning):
    """A particles file without a ``kind`` column: every particle is read as a grain."""


def warn_missing_kind(path: str | Path, stacklevel: int = 3) -> None:
    """Warn that ``path`` has no particle kinds, so boundary disks would count as grains."""
    warnings.warn(
        f"{path}: no 'kind' column: every particle is read as a grain (kind 0), so membrane or "
        "wall disks in the file would count as grains in Z, lambda and the fabric; add a 'kind' "
        "column (1 for membrane disks, docs/file-formats.md) or map one with columns=",
        MissingKindWarning,
        stacklevel=stacklevel,
    )


def check_column_map(
    columns: Mapping[str, str] | None, roles: tuple[str, ...], what: str = "columns"
) -> dict[str, str]:
    """``columns`` as ``{role: file column (lower case)}``; ValueError naming a bad entry.

    >>> check_column_map({"id": "ID", "x": "pos_x"}, PARTICLE_ROLES)
    {'id': 'id', 'x': 'pos_x'}
    """
    out: dict[str, str] = {}
    for role, name in (columns or {}).items():
        if role not in roles:
            raise ValueError(f"{what}: unknown role {role!r} (roles: {', '.join(roles)})")
        if not isinstance(name, str) or not name.strip():
            raise ValueError(f"{what}[{role!r}]: expected a column name, got {name!r}")
        out[role] = name.strip().lower()
    taken = list(out.values())
    for name in taken:
        if taken.count(name) > 1:
            both = [r for r, n in out.items() if n == name]
            raise ValueError(f"{what}: column {name!r} given two roles ({', '.join(both)})")
    return out


def _rename(
    path: str | Path, line: int, names: list[str], column_map: Mapping[str, str]
) -> list[str]:
    """The header's names with the mapped file columns renamed to their roles."""
    role_of = {name: role for role, name in column_map.items()}
    for role, name in column_map.items():
        if name not in names:
            raise FileFormatError(
                path,
                line,
                f"column mapping {role}={name}: no column {name!r} in the header "
                f"(header has {', '.join(names)})",
            )
    renamed = [role_of.get(n, n) for n in names]
    for role, name in column_map.items():
        if role != name and role in names:
            raise FileFormatError(
                path,
                line,
                f"column mapping {role}={name}: the header also has a column {role!r}; "
                f"map one of them away or drop it",
            )
    return renamed


def _read_csv(
    path: str | Path, required: tuple[str, ...], column_map: Mapping[str, str] | None = None
) -> tuple[list[str], NDArray[np.float64], NDArray[np.int64]]:
    lines = read_lines(path)
    keep = [
        (k + 1, text)
        for k, text in enumerate(lines)
        if text.strip() and not text.lstrip().startswith("#")
    ]
    if not keep:
        raise FileFormatError(
            path, None, "empty file: expected a header line " + ",".join(required)
        )
    header_line, header = keep[0]
    names = [h.strip().lower() for h in header.split(",")]
    trailing = len(names) > 1 and names[-1] == ""  # tolerate a trailing comma on every line
    if trailing:
        names = names[:-1]
    if column_map:
        names = _rename(path, header_line, names, column_map)
    seen: set[str] = set()
    for name in names:
        if name == "":
            raise FileFormatError(path, header_line, "empty column name in the header")
        if name in seen:
            raise FileFormatError(path, header_line, f"duplicate column {name!r} in the header")
        seen.add(name)
    missing = [c for c in required if c not in seen]
    if missing:
        example = ",".join(f"{c}=NAME" for c in missing)
        raise FileFormatError(
            path,
            header_line,
            f"missing column(s) {', '.join(missing)} "
            f"(header has {', '.join(names)}; need {','.join(required)}; a file with other "
            f"names maps them with columns=, on the command line --columns {example})",
        )
    rows = keep[1:]
    numbers = np.array([k for k, _ in rows], dtype=np.int64)
    texts = [t.rstrip()[:-1] if trailing and t.rstrip().endswith(",") else t for _, t in rows]
    data = parse_float_table(path, texts, numbers, len(names), delimiter=",", column_names=names)
    return names, data, numbers


def read_particles_csv(
    path: str | Path,
    *,
    contacts: str | Path | None = None,
    tolerance: float = 0.0,
    detect: bool = True,
    z_policy: str = "refuse",
    z0: float | None = None,
    columns: Mapping[str, str] | None = None,
    contact_columns: Mapping[str, str] | None = None,
    format_name: str = "particles-csv",
) -> Snapshot:
    """Read a particles CSV (and optionally a contacts CSV) into a :class:`Snapshot`.

    Without ``contacts`` and with ``detect=True`` contacts are detected from
    the geometry (centre distance < r_i + r_j + ``tolerance``). ``columns`` maps
    grainlab's roles (:data:`PARTICLE_ROLES`) to the file's column names,
    ``contact_columns`` those of the contacts file (:data:`CONTACT_ROLES`). The
    columns, the ``z`` check (``z_policy``, ``z0``) and the warning of a file without
    a ``kind`` column (:class:`MissingKindWarning`): docs/analysis.md, "Files read
    and written".

    >>> import pathlib, tempfile, warnings
    >>> f = pathlib.Path(tempfile.mkdtemp()) / "balls.csv"
    >>> _ = f.write_text("ID,pos_x,pos_y,rad\\n7,0,0,0.001\\n8,0.002,0,0.001\\n")
    >>> with warnings.catch_warnings():
    ...     warnings.simplefilter("ignore", MissingKindWarning)
    ...     s = read_particles_csv(f, columns={"id": "ID", "x": "pos_x", "y": "pos_y", "radius": "rad"},
    ...                            tolerance=1e-9)
    >>> s.ids.tolist(), s.n_contacts
    ([7, 8], 1)
    """
    check_z_policy(z_policy, z0, contacts)
    column_map = check_column_map(columns, PARTICLE_ROLES)
    contact_map = check_column_map(contact_columns, CONTACT_ROLES, "contact_columns")
    if contact_map and contacts is None:
        raise ValueError("contact_columns: only apply to a contacts file (give contacts=)")
    names, data, numbers = _read_csv(path, PARTICLE_COLUMNS, column_map)
    if data.shape[0] == 0:
        raise FileFormatError(path, None, "no particle rows after the header")
    col = {n: data[:, k] for k, n in enumerate(names)}
    ids = integral_column(path, col["id"], numbers, "id")
    check_unique_ids(path, ids, numbers)
    radius = col["radius"]
    refuse_first(
        path, radius <= 0, numbers, lambda k: f"column 'radius': {plain(radius[k])} is not > 0"
    )
    kind = _kinds(path, col, numbers)
    extra = _label_fields(path, col, numbers)
    positions = np.c_[col["x"], col["y"]]
    metadata: dict[str, Any] = {"source": str(path), "format": format_name}
    if column_map:
        metadata["columns"] = dict(column_map)
    rotations = col.get("rotation")
    plan = planar(path, None, col.get("z"), radius, z_policy=z_policy, z0=z0)
    check_geometry(path, positions[plan.keep], plan.radii, numbers[plan.keep])
    kwargs: dict[str, Any] = dict(
        ids=ids, rotations=rotations, kind=kind, particle_fields=extra, metadata=metadata
    )
    positions, radius = keep_planar_rows(plan, positions, radius, kwargs, z_field=False)
    if contacts is not None:
        snap = Snapshot(positions, radius, **kwargs)
        return attach_contacts_csv(snap, contacts, columns=contact_map)
    return detected_snapshot(path, plan, positions, radius, kwargs, detect=detect, tolerance=tolerance)


def _kinds(
    path: str | Path, col: Mapping[str, NDArray[np.float64]], numbers: NDArray[np.int64]
) -> NDArray[np.int64] | None:
    """The particles' kinds from the ``kind`` column (known codes only), or None with
    a :class:`MissingKindWarning` when there is none."""
    if "kind" not in col:
        warn_missing_kind(path)
        return None
    kind = integral_column(path, col["kind"], numbers, "kind")
    refuse_first(path, ~np.isin(kind, [int(k) for k in ParticleKind]), numbers,
                 lambda k: f"column 'kind': unknown code {int(kind[k])}")
    return kind


def _label_fields(
    path: str | Path, col: Mapping[str, NDArray[np.float64]], numbers: NDArray[np.int64]
) -> dict[str, NDArray[Any]]:
    """The particles' fields: every column but the core ones, with the membrane chain
    (``body``) and the grain (``grain``; ``grain_x, grain_y`` as the field
    ``grain_centroid``) read as labels and checked, naming the line."""
    extra: dict[str, NDArray[Any]] = {
        n: v for n, v in col.items() if n not in PARTICLE_COLUMNS + ("rotation", "kind", *GRAIN_CENTROID_COLUMNS)
    }
    if BODY_FIELD in col:
        extra[BODY_FIELD] = label_column(path, col[BODY_FIELD], numbers, BODY_FIELD, "body", -1)
    if GRAIN_FIELD in col:
        extra[GRAIN_FIELD] = label_column(path, col[GRAIN_FIELD], numbers, GRAIN_FIELD, "grain", 0)
    given = [n for n in (*GRAIN_CENTROID_COLUMNS, GRAIN_ANGLE_FIELD) if n in col]
    if given and GRAIN_FIELD not in col:
        raise FileFormatError(path, None, f"column {given[0]!r}: a grain's value without a {GRAIN_FIELD!r} column")
    x, y = (col.get(n) for n in GRAIN_CENTROID_COLUMNS)
    if (x is None) != (y is None):
        raise FileFormatError(path, None, "columns 'grain_x', 'grain_y': a grain's centroid needs both")
    if x is not None and y is not None:
        extra[GRAIN_CENTROID_FIELD] = np.c_[x, y]
    return extra


def read_contacts_csv(
    path: str | Path, *, columns: Mapping[str, str] | None = None
) -> dict[str, NDArray[Any]]:
    """Read a contacts CSV: a dict with ``i``, ``j`` (ids) and the optional force columns.

    ``columns`` maps the roles :data:`CONTACT_ROLES` to the file's column
    names (``{"i": "end1", "j": "end2"}``). Also returns ``line`` (the file
    line of each row) for error messages.
    """
    column_map = check_column_map(columns, CONTACT_ROLES, "contact_columns")
    names, data, numbers = _read_csv(path, CONTACT_COLUMNS, column_map)
    col = {n: data[:, k] for k, n in enumerate(names)}
    out: dict[str, NDArray[Any]] = {
        "i": integral_column(path, col["i"], numbers, "i"),
        "j": integral_column(path, col["j"], numbers, "j"),
        "line": numbers,
    }
    for name in ("normal_force", "shear_force"):
        if name in col:
            out[name] = col[name]
    return out


def attach_contacts_csv(
    snapshot: Snapshot, path: str | Path, *, columns: Mapping[str, str] | None = None
) -> Snapshot:
    """The snapshot with the contacts read from a contacts CSV (ids -> indices)."""
    c = read_contacts_csv(path, columns=columns)
    i, j = pair_indices(path, snapshot, (c["i"], c["j"]), ("i", "j"), c["line"], "particle",
                        "in contact with itself")
    metadata = dict(snapshot.metadata)
    metadata["contacts"] = f"read from {path}"
    return dataclasses.replace(
        snapshot,
        contact_i=i,
        contact_j=j,
        normal_force=c.get("normal_force"),
        shear_force=c.get("shear_force"),
        contact_normal=None,
        contact_point=None,
        contact_fields={},
        metadata=metadata,
    )


def write_particles_csv(
    path: str | Path,
    snapshot: Snapshot,
    columns: Mapping[str, ArrayLike] | None = None,
    *,
    float_format: str = "%.17g",
) -> Path:
    """Write ``id,x,y,radius`` (+ rotation when set, kind, body and grain when set, + ``columns``) as CSV.

    A snapshot with grains (:data:`~grainlab.snapshot.GRAIN_FIELD`) writes
    ``grain`` and, when it has them, ``grain_x, grain_y`` and ``grain_angle``.

    ``kind`` is always written, so that reading the file back does not warn
    (:class:`MissingKindWarning`).

    Extra ``columns`` are (N,) arrays; NaN is written as an empty field.
    Integer and bool columns are written as integers. Returns the path.
    """
    cols: dict[str, NDArray[Any]] = {
        "id": np.asarray(snapshot.ids),
        "x": snapshot.positions[:, 0],
        "y": snapshot.positions[:, 1],
        "radius": np.asarray(snapshot.radii),
    }
    if snapshot.rotations is not None:
        cols["rotation"] = np.asarray(snapshot.rotations)
    cols["kind"] = np.asarray(snapshot.kind)
    fields = snapshot.particle_fields
    for name in (BODY_FIELD, GRAIN_FIELD):
        if name in fields:
            cols[name] = np.asarray(fields[name])
    if GRAIN_CENTROID_FIELD in fields:
        centroid = np.asarray(fields[GRAIN_CENTROID_FIELD])
        cols.update(zip(GRAIN_CENTROID_COLUMNS, centroid.T, strict=True))
    if GRAIN_ANGLE_FIELD in fields:
        cols[GRAIN_ANGLE_FIELD] = np.asarray(fields[GRAIN_ANGLE_FIELD])
    for name, values in (columns or {}).items():
        v = np.asarray(values)
        if v.shape != (snapshot.n_particles,):
            raise ValueError(
                f"columns[{name!r}]: expected shape ({snapshot.n_particles},), got {v.shape}"
            )
        cols[name] = v
    return _write_table(path, cols, float_format)


def write_contacts_csv(
    path: str | Path, snapshot: Snapshot, *, float_format: str = "%.17g"
) -> Path:
    """Write the particle–particle contacts as ``i,j[,normal_force,shear_force]`` (by id)."""
    pp = np.asarray(snapshot.contact_j) >= 0
    cols: dict[str, NDArray[Any]] = {
        "i": np.asarray(snapshot.ids)[np.asarray(snapshot.contact_i)[pp]],
        "j": np.asarray(snapshot.ids)[np.asarray(snapshot.contact_j)[pp]],
    }
    if snapshot.normal_force is not None:
        cols["normal_force"] = np.asarray(snapshot.normal_force)[pp]
    if snapshot.shear_force is not None:
        cols["shear_force"] = np.asarray(snapshot.shear_force)[pp]
    return _write_table(path, cols, float_format)


def _write_table(path: str | Path, cols: Mapping[str, NDArray[Any]], float_format: str) -> Path:
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    rendered = []
    for v in cols.values():
        if v.dtype == bool:
            v = v.astype(np.int64)
        if np.issubdtype(v.dtype, np.integer):
            rendered.append(v.astype(str))
        else:
            f = np.asarray(v, dtype=np.float64)
            text = np.char.mod(float_format, f)
            rendered.append(np.where(np.isfinite(f), text, ""))
    header = ",".join(cols)
    if rendered and rendered[0].size:
        body = rendered[0].astype(object)
        for r in rendered[1:]:
            body = body + "," + r.astype(object)
        content = header + "\n" + "\n".join(body.tolist()) + "\n"
    else:
        content = header + "\n"
    p.write_text(content, encoding="utf-8")
    return p
