"""3D input to a 2D snapshot: refuse it, or project or slice it when asked (readers only).

The rule and the two policies: docs/analysis.md, "Files read and written" (3D data).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from grainlab.io._table import FileFormatError
from grainlab.snapshot import Snapshot, detect_contacts

#: Largest spread of z (max - min), as a fraction of the smallest radius, read as 2D.
PLANAR_TOLERANCE = 1e-3

#: What a reader does with 3D data.
Z_POLICIES = ("refuse", "project", "slice")


def check_z_policy(z_policy: str, z0: float | None, contacts: Any = None) -> None:
    """ValueError naming ``z_policy`` / ``z0`` for a bad choice (a slice takes no
    ``contacts`` file), before any reading."""
    if z_policy not in Z_POLICIES:
        raise ValueError(f"z_policy: must be one of {', '.join(Z_POLICIES)}, got {z_policy!r}")
    if z_policy == "slice":
        if z0 is None or not np.isfinite(z0):
            raise ValueError("z0: z_policy='slice' needs the height z0 (m) of the slicing plane")
    elif z0 is not None:
        raise ValueError(f"z0: only applies to z_policy='slice', not {z_policy!r}")
    if z_policy == "slice" and contacts is not None:
        raise ValueError(
            "contacts: z_policy='slice' takes its contacts from the cross-sections; "
            "read it without a contacts file"
        )


@dataclass
class Planar:
    """What a reader keeps of its rows: ``keep`` (N,) mask, the disks' ``radii``
    (of the kept rows), ``z`` (kept rows, None for 2D data) and metadata."""

    keep: NDArray[np.bool_]
    radii: NDArray[np.float64]
    z: NDArray[np.float64] | None
    metadata: dict[str, Any] = field(default_factory=dict)

    @property
    def spheres(self) -> bool:
        """True when contacts must be those of the 3D spheres (projection)."""
        return self.metadata.get("z_policy") == "project"


def planar(
    path: str | Path,
    line: int | None,
    z: NDArray[np.float64] | None,
    radii: NDArray[np.float64],
    *,
    z_policy: str = "refuse",
    z0: float | None = None,
    column: str = "z",
) -> Planar:
    """Apply ``z_policy`` to rows with z coordinates ``z`` (None: no z column)."""
    n = radii.shape[0]
    if z is None:
        if z_policy != "refuse":
            raise FileFormatError(path, line, f"z_policy={z_policy!r}: the file has no z column")
        return Planar(np.ones(n, bool), radii, None)
    spread = float(z.max() - z.min())
    smallest = float(radii.min())
    if z_policy == "refuse":
        if spread > PLANAR_TOLERANCE * smallest:
            raise FileFormatError(
                path,
                line,
                f"3D data: column {column!r} spreads over {spread:.6g} m ({spread / smallest:.3g} times the "
                f"smallest radius, more than {PLANAR_TOLERANCE:g} for a 2D snapshot); read it with "
                "z_policy='project' (disks of the spheres' radii, sphere contacts) or z_policy='slice' "
                "with z0 (the cross-sections with the plane z = z0)",
            )
        return Planar(np.ones(n, bool), radii, None)
    meta: dict[str, Any] = {"z_policy": z_policy, "z_spread_m": spread}
    if z_policy == "project":
        return Planar(np.ones(n, bool), radii, z, meta)
    assert z0 is not None  # check_z_policy ran before any reading
    h = z - float(z0)
    keep = np.abs(h) < radii
    if not keep.any():
        raise FileFormatError(
            path, line, f"z_policy='slice': no sphere crosses the plane z = {z0:g} m (z from {z.min():g} to {z.max():g} m)"
        )
    meta["z0_m"] = float(z0)
    return Planar(keep, np.sqrt(radii[keep] ** 2 - h[keep] ** 2), z[keep], meta)


def sphere_contacts(
    path: str | Path,
    positions: NDArray[np.float64],
    z: NDArray[np.float64],
    radii: NDArray[np.float64],
    ids: NDArray[np.int64],
    *,
    tolerance: float,
    box: NDArray[np.float64] | None,
    periodic: tuple[bool, bool],
) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.float64]]:
    """Contacts of the spheres (3D centre distance < r_i + r_j + tolerance) and
    the in-plane unit normal of each; an error when a centre line is vertical."""
    i, j = detect_contacts(np.c_[positions, z], radii, tolerance=tolerance, box=box, periodic=periodic)
    d = positions[j] - positions[i]
    if box is not None:
        lengths = box[:, 1] - box[:, 0]
        for axis in (0, 1):
            if periodic[axis]:
                d[:, axis] -= lengths[axis] * np.round(d[:, axis] / lengths[axis])
    length = np.hypot(d[:, 0], d[:, 1])
    flat = length <= 1e-9 * (radii[i] + radii[j])
    if flat.any():
        k = int(np.argmax(flat))
        raise FileFormatError(
            path,
            None,
            f"z_policy='project': the spheres with ids {int(ids[i[k]])} and {int(ids[j[k]])} touch one "
            "above the other: their contact has no direction in the plane",
        )
    return i, j, d / length[:, None]


def keep_planar_rows(
    plan: Planar, positions: NDArray[np.float64], radii: NDArray[np.float64], kwargs: dict[str, Any], *,
    z_field: bool,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """A reader's positions and radii as ``plan`` keeps them: with 3D data read as
    asked, the chosen rows, and in ``kwargs`` (the Snapshot's) the same rows of
    ``ids``, ``kind``, ``rotations`` and every particle field (``z`` added as a field
    when ``z_field``) and the plan's metadata; else as they are."""
    if plan.z is None:
        return positions, radii
    keep = plan.keep
    for key in ("ids", "kind", "rotations"):
        if kwargs.get(key) is not None:
            kwargs[key] = kwargs[key][keep]
    fields = {name: values[keep] for name, values in kwargs["particle_fields"].items()}
    kwargs["particle_fields"] = fields | {"z": plan.z} if z_field else fields
    kwargs["metadata"].update(plan.metadata)
    return positions[keep], plan.radii


def detected_snapshot(
    path: str | Path, plan: Planar, positions: NDArray[np.float64], radii: NDArray[np.float64],
    kwargs: dict[str, Any], *, detect: bool, tolerance: float,
) -> Snapshot:
    """A reader's snapshot with its contacts detected: between the spheres in 3D
    for projected 3D data, else in the plane; none when not ``detect``."""
    if detect and plan.spheres and plan.z is not None:
        i, j, normals = sphere_contacts(
            path, positions, plan.z, radii, kwargs["ids"], tolerance=tolerance,
            box=kwargs.get("box"), periodic=kwargs.get("periodic", (False, False)),
        )  # fmt: skip
        kwargs["metadata"]["contacts"] = f"detected between the spheres in 3D (tolerance {tolerance:g} m)"
        return Snapshot(positions, radii, contact_i=i, contact_j=j, contact_normal=normals, **kwargs)
    if detect:
        return Snapshot.from_geometry(positions, radii, tolerance=tolerance, **kwargs)
    return Snapshot(positions, radii, **kwargs)
