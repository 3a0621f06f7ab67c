"""Reading and writing snapshots: particles CSV, LAMMPS/LIGGGHTS dumps.

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
    read_contacts_csv,
    read_particles_csv,
    write_contacts_csv,
    write_particles_csv,
)
from grainlab.io.hdf5 import read_hdf5_snapshot
from grainlab.io.lammps_dump import list_timesteps, read_lammps_dump
from grainlab.snapshot import Snapshot

__all__ = [
    "READERS",
    "FileFormatError",
    "detect_format",
    "list_timesteps",
    "read_contacts_csv",
    "read_lammps_dump",
    "read_particles_csv",
    "read_snapshot",
    "write_contacts_csv",
    "write_particles_csv",
]

_HDF5_MAGIC = b"\x89HDF\r\n\x1a\n"


def detect_format(path: str | Path) -> str:
    """``"particles-csv"``, ``"lammps-dump"`` or ``"grainlab-hdf5"``, from the file's content.

    HDF5 by its signature; a LAMMPS dump by a first line ``ITEM: TIMESTEP``;
    a particles CSV by a header with the columns ``id,x,y,radius``.
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
    lines = [
        ln.strip() for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")
    ]
    if not lines:
        raise FileFormatError(p, None, "empty file: cannot tell its format")
    if lines[0].startswith("ITEM: TIMESTEP"):
        return "lammps-dump"
    header = {h.strip().lower() for h in lines[0].split(",")}
    if {"id", "x", "y", "radius"} <= header:
        return "particles-csv"
    raise FileFormatError(
        p,
        None,
        "unknown format: expected a particles CSV (header id,x,y,radius) or a LAMMPS dump "
        f"(first line 'ITEM: TIMESTEP'); the first line is {lines[0][:60]!r}",
    )


def _read_csv(
    path: Path, *, contacts=None, timestep=None, tolerance=0.0, columns=None, boundary_types=()
) -> Snapshot:
    if timestep is not None:
        raise ValueError("timestep: only applies to LAMMPS dumps, not to a particles CSV")
    if columns:
        raise ValueError("contact columns: only apply to LAMMPS local dumps")
    if len(boundary_types):
        raise ValueError(
            "boundary types: only apply to LAMMPS dumps (use a 'kind' column in a CSV)"
        )
    return read_particles_csv(path, contacts=contacts, tolerance=tolerance)


def _read_dump(
    path: Path, *, contacts=None, timestep=None, tolerance=0.0, columns=None, boundary_types=()
) -> Snapshot:
    return read_lammps_dump(
        path,
        timestep=timestep,
        contacts=contacts,
        columns=columns,
        tolerance=tolerance,
        boundary_types=boundary_types,
    )


#: Reader per format name:
#: ``reader(path, *, contacts, timestep, tolerance, columns, boundary_types) -> Snapshot``.
READERS: dict[str, Callable[..., Snapshot]] = {
    "particles-csv": _read_csv,
    "lammps-dump": _read_dump,
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
) -> Snapshot:
    """Read a snapshot from any supported file.

    Parameters
    ----------
    path
        Particles CSV, LAMMPS atoms dump or grainlab results file ``run.h5``
        (format detected, or ``format``).
    contacts
        Contacts file: a contacts CSV for a particles CSV, a ``dump local``
        file for a LAMMPS dump. Without it contacts are detected from the
        geometry (centre distance < r_i + r_j + ``tolerance``, m).
    timestep
        Frame of a multi-frame dump (default the last); for ``run.h5`` the
        snapshot recorded at that engine step.
    columns
        Column roles of a LAMMPS local dump (see :mod:`grainlab.io.lammps_dump`).
    boundary_types
        LAMMPS atom types that bound the sample (wall disks): kind MEMBRANE.
    snapshot
        Snapshot of a grainlab results file ``run.h5``, by name
        (``"strain_0.0150"``) or position (``-1`` the last, the default);
        ``timestep`` selects one by its engine step instead.
    """
    p = Path(path)
    fmt = format or detect_format(p)
    if fmt not in READERS:
        raise ValueError(f"format: unknown {fmt!r} (known: {', '.join(READERS)})")
    if snapshot is not None and fmt != "grainlab-hdf5":
        raise ValueError(f"snapshot: only applies to grainlab HDF5 results files, not a {fmt}")
    extra: dict[str, Any] = {} if snapshot is None else {"snapshot": snapshot}
    return READERS[fmt](
        p,
        contacts=contacts,
        timestep=timestep,
        tolerance=tolerance,
        columns=columns,
        boundary_types=boundary_types,
        **extra,
    )
