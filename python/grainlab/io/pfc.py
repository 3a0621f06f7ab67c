"""PFC (Itasca) ball and contact tables exported as CSV, read through the CSV reader.

Columns, the ball-ball rule and the shear force's sign: docs/file-formats.md,
"Formats read from other codes".
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

from grainlab.io._table import FileFormatError, read_lines
from grainlab.io.csv import read_particles_csv
from grainlab.snapshot import Snapshot

__all__ = ["PFC_BALL_COLUMNS", "PFC_CONTACT_COLUMNS", "is_pfc_balls", "read_pfc_balls"]

#: grainlab role -> PFC column of a ball table (``z`` only when the file has ``pos_z``).
PFC_BALL_COLUMNS = {"id": "id", "x": "pos_x", "y": "pos_y", "z": "pos_z", "radius": "radius"}
#: grainlab role -> PFC column of a contact table (``normal_force`` only when present).
PFC_CONTACT_COLUMNS = {"i": "end1", "j": "end2", "normal_force": "force_normal"}
_OPTIONAL = ("z", "normal_force")


def header_names(path: str | Path) -> list[str]:
    """The lower-case column names of a CSV's first line that is not blank or a comment."""
    for text in read_lines(path):
        if text.strip() and not text.lstrip().startswith("#"):
            return [h.strip().lower() for h in text.split(",")]
    raise FileFormatError(path, None, "empty file: expected a header line")


def is_pfc_balls(names: list[str]) -> bool:
    """True for a header with PFC's ball columns ``id,pos_x,pos_y,radius``."""
    return {"id", "pos_x", "pos_y", "radius"} <= set(names)


def _mapping(path: str | Path, defaults: Mapping[str, str], given: Mapping[str, str] | None) -> dict[str, str]:
    names = header_names(path)
    out = {role: name for role, name in defaults.items() if role not in _OPTIONAL or name in names}
    out.update({role: name.strip().lower() for role, name in (given or {}).items()})
    return out


def read_pfc_balls(
    path: str | Path,
    *,
    contacts: str | Path | None = None,
    tolerance: float = 0.0,
    columns: Mapping[str, str] | None = None,
    contact_columns: Mapping[str, str] | None = None,
    z_policy: str = "refuse",
    z0: float | None = None,
) -> Snapshot:
    """Read a PFC ball table (and optionally its contact table) into a snapshot.

    ``columns`` / ``contact_columns`` override single entries of
    :data:`PFC_BALL_COLUMNS` / :data:`PFC_CONTACT_COLUMNS`. Without
    ``contacts`` the contacts are detected from the geometry (centre distance
    < r_i + r_j + ``tolerance``, m). ``z_policy`` as for the other readers
    (PFC3D tables).
    """
    ball_map = _mapping(path, PFC_BALL_COLUMNS, columns)
    contact_map = None if contacts is None else _mapping(contacts, PFC_CONTACT_COLUMNS, contact_columns)
    if contacts is None and contact_columns:
        raise ValueError("contact_columns: only apply to a contacts file (give contacts=)")
    return read_particles_csv(
        path,
        contacts=contacts,
        tolerance=tolerance,
        columns=ball_map,
        contact_columns=contact_map,
        z_policy=z_policy,
        z0=z0,
        format_name="pfc-csv",
    )
