"""ParaView export: VTK XML UnstructuredGrid (``.vtu``) files and a ``.pvd`` time series.

Each snapshot of a run becomes one ``.vtu`` file (VTK XML UnstructuredGrid,
written here by a small writer, no VTK needed):

* every particle is a point (z = 0) with a ``VTK_VERTEX`` cell, and carries the
  point data ``id``, ``radius`` (m), ``kind`` (:class:`~grainlab.snapshot.ParticleKind`
  code: 0 grain, 1 membrane, 2 boundary grain), ``velocity`` (m/s, only when the
  snapshot has a ``velocity`` particle field), ``displacement`` (m, from the first
  snapshot, matched by id; NaN for particles absent from it), ``rotation`` (rad,
  accumulated; only when the snapshot has rotations), ``n_contacts`` (all
  contacts of the particle, walls included), ``stability_index`` (lambda; NaN for
  membrane disks), ``local_shear_strain`` (:class:`~grainlab.analysis.LocalStrain`
  against the first snapshot; NaN in the first snapshot) and ``in_shear_band``
  (1 for the members of the band :class:`~grainlab.analysis.ShearBand` finds in
  the excess shear strain, else 0; all 0 in the first snapshot or when no band
  can be located);
* every particle–particle contact is a ``VTK_LINE`` cell between its two
  particles, with the cell data ``normal_force`` (N; NaN on the vertex cells).
  Wall contacts (``contact_j < 0``) have no second point and are left out.

The ``.pvd`` collection lists the files with their time value: the snapshot's
axial strain when every snapshot has one, else its time in s, else its index.
The ``.vtu`` format is used rather than ``.vtp`` so that independent readers
such as meshio can read the files back; ParaView opens both alike.
"""

from __future__ import annotations

import base64
import os
import xml.etree.ElementTree as ET
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "VTK_LINE",
    "VTK_VERTEX",
    "VtkExport",
    "export_vtk",
    "snapshot_arrays",
    "write_pvd",
    "write_vtu",
]

VTK_VERTEX = 1
VTK_LINE = 3

_VTK_TYPES = {
    np.dtype(np.float32): "Float32",
    np.dtype(np.float64): "Float64",
    np.dtype(np.int8): "Int8",
    np.dtype(np.uint8): "UInt8",
    np.dtype(np.int32): "Int32",
    np.dtype(np.int64): "Int64",
}


def _prepare(name: str, value: ArrayLike, length: int) -> NDArray[Any]:
    a = np.asarray(value)
    if a.dtype == np.bool_:
        a = a.astype(np.uint8)
    elif np.issubdtype(a.dtype, np.integer) and a.dtype not in _VTK_TYPES:
        a = a.astype(np.int64)
    elif np.issubdtype(a.dtype, np.floating) and a.dtype not in _VTK_TYPES:
        a = a.astype(np.float64)
    if a.dtype not in _VTK_TYPES:
        raise ValueError(f"{name}: unsupported dtype {a.dtype}")
    if a.ndim not in (1, 2) or a.shape[0] != length:
        raise ValueError(f"{name}: expected shape ({length},) or ({length}, k), got {a.shape}")
    return np.ascontiguousarray(a.astype(a.dtype.newbyteorder("<")))


def _data_array(parent: ET.Element, name: str, a: NDArray[Any], binary: bool) -> None:
    el = ET.SubElement(parent, "DataArray", type=_VTK_TYPES[a.dtype.newbyteorder("=")], Name=name)
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
            el.text = " ".join(repr(float(v)) for v in flat)
        else:
            el.text = " ".join(str(int(v)) for v in flat)


def write_vtu(
    path: str | os.PathLike[str],
    points: ArrayLike,
    *,
    lines: ArrayLike | None = None,
    point_data: Mapping[str, ArrayLike] | None = None,
    line_data: Mapping[str, ArrayLike] | None = None,
    binary: bool = True,
) -> Path:
    """Write points (one ``VTK_VERTEX`` cell each) and lines to a ``.vtu`` file.

    ``points`` (N, 2) or (N, 3); ``lines`` (M, 2) point indices; ``point_data``
    arrays of length N; ``line_data`` arrays of length M (stored as cell data,
    NaN / 0 on the vertex cells). ``binary`` selects base64 raw data (UInt64
    headers) over ASCII. Returns the path.
    """
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

    root = ET.Element(
        "VTKFile",
        type="UnstructuredGrid",
        version="1.0",
        byte_order="LittleEndian",
        header_type="UInt64",
    )
    piece = ET.SubElement(
        ET.SubElement(root, "UnstructuredGrid"),
        "Piece",
        NumberOfPoints=str(n),
        NumberOfCells=str(n + m),
    )
    pd = ET.SubElement(piece, "PointData")
    for name, value in (point_data or {}).items():
        _data_array(pd, name, _prepare(name, value, n), binary)
    cd = ET.SubElement(piece, "CellData")
    for name, value in (line_data or {}).items():
        a = _prepare(name, value, m)
        fill = np.nan if np.issubdtype(a.dtype, np.floating) else 0
        full = np.full((n + m, *a.shape[1:]), fill, dtype=a.dtype)
        full[n:] = a
        _data_array(cd, name, full, binary)
    _data_array(ET.SubElement(piece, "Points"), "Points", _prepare("points", pts, n), binary)
    cells = ET.SubElement(piece, "Cells")
    connectivity = np.r_[np.arange(n, dtype=np.int64), seg.ravel()]
    offsets = np.r_[np.arange(1, n + 1, dtype=np.int64), n + 2 * np.arange(1, m + 1)]
    types = np.r_[np.full(n, VTK_VERTEX, np.uint8), np.full(m, VTK_LINE, np.uint8)]
    _data_array(cells, "connectivity", connectivity.astype("<i8"), binary)
    _data_array(cells, "offsets", offsets.astype("<i8"), binary)
    _data_array(cells, "types", types, binary)

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


def snapshot_arrays(snap: Any, reference: Any | None = None) -> dict[str, NDArray[Any]]:
    """Point data of one :class:`~grainlab.snapshot.Snapshot` for the export.

    ``reference`` is the run's first snapshot (``None`` or ``snap`` itself for
    the first one): displacement, local shear strain and shear band are taken
    against it. See the module docstring for the fields.
    """
    from grainlab.analysis import LocalStrain, ShearBand, StabilityIndex, match_ids

    n = snap.n_particles
    ci, cj = np.asarray(snap.contact_i), np.asarray(snap.contact_j)
    counts = np.bincount(ci, minlength=n) + np.bincount(cj[cj >= 0], minlength=n)
    out: dict[str, NDArray[Any]] = {
        "id": np.asarray(snap.ids, np.int64),
        "radius": np.asarray(snap.radii, np.float64),
        "kind": np.asarray(snap.kind, np.int32),
    }
    velocity = snap.particle_fields.get("velocity")
    if velocity is not None:
        v = np.asarray(velocity, np.float64).reshape(n, -1)
        out["velocity"] = np.c_[v, np.zeros((n, 3 - v.shape[1]))] if v.shape[1] < 3 else v
    first = reference is None or reference is snap
    disp = np.zeros((n, 3))
    gamma = np.full(n, np.nan)
    band = np.zeros(n, np.uint8)
    if not first:
        to_ref = match_ids(reference, snap)
        ok = to_ref >= 0
        disp[:, :2] = np.nan
        disp[ok, :2] = snap.minimum_image(snap.positions[ok] - reference.positions[to_ref[ok]])
        strain = LocalStrain().compute(reference, snap)
        gamma = np.asarray(strain.shear_strain, np.float64)
        try:
            found = ShearBand().compute(snap, strain.excess_shear_strain)
            band = np.asarray(found.members, bool).astype(np.uint8)
        except ValueError:  # too few particles with a finite strain: no band
            pass
    out["displacement"] = disp
    if snap.rotations is not None:
        out["rotation"] = np.asarray(snap.rotations, np.float64)
    out["n_contacts"] = counts.astype(np.int32)
    out["stability_index"] = np.asarray(StabilityIndex().compute(snap).stability_index, float)
    out["local_shear_strain"] = gamma
    out["in_shear_band"] = band
    return out


@dataclass(frozen=True)
class VtkExport:
    """What :func:`export_vtk` wrote."""

    pvd: Path
    files: tuple[Path, ...]
    times: tuple[float, ...]
    time_quantity: str  # "axial_strain", "time" or "index"


def export_vtk(
    run: str | os.PathLike[str],
    out_dir: str | os.PathLike[str] | None = None,
    *,
    binary: bool = True,
) -> VtkExport:
    """Write one ``.vtu`` per snapshot of ``run`` (a run folder or its ``run.h5``) and a ``.pvd``.

    Files go to ``out_dir`` (default ``<run folder>/vtk``) as ``snapshot_0000.vtu``, ...
    and ``run.pvd``. Raises ValueError when the run has no snapshots.
    """
    from grainlab.io.hdf5 import read_results

    path = Path(run)
    h5 = path / "run.h5" if path.is_dir() else path
    folder = Path(out_dir) if out_dir is not None else h5.parent / "vtk"
    results = read_results(h5)
    names = list(results.snapshot_names)
    if not names:
        raise ValueError(f"{h5}: the run has no snapshots to export")
    snaps = [results.snapshot(name) for name in names]
    if all(s.axial_strain is not None for s in snaps):
        quantity, times = "axial_strain", [float(s.axial_strain) for s in snaps]
    elif all(s.time is not None for s in snaps):
        quantity, times = "time", [float(s.time) for s in snaps]
    else:
        quantity, times = "index", [float(k) for k in range(len(snaps))]
    files = []
    for k, snap in enumerate(snaps):
        pp = np.asarray(snap.contact_j) >= 0
        lines = np.c_[np.asarray(snap.contact_i)[pp], np.asarray(snap.contact_j)[pp]]
        force = (
            np.full(int(pp.sum()), np.nan)
            if snap.normal_force is None
            else np.asarray(snap.normal_force)[pp]
        )
        files.append(
            write_vtu(
                folder / f"snapshot_{k:04d}.vtu",
                snap.positions,
                lines=lines,
                point_data=snapshot_arrays(snap, snaps[0]),
                line_data={"normal_force": force},
                binary=binary,
            )
        )
    pvd = write_pvd(folder / "run.pvd", [(t, f.name) for t, f in zip(times, files, strict=True)])
    return VtkExport(pvd, tuple(files), tuple(times), quantity)
