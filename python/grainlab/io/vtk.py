"""ParaView files: VTK XML PolyData (``.vtp``), UnstructuredGrid (``.vtu``) and ``.pvd`` series.

The layout (points, contact lines, ``cell_kind``, fills, clumps, field data, time
values, exact binary and ASCII values): docs/file-formats.md, "ParaView".
"""

from __future__ import annotations

import base64
import os
import xml.etree.ElementTree as ET
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "CELL_CONTACT",
    "CELL_PARTICLE",
    "as_vector3",
    "clump_points",
    "contact_lines",
    "exportable",
    "CELL_WALL",
    "write_clumps_vtp",
    "write_pvd",
    "write_vtp",
    "write_vtu",
    "write_walls_vtp",
]

#: ``cell_kind`` of the vertex cell of a particle.
CELL_PARTICLE = 0
#: ``cell_kind`` of the line cell of a particle–particle contact.
CELL_CONTACT = 1
#: ``cell_kind`` of the line cell of a wall (platen) in a walls file.
CELL_WALL = 2

_VTK_TYPES = {
    np.dtype(np.float32): "Float32",
    np.dtype(np.float64): "Float64",
    np.dtype(np.int8): "Int8",
    np.dtype(np.uint8): "UInt8",
    np.dtype(np.int16): "Int16",
    np.dtype(np.uint16): "UInt16",
    np.dtype(np.int32): "Int32",
    np.dtype(np.uint32): "UInt32",
    np.dtype(np.int64): "Int64",
    np.dtype(np.uint64): "UInt64",
}


def _prepare(name: str, value: ArrayLike, length: int) -> NDArray[Any]:
    """``value`` as a little-endian array of a VTK type, shape (length,) or (length, k)."""
    a = np.asarray(value)
    if a.dtype == np.bool_:
        a = a.astype(np.int32)
    elif np.issubdtype(a.dtype, np.integer) and a.dtype.newbyteorder("=") not in _VTK_TYPES:
        a = a.astype(np.int64)
    elif np.issubdtype(a.dtype, np.floating) and a.dtype.newbyteorder("=") not in _VTK_TYPES:
        a = a.astype(np.float64)
    if a.dtype.newbyteorder("=") not in _VTK_TYPES:
        raise ValueError(f"{name}: unsupported dtype {a.dtype}")
    if a.ndim not in (1, 2) or a.shape[0] != length:
        raise ValueError(f"{name}: expected shape ({length},) or ({length}, k), got {a.shape}")
    return np.ascontiguousarray(a.astype(a.dtype.newbyteorder("<")))


def _data_array(parent: ET.Element, name: str, a: NDArray[Any], binary: bool, **attrs: str) -> None:
    el = ET.SubElement(parent, "DataArray", type=_VTK_TYPES[a.dtype.newbyteorder("=")], Name=name)
    for key, value in attrs.items():
        el.set(key, value)
    if a.ndim == 2:
        el.set("NumberOfComponents", str(a.shape[1]))
    if binary:
        el.set("format", "binary")
        raw = a.tobytes()
        el.text = base64.b64encode(np.uint64(len(raw)).astype("<u8").tobytes() + raw).decode()
    else:
        el.set("format", "ascii")
        flat = a.ravel()
        if np.issubdtype(a.dtype, np.floating):
            if np.any(np.isneginf(flat)):
                raise ValueError(f"{name}: -inf cannot be written as ASCII (VTK reads it as +inf)")
            text = " ".join(repr(float(v)) for v in flat)
        else:
            text = " ".join(str(int(v)) for v in flat)
        # VTK's ASCII parser drops a final nan / inf unless whitespace follows it
        el.text = text + "\n"


def _fill_value(a: NDArray[Any]) -> tuple[NDArray[Any], float | int]:
    """The array in a dtype that can hold the vertex-cell fill, and that fill."""
    if np.issubdtype(a.dtype, np.floating):
        return a, np.nan
    if np.issubdtype(a.dtype, np.unsignedinteger):
        a = a.astype("<i8")
    return a, -1


def write_vtp(
    path: str | os.PathLike[str],
    points: ArrayLike,
    *,
    lines: ArrayLike | None = None,
    point_data: Mapping[str, ArrayLike] | None = None,
    line_data: Mapping[str, ArrayLike] | None = None,
    field_data: Mapping[str, ArrayLike] | None = None,
    binary: bool = True,
) -> Path:
    """Write points, one vertex cell per point, and lines to a VTK XML PolyData file.

    Booleans are stored as Int32 0 / 1. Returns the path.

    Parameters
    ----------
    path : path of the ``.vtp`` file (parent folders are created).
    points : (N, 2) or (N, 3) float
        Coordinates; z = 0 when two columns are given.
    lines : (M, 2) int, optional
        Point indices of the two ends of each line.
    point_data : mapping of str to (N,) or (N, k) arrays, optional
    line_data : mapping of str to (M,) or (M, k) arrays, optional
        Stored as cell data over the N vertex cells followed by the M lines,
        with NaN (floats) or -1 (integers; unsigned become Int64) on the
        vertex cells. An Int32 ``cell_kind`` array (:data:`CELL_PARTICLE` on
        vertices, :data:`CELL_CONTACT` on lines) is always added.
    field_data : mapping of str to arrays, optional
        Whole-file values (any length, flattened to one component).
    binary : bool, default True
        Base64 raw arrays with UInt64 headers; False writes ASCII (no ``-inf``).

    Raises
    ------
    ValueError
        On a wrong shape, a line index out of range, an unsupported dtype,
        a line array named ``cell_kind`` or ``-inf`` in an ASCII file.
    """
    return _write_xml("PolyData", path, points, lines, point_data, line_data, field_data, binary)


def write_vtu(
    path: str | os.PathLike[str],
    points: ArrayLike,
    *,
    lines: ArrayLike | None = None,
    point_data: Mapping[str, ArrayLike] | None = None,
    line_data: Mapping[str, ArrayLike] | None = None,
    field_data: Mapping[str, ArrayLike] | None = None,
    binary: bool = True,
) -> Path:
    """What :func:`write_vtp` writes, as a VTK XML UnstructuredGrid (``.vtu``).

    The same points, cells (a ``VTK_VERTEX`` per point, then a ``VTK_LINE``
    per line), point, cell and field data, for readers that take unstructured
    grids but no PolyData (meshio). Parameters and errors as :func:`write_vtp`.
    """
    return _write_xml("UnstructuredGrid", path, points, lines, point_data, line_data, field_data, binary)


def write_walls_vtp(path: str | os.PathLike[str], segments: ArrayLike, *, binary: bool = True) -> Path:
    """The walls as line cells (no vertices) of a PolyData: ``segments`` (K, 2, 2) end points, m.

    The cell data are ``cell_kind`` (:data:`CELL_WALL`) and ``wall_index``
    (0 .. K-1, in the order given); the field data ``n_walls`` is K.
    """
    seg = np.asarray(segments, dtype=np.float64).reshape(-1, 2, 2)
    k = seg.shape[0]
    field: dict[str, ArrayLike] = {"n_walls": [k]}
    return _write_xml(
        "PolyData", path, seg.reshape(-1, 2), np.arange(2 * k).reshape(k, 2),
        None, {"wall_index": np.arange(k, dtype=np.int32)}, field, binary, verts=False,
    )


def clump_points(snap: Any) -> tuple[NDArray[np.float64], dict[str, NDArray[Any]]] | None:
    """The clumps of a snapshot as points: ``(centroids (C, 2), point_data)``, or None.

    One point per grain of more than one particle (a clump; :meth:`Snapshot.grains
    <grainlab.snapshot.Snapshot.grains>`), in increasing grain label, at its centroid, m.
    Point data: ``grain`` (Int64, the label), ``angle`` (rad, CCW positive),
    ``orientation`` (cos, sin, 0 of the angle: the body frame's x axis, the
    orientation array of a glyph) and ``n_pebbles`` (Int32). None when the
    snapshot has no clumps, or does not know their centroids and angles (a file
    that labels grains only).
    """
    fields = snap.particle_fields
    if "grain_centroid" not in fields or "grain_angle" not in fields:
        return None
    label, first, count = np.unique(snap.grains(), return_index=True, return_counts=True)
    clump = count > 1
    if not clump.any():
        return None
    rows = first[clump]
    angle = np.asarray(fields["grain_angle"], np.float64)[rows]
    data: dict[str, NDArray[Any]] = {
        "grain": label[clump].astype(np.int64),
        "angle": angle,
        "orientation": np.c_[np.cos(angle), np.sin(angle), np.zeros(len(rows))],
        "n_pebbles": count[clump].astype(np.int32),
    }
    return np.asarray(fields["grain_centroid"], np.float64)[rows], data


def write_clumps_vtp(path: str | os.PathLike[str], snap: Any, *, binary: bool = True) -> Path | None:
    """The clumps of ``snap`` as one vertex each at its centroid (:func:`clump_points`), with
    the field data ``n_clumps``; writes nothing and returns None when :func:`clump_points` is None."""
    clumps = clump_points(snap)
    if clumps is None:
        return None
    centroids, data = clumps
    return write_vtp(path, centroids, point_data=data, field_data={"n_clumps": [len(centroids)]}, binary=binary)


def _write_xml(
    dataset: str,
    path: str | os.PathLike[str],
    points: ArrayLike,
    lines: ArrayLike | None,
    point_data: Mapping[str, ArrayLike] | None,
    line_data: Mapping[str, ArrayLike] | None,
    field_data: Mapping[str, ArrayLike] | None,
    binary: bool,
    verts: bool = True,
) -> Path:
    pts = np.asarray(points, dtype=np.float64)
    if pts.ndim != 2 or pts.shape[1] not in (2, 3):
        raise ValueError(f"points: expected shape (N, 2) or (N, 3), got {pts.shape}")
    n = pts.shape[0]
    if pts.shape[1] == 2:
        pts = np.c_[pts, np.zeros(n)]
    seg = np.zeros((0, 2), np.int64) if lines is None else np.asarray(lines, dtype=np.int64)
    if seg.ndim != 2 or seg.shape[1] != 2:
        raise ValueError(f"lines: expected shape (M, 2), got {seg.shape}")
    if seg.size and (seg.min() < 0 or seg.max() >= n):
        raise ValueError(f"lines: point index out of range [0, {n})")
    m = seg.shape[0]
    if line_data and "cell_kind" in line_data:
        raise ValueError("line_data: 'cell_kind' is reserved for the writer")

    root = ET.Element(
        "VTKFile", type=dataset, version="1.0", byte_order="LittleEndian", header_type="UInt64"
    )
    poly = ET.SubElement(root, dataset)
    nv = n if verts else 0  # vertex cells: one per point, or none (walls)
    if field_data:
        fd = ET.SubElement(poly, "FieldData")
        for name, value in field_data.items():
            a = np.asarray(value).ravel()
            a = _prepare(name, a, a.shape[0])
            _data_array(fd, name, a, binary, NumberOfTuples=str(a.shape[0]))
    counts = (
        {"NumberOfCells": str(nv + m)}
        if dataset == "UnstructuredGrid"
        else {"NumberOfVerts": str(nv), "NumberOfLines": str(m), "NumberOfStrips": "0", "NumberOfPolys": "0"}
    )
    piece = ET.SubElement(poly, "Piece", {"NumberOfPoints": str(n), **counts})
    pd = ET.SubElement(piece, "PointData")
    for name, value in (point_data or {}).items():
        _data_array(pd, name, _prepare(name, value, n), binary)
    cd = ET.SubElement(piece, "CellData")
    kind = np.r_[np.full(nv, CELL_PARTICLE, "<i4"), np.full(m, CELL_CONTACT if verts else CELL_WALL, "<i4")]
    _data_array(cd, "cell_kind", kind, binary)
    for name, value in (line_data or {}).items():
        a, fill = _fill_value(_prepare(name, value, m))
        full = np.full((nv + m, *a.shape[1:]), fill, dtype=a.dtype)
        full[nv:] = a
        _data_array(cd, name, full, binary)
    _data_array(ET.SubElement(piece, "Points"), "Points", _prepare("points", pts, n), binary)
    if dataset == "UnstructuredGrid":
        el = ET.SubElement(piece, "Cells")
        connectivity = np.r_[np.arange(nv, dtype="<i8"), seg.ravel().astype("<i8")]
        offsets = np.r_[np.arange(1, nv + 1), nv + 2 * np.arange(1, m + 1)].astype("<i8")
        _data_array(el, "connectivity", connectivity, binary)
        _data_array(el, "offsets", offsets, binary)
        types = np.r_[np.full(nv, 1, "u1"), np.full(m, 3, "u1")]  # VTK_VERTEX, VTK_LINE
        _data_array(el, "types", types, binary)
    else:
        for tag, connectivity, size in (
            ("Verts", np.arange(nv, dtype="<i8"), 1),
            ("Lines", seg.ravel().astype("<i8"), 2),
        ):
            el = ET.SubElement(piece, tag)
            count = connectivity.shape[0] // size
            _data_array(el, "connectivity", connectivity, binary)
            _data_array(el, "offsets", size * np.arange(1, count + 1, dtype="<i8"), binary)

    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    ET.ElementTree(root).write(out, encoding="utf-8", xml_declaration=True)
    return out


def write_pvd(
    path: str | os.PathLike[str], entries: Sequence[tuple[float, str | os.PathLike[str]]]
) -> Path:
    """Write a ParaView collection of ``(time, file)`` entries; files relative to the .pvd."""
    out = Path(path)
    root = ET.Element("VTKFile", type="Collection", version="0.1", byte_order="LittleEndian")
    coll = ET.SubElement(root, "Collection")
    for time, file in entries:
        f = Path(file)
        rel = os.path.relpath(f, out.parent) if f.is_absolute() else str(f)
        ET.SubElement(
            coll,
            "DataSet",
            timestep=repr(float(time)),
            group="",
            part="0",
            file=Path(rel).as_posix(),
        )
    out.parent.mkdir(parents=True, exist_ok=True)
    ET.ElementTree(root).write(out, encoding="utf-8", xml_declaration=True)
    return out


def as_vector3(a: NDArray[Any]) -> NDArray[Any]:
    """(N, 2) vectors padded with z = 0, so that ParaView's vector filters apply."""
    if a.ndim == 2 and a.shape[1] == 2:
        return np.column_stack((a, np.zeros(a.shape[0], a.dtype)))
    return a


def exportable(a: NDArray[Any]) -> bool:
    """Whether an array can be a VTK data array: numeric or boolean, real, 1 or 2 dimensions."""
    numeric = a.dtype == np.bool_ or np.issubdtype(a.dtype, np.number)
    return numeric and not np.iscomplexobj(a) and a.ndim in (1, 2)


def contact_lines(snap: Any) -> tuple[NDArray[np.int64], dict[str, NDArray[Any]], dict[str, int]]:
    """The drawable contacts of a snapshot: ``(lines, line_data, n_left_out)``.

    ``lines`` (M, 2) holds the particle indices ``(contact_i, contact_j)`` of
    every particle–particle contact whose centres are not separated by a
    periodic boundary, in the snapshot's contact order. ``line_data`` has, for
    those contacts, ``normal_force`` and ``shear_force`` (N, only when the
    snapshot stores them) and every numeric contact field (``overlap``,
    ``sliding``, ``bonded``, ...) under its own name. ``n_left_out`` counts the
    contacts without a line: ``n_wall_contacts`` and ``n_periodic_contacts``.
    """
    ci = np.asarray(snap.contact_i, np.int64)
    cj = np.asarray(snap.contact_j, np.int64)
    wall = cj < 0
    partner = np.where(wall, ci, cj)
    d = snap.positions[partner] - snap.positions[ci]
    crosses = ~wall & np.any(snap.minimum_image(d) != d, axis=1)
    keep = ~wall & ~crosses
    data: dict[str, NDArray[Any]] = {}
    for name in ("normal_force", "shear_force"):
        value = getattr(snap, name)
        if value is not None:
            data[name] = np.asarray(value, np.float64)[keep]
    for name, value in snap.contact_fields.items():
        a = np.asarray(value)
        if name not in data and name != "cell_kind" and exportable(a):
            data[name] = as_vector3(a[keep])
    left_out = {"n_wall_contacts": int(wall.sum()), "n_periodic_contacts": int(crosses.sum())}
    return np.c_[ci[keep], cj[keep]], data, left_out
