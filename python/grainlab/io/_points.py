"""A snapshot from parsed point rows: the part every point-table reader shares (readers only)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from grainlab.io._planar import detected_snapshot, planar
from grainlab.io._table import (
    FileFormatError,
    check_geometry,
    check_unique_ids,
    integral_column,
    plain,
    refuse_first,
)
from grainlab.snapshot import ParticleKind, Snapshot


def boundary_kind(codes: NDArray[Any], boundary: Any) -> NDArray[np.int8]:
    """Kind MEMBRANE where ``codes`` (atom types, material ids) is one of ``boundary``, else SOIL."""
    bounding = np.isin(codes, np.asarray(list(boundary), dtype=np.float64))
    return np.where(bounding, ParticleKind.MEMBRANE, ParticleKind.SOIL).astype(np.int8)


def pair_indices(
    path: str | Path,
    snapshot: Snapshot,
    ids: tuple[NDArray[np.int64], NDArray[np.int64]],
    columns: tuple[str, str],
    line_numbers: NDArray[np.int64],
    what: str,
    itself: str,
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """The snapshot's indices of the pairs of ``what`` ids (``"particle"``, ``"atom"``) a
    contacts file lists in ``columns``; an unknown id or one paired with itself (``itself``
    says how) is refused, naming the line."""
    i, j = snapshot.index_of(ids[0]), snapshot.index_of(ids[1])
    for index, values, name in ((i, ids[0], columns[0]), (j, ids[1], columns[1])):
        refuse_first(  # the message is made at once: the loop's names are current
            path, index < 0, line_numbers,
            lambda k: f"column {name!r}: unknown {what} id {int(values[k])}",  # noqa: B023
        )
    refuse_first(path, i == j, line_numbers, lambda k: f"{what} id {int(ids[0][k])} {itself}")
    return i, j


def snapshot_from_points(
    path: str | Path,
    line_numbers: NDArray[np.int64],
    positions: NDArray[np.float64],
    z: NDArray[np.float64] | None,
    radii: NDArray[np.float64],
    id_column: NDArray[np.float64] | None,
    *,
    kind: NDArray[np.int8] | None,
    fields: dict[str, NDArray[Any]],
    metadata: dict[str, Any],
    tolerance: float,
    z_policy: str,
    z0: float | None,
) -> Snapshot:
    """Check the rows, apply ``z_policy`` and detect the contacts from the geometry.

    ``line_numbers`` name the file line of each row in errors (``None``
    entries are not allowed: pass the first data line for files without rows
    per particle). ``id_column`` is the file's id column (whole numbers), None for
    0..N-1; ``kind`` None means every particle a grain.
    """
    if radii.shape[0] == 0:
        raise FileFormatError(path, None, "no particles in the file")
    ids = (np.arange(radii.shape[0], dtype=np.int64) if id_column is None
           else integral_column(path, id_column, line_numbers, "id"))
    check_unique_ids(path, ids, line_numbers)
    refuse_first(path, ~(radii > 0), line_numbers, lambda k: f"radius {plain(radii[k])} is not > 0")
    if not (0 <= tolerance < np.inf):
        raise ValueError(f"tolerance: must be a finite value >= 0 m, got {tolerance}")
    plan = planar(path, None, z, radii, z_policy=z_policy, z0=z0)
    keep = plan.keep
    check_geometry(path, positions[keep], plan.radii, line_numbers[keep])
    positions, ids = positions[keep], ids[keep]
    kind = None if kind is None else kind[keep]
    fields = {name: value[keep] for name, value in fields.items()}
    metadata = {**metadata, **plan.metadata}
    kwargs: dict[str, Any] = dict(ids=ids, kind=kind, particle_fields=fields, metadata=metadata)
    return detected_snapshot(path, plan, positions, plan.radii, kwargs, detect=True, tolerance=tolerance)
