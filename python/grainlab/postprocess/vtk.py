"""ParaView export of a run: one ``.vtp`` per snapshot and a ``.pvd`` time series
(docs/file-formats.md, "ParaView").
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from grainlab.analysis import LocalStrain, StabilityIndex, match_ids
from grainlab.io.hdf5 import read_results
from grainlab.io.vtk import (
    as_vector3,
    contact_lines,
    exportable,
    write_clumps_vtp,
    write_pvd,
    write_vtp,
    write_vtu,
    write_walls_vtp,
)
from grainlab.postprocess.band import band_labels

__all__ = ["VtkExport", "export_vtk", "snapshot_arrays"]


def snapshot_arrays(snap: Any, reference: Any | None = None) -> dict[str, NDArray[Any]]:
    """Point data of one :class:`~grainlab.snapshot.Snapshot` for the export, in the
    order and units of docs/file-formats.md, "ParaView"; ``reference`` is the run's first
    snapshot (``None`` or ``snap`` itself for the first one), which displacement, local
    shear strain and shear band are taken against. A particle field whose name is
    already taken is left out.
    """
    n = snap.n_particles
    out: dict[str, NDArray[Any]] = {
        "id": np.asarray(snap.ids, np.int64),
        "kind": np.asarray(snap.kind, np.int32),
        "radius": np.asarray(snap.radii, np.float64),
    }
    disp = np.zeros((n, 3))
    gamma = np.full(n, np.nan)
    band = np.zeros(n, np.int32)
    if reference is not None and reference is not snap:
        to_ref = match_ids(reference, snap)
        ok = to_ref >= 0
        disp[:, :2] = np.nan
        disp[ok, :2] = snap.minimum_image(snap.positions[ok] - reference.positions[to_ref[ok]])
        strain = LocalStrain().compute(reference, snap)
        gamma = np.asarray(strain.shear_strain, np.float64)
        # the bands the biaxial figures outline (grains away from the boundary,
        # with the figures' acceptance tests): 1 dominant, 2 conjugate
        try:
            band = band_labels(reference, snap)
        except ValueError:  # too few grains with a local strain: no band
            pass
    out["displacement"] = disp
    if snap.rotations is not None:
        out["rotation"] = np.asarray(snap.rotations, np.float64)
    out["n_contacts"] = snap.contact_counts().astype(np.int32)
    out["stability_index"] = np.asarray(StabilityIndex().compute(snap).stability_index, float)
    out["local_shear_strain"] = gamma
    out["in_shear_band"] = band
    for name, value in snap.particle_fields.items():
        a = np.asarray(value)
        if name not in out and exportable(a):
            out[name] = as_vector3(a)
    return out


def _time_axis(snaps: Sequence[Any]) -> tuple[str, list[float]]:
    for quantity in ("axial_strain", "time"):
        values = [getattr(s, quantity) for s in snaps]
        if all(v is not None for v in values):
            t = np.asarray(values, np.float64)
            if np.all(np.diff(t) > 0):
                return quantity, [float(v) for v in t]
    return "index", [float(k) for k in range(len(snaps))]


@dataclass(frozen=True)
class VtkExport:
    """What :func:`export_vtk` wrote."""

    pvd: Path
    files: tuple[Path, ...]
    times: tuple[float, ...]
    time_quantity: str  # "axial_strain", "time" or "index"
    #: The same snapshots as UnstructuredGrid files (``snapshot_0000.vtu``, ...), for meshio.
    vtu_files: tuple[Path, ...] = ()
    #: The walls of each snapshot that stores them (``walls_0000.vtp``, ...) and their ``walls.pvd``.
    wall_files: tuple[Path, ...] = ()
    walls_pvd: Path | None = None
    #: The clumps of each snapshot that has them (``clumps_0000.vtp``, ...) and their ``clumps.pvd``.
    clump_files: tuple[Path, ...] = ()
    clumps_pvd: Path | None = None


def export_vtk(
    run: str | os.PathLike[str],
    out_dir: str | os.PathLike[str] | None = None,
    *,
    binary: bool = True,
) -> VtkExport:
    """Write one ``.vtp`` per snapshot of ``run`` (a run folder or its ``run.h5``) and a ``.pvd``.

    Into ``out_dir`` (default ``<run folder>/vtk``): the files of docs/file-formats.md,
    "ParaView" (``.vtu`` twins, walls and clumps when the run has them). Raises
    ValueError when the run has no snapshots.
    """
    path = Path(run)
    h5 = path / "run.h5" if path.is_dir() else path
    folder = Path(out_dir) if out_dir is not None else h5.parent / "vtk"
    results = read_results(h5)
    names = list(results.snapshot_names)
    if not names:
        raise ValueError(f"{h5}: the run has no snapshots to export")
    snaps = [results.snapshot(name) for name in names]
    quantity, times = _time_axis(snaps)
    files, grids, walls_written, clumps_written = [], [], [], []
    for k, (name, snap) in enumerate(zip(names, snaps, strict=True)):
        lines, line_data, left_out = contact_lines(snap)
        field_data: dict[str, ArrayLike] = {
            name: [getattr(snap, name)]
            for name in ("axial_strain", "time")
            if getattr(snap, name) is not None
        }
        field_data.update({name: [count] for name, count in left_out.items()})
        content: dict[str, Any] = dict(
            lines=lines,
            point_data=snapshot_arrays(snap, snaps[0]),
            line_data=line_data,
            field_data=field_data,
            binary=binary,
        )
        files.append(write_vtp(folder / f"snapshot_{k:04d}.vtp", snap.positions, **content))
        grids.append(write_vtu(folder / f"snapshot_{k:04d}.vtu", snap.positions, **content))
        walls = results.walls(name)
        if walls is not None:
            r = np.asarray(snap.radii)[:, None]
            extent = np.array([(snap.positions - r).min(axis=0), (snap.positions + r).max(axis=0)])
            segments = walls.segments(extent)
            walls_written.append((times[k], write_walls_vtp(folder / f"walls_{k:04d}.vtp", segments, binary=binary)))
        clumps = write_clumps_vtp(folder / f"clumps_{k:04d}.vtp", snap, binary=binary)
        if clumps is not None:
            clumps_written.append((times[k], clumps))
    pvd = write_pvd(folder / "run.pvd", [(t, f.name) for t, f in zip(times, files, strict=True)])
    return VtkExport(
        pvd, tuple(files), tuple(times), quantity, tuple(grids), tuple(f for _, f in walls_written),
        _collection(folder / "walls.pvd", walls_written), tuple(f for _, f in clumps_written),
        _collection(folder / "clumps.pvd", clumps_written),
    )


def _collection(pvd: Path, written: Sequence[tuple[float, Path]]) -> Path | None:
    """The ``.pvd`` of the files ``written`` (time, file), or None without any."""
    return write_pvd(pvd, [(t, f.name) for t, f in written]) if written else None
