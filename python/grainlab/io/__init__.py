"""Reading and writing snapshots: particles CSV, LAMMPS/LIGGGHTS dumps, PFC, YADE, legacy VTK.

:func:`read_snapshot` recognises the format of a file from its content and
dispatches to the reader registered for it in :data:`READERS`; grainlab's
HDF5 results files (``run.h5``) are read by :mod:`grainlab.io.hdf5`.

All readers raise :class:`FileFormatError` (a ``ValueError``) whose message
names the file, the line and the problem.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

from grainlab.io._table import FileFormatError
from grainlab.io.csv import (
    MissingKindWarning,
    read_contacts_csv,
    read_particles_csv,
    write_contacts_csv,
    write_particles_csv,
)
from grainlab.io.hdf5 import read_hdf5_snapshot
from grainlab.io.lammps_dump import list_timesteps, read_lammps_dump
from grainlab.io.pfc import is_pfc_balls, read_pfc_balls
from grainlab.io.vtk_read import is_legacy_vtk, read_legacy_vtk
from grainlab.io.yade import read_yade_text
from grainlab.snapshot import Snapshot

__all__ = [
    "READERS",
    "FileFormatError",
    "MissingKindWarning",
    "detect_format",
    "list_timesteps",
    "read_contacts_csv",
    "read_lammps_dump",
    "read_legacy_vtk",
    "read_particles_csv",
    "read_pfc_balls",
    "read_snapshot",
    "read_yade_text",
    "write_contacts_csv",
    "write_particles_csv",
]

_HDF5_MAGIC = b"\x89HDF\r\n\x1a\n"


def detect_format(path: str | Path) -> str:
    """The format name of a file (a key of :data:`READERS`), from its content.

    ``"grainlab-hdf5"`` by the HDF5 signature; ``"legacy-vtk"`` by a first
    line ``# vtk DataFile Version``; ``"yade-text"`` by a first line
    ``#format NAME``; ``"lammps-dump"`` by a first line ``ITEM: TIMESTEP``;
    ``"particles-csv"`` by a header with the columns ``id,x,y,radius``;
    ``"pfc-csv"`` by one with ``id,pos_x,pos_y,radius``. A CSV with other
    names is read as a particles CSV with a column mapping
    (``read_snapshot(..., particle_columns=...)``).
    """
    p = Path(path)
    try:
        with p.open("rb") as fh:
            head = fh.read(4096)
    except FileNotFoundError:
        raise FileFormatError(p, None, "file not found") from None
    except IsADirectoryError:
        raise FileFormatError(p, None, "is a directory, not a file") from None
    if head.startswith(_HDF5_MAGIC):
        return "grainlab-hdf5"
    text = head.decode("utf-8", errors="replace").removeprefix("\ufeff")  # a spreadsheet's byte-order mark
    first = text.lstrip().split("\n", 1)[0]
    if is_legacy_vtk(first):
        return "legacy-vtk"
    if first.startswith("#format"):
        return "yade-text"
    lines = [
        ln.strip() for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")
    ]
    if not lines:
        raise FileFormatError(p, None, "empty file: cannot tell its format")
    # a dump written with `dump_modify ... time yes` opens each frame with ITEM: TIME
    if lines[0].startswith("ITEM: TIMESTEP") or lines[0].startswith("ITEM: TIME"):
        return "lammps-dump"
    header = {h.strip().lower() for h in lines[0].split(",")}
    if {"id", "x", "y", "radius"} <= header:
        return "particles-csv"
    if is_pfc_balls(sorted(header)):
        return "pfc-csv"
    raise FileFormatError(
        p,
        None,
        "unknown format: expected a particles CSV (header id,x,y,radius; other names with a "
        "column mapping, --columns id=ID,x=pos_x,...), a PFC ball table (id,pos_x,pos_y,radius), "
        "a LAMMPS dump (first line 'ITEM: TIMESTEP' or 'ITEM: TIME'), a YADE text export (first line '#format "
        f"x_y_z_r') or a legacy VTK file; the first line is {lines[0][:60]!r}",
    )


# the keywords every reader below takes (read_snapshot passes them on)
_PathOrNone = str | Path | None
_Columns = Mapping[str, str] | None


def _reader(fmt: str, read: Callable[..., Snapshot], *, alone: bool = False) -> Callable[..., Snapshot]:
    """The :data:`READERS` entry of a particles table (CSV, PFC) read by ``read``, or
    with ``alone`` of a file read alone, its contacts detected from the geometry
    (YADE, legacy VTK): ``read(path, tolerance, boundary_types)``."""

    def reader(
        path: Path, *, contacts: _PathOrNone = None, timestep: int | None = None,
        tolerance: float = 0.0, columns: _Columns = None, boundary_types: Sequence[int] = (),
        particle_columns: _Columns = None,
    ) -> Snapshot:
        if timestep is not None:
            raise ValueError(f"timestep: only applies to LAMMPS dumps and run.h5, not to a {fmt}")
        if not alone:
            if len(boundary_types):
                raise ValueError(
                    "boundary types: only apply to LAMMPS dumps and VTK files (use a 'kind' column)"
                )
            return read(path, contacts=contacts, tolerance=tolerance, columns=particle_columns,
                        contact_columns=columns)
        for name, value in (("contacts", contacts), ("contact columns", columns),
                            ("particle columns", particle_columns)):
            if value:
                raise ValueError(
                    f"{name}: a {fmt} is read alone (its contacts are detected from the geometry)"
                )
        return read(path, tolerance, boundary_types)

    return reader


def _yade(path: Path, tolerance: float, boundary_types: Sequence[int]) -> Snapshot:
    if len(boundary_types):
        raise ValueError("boundary types: a YADE file has no atom types (read_yade_text(boundary_materials=...))")
    return read_yade_text(path, tolerance=tolerance)


def _read_dump(
    path: Path, *, contacts: _PathOrNone = None, timestep: int | None = None, tolerance: float = 0.0,
    columns: _Columns = None, boundary_types: Sequence[int] = (), particle_columns: _Columns = None,
    grain_column: str | None = None,
) -> Snapshot:
    if particle_columns:
        raise ValueError("particle columns: only apply to CSV files (a LAMMPS dump names its columns)")
    return read_lammps_dump(
        path,
        timestep=timestep,
        contacts=contacts,
        columns=columns,
        tolerance=tolerance,
        boundary_types=boundary_types,
        grain_column=grain_column,
    )


#: Reader per format name: ``reader(path, *, contacts, timestep, tolerance, columns,
#: boundary_types, particle_columns) -> Snapshot``.
READERS: dict[str, Callable[..., Snapshot]] = {
    "particles-csv": _reader("particles CSV", read_particles_csv),
    "pfc-csv": _reader("PFC ball table", read_pfc_balls),
    "lammps-dump": _read_dump,
    "yade-text": _reader("YADE text export", _yade, alone=True),
    "legacy-vtk": _reader(
        "legacy VTK file",
        lambda path, tol, types: read_legacy_vtk(path, tolerance=tol, boundary_types=types),
        alone=True,
    ),
    "grainlab-hdf5": read_hdf5_snapshot,
}


def read_snapshot(
    path: str | Path,
    *,
    contacts: str | Path | None = None,
    timestep: int | None = None,
    tolerance: float = 0.0,
    columns: Mapping[str, str] | None = None,
    boundary_types: Sequence[int] = (),
    format: str | None = None,
    snapshot: str | int | None = None,
    particle_columns: Mapping[str, str] | None = None,
    grain_column: str | None = None,
) -> Snapshot:
    """Read a snapshot from any supported file.

    Parameters
    ----------
    path
        Particles CSV, PFC ball table, LAMMPS atoms dump, YADE text export,
        legacy VTK particle file (LIGGGHTS / LAMMPS) or grainlab results file
        ``run.h5`` (format detected, or ``format``, a key of :data:`READERS`).
    contacts
        Contacts file: a contacts CSV for a particles CSV or PFC table, a
        ``dump local`` file for a LAMMPS dump. Without it contacts are
        detected from the geometry (centre distance < r_i + r_j +
        ``tolerance``, m).
    timestep
        Frame of a multi-frame dump (default the last); for ``run.h5`` the
        snapshot recorded at that engine step.
    columns
        Column roles of the contacts file: of a LAMMPS local dump (see
        :mod:`grainlab.io.lammps_dump`) or a contacts CSV (``{"i": "end1",
        "j": "end2"}``, :data:`grainlab.io.csv.CONTACT_ROLES`).
    particle_columns
        Column roles of a particles CSV or PFC table, ``{role: file
        column}`` (``{"id": "ID", "x": "pos_x", "y": "pos_y", "radius":
        "radius"}``, :data:`grainlab.io.csv.PARTICLE_ROLES`); a CSV with
        other names is read as a particles CSV when this is given.
    boundary_types
        LAMMPS atom types that bound the sample (wall disks): kind MEMBRANE.
    grain_column
        The column of a LAMMPS dump that says which rigid body each atom is a
        pebble of (``"mol"``; :func:`grainlab.io.lammps_dump.read_lammps_dump`).
    snapshot
        Snapshot of a grainlab results file ``run.h5``, by name
        (``"strain_0.0150"``) or position (``-1`` the last, the default);
        ``timestep`` selects one by its engine step instead.
    """
    p = Path(path)
    if format is None and particle_columns:
        try:
            fmt = detect_format(p)
        except FileFormatError as error:  # a CSV whose names only the mapping explains
            if "unknown format" not in error.problem:
                raise
            fmt = "particles-csv"
    else:
        fmt = format or detect_format(p)
    if fmt not in READERS:
        raise ValueError(f"format: unknown {fmt!r} (known: {', '.join(READERS)})")
    if snapshot is not None and fmt != "grainlab-hdf5":
        raise ValueError(f"snapshot: only applies to grainlab HDF5 results files, not a {fmt}")
    extra: dict[str, Any] = {} if snapshot is None else {"snapshot": snapshot}
    if grain_column is not None:
        if fmt != "lammps-dump":
            raise ValueError(f"grain column: only applies to LAMMPS dumps, not a {fmt}")
        extra["grain_column"] = grain_column
    if particle_columns:
        if fmt == "grainlab-hdf5":
            raise ValueError("particle columns: only apply to CSV files, not to a grainlab results file")
        extra["particle_columns"] = particle_columns
    return READERS[fmt](
        p,
        contacts=contacts,
        timestep=timestep,
        tolerance=tolerance,
        columns=columns,
        boundary_types=boundary_types,
        **extra,
    )
