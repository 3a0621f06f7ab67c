"""One snapshot as an HDF5 group (``/snapshots/<name>`` of a results file): written, read,
and described without loading it (:class:`SnapshotInfo`); the layouts of versions 1-3:
docs/file-formats.md.
"""

from __future__ import annotations

import dataclasses
import json
import math
import re
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import h5py
import numpy as np
from numpy.typing import ArrayLike, NDArray

from grainlab.io.hdf5._layout import _check_name, _dumps, _read_text, _write_text
from grainlab.io.hdf5.errors import ResultsFileError
from grainlab.snapshot import GRAIN_ANGLE_FIELD, GRAIN_CENTROID_FIELD, GRAIN_FIELD, Snapshot

__all__ = ["SnapshotInfo", "snapshot_name", "snapshot_strain"]

# Units of the snapshot datasets and of well-known per-particle / per-contact fields.
_SNAPSHOT_UNITS = {
    "positions": "m",
    "radii": "m",
    "ids": "",
    "rotations": "rad",
    "kind": "",
    "contact_i": "",
    "contact_j": "",
    "normal_force": "N",
    "shear_force": "N",
    "contact_normal": "",
    "contact_point": "m",
    "box": "m",
}
_FIELD_UNITS = {
    "overlap": "m",
    "velocity": "m/s",
    "force": "N",
    "angular_velocity": "rad/s",
    "torque": "N m",
    "displacement": "m",
}


def snapshot_name(axial_strain: float, *, digits: int = 4, prefix: str = "strain") -> str:
    """A stable snapshot name from an axial strain (a fraction, not percent).

    ``f"{prefix}_{axial_strain:.{digits}f}"``, with ``-0`` written as ``0``.
    Two strains that round to the same name give the same name, which
    :meth:`ResultsWriter.write_snapshot` refuses unless ``overwrite=True``.

    >>> snapshot_name(0.005), snapshot_name(0.015), snapshot_name(0.1)
    ('strain_0.0050', 'strain_0.0150', 'strain_0.1000')
    >>> snapshot_name(-1e-9), snapshot_name(0.00705, digits=5)
    ('strain_0.0000', 'strain_0.00705')
    """
    value = float(axial_strain)
    if not math.isfinite(value):
        raise ValueError(f"axial_strain: must be finite, got {value!r}")
    if not 0 <= int(digits) <= 12:
        raise ValueError(f"digits: must be in 0..12, got {digits!r}")
    text = f"{value:.{int(digits)}f}"
    if text.startswith("-") and float(text) == 0.0:
        text = text[1:]
    return f"{prefix}_{text}"


# ------------------------------------------------------------------ snapshot <-> group
def _write_array(
    group: h5py.Group,
    name: str,
    data: ArrayLike,
    *,
    units: str | None,
    compression: str | None,
    where: str,
) -> None:
    a = np.asarray(data)
    if a.dtype.kind not in "biuf":
        raise ValueError(f"{where}: cannot store dtype {a.dtype} (numbers or booleans only)")
    kwargs: dict[str, Any] = {}
    if compression and a.size:
        kwargs.update(compression=compression, shuffle=True)
    ds = group.create_dataset(name, data=a, **kwargs)
    if units is not None:
        ds.attrs["units"] = units


#: Attributes of a snapshot group that a scalar may not be named as.
_RESERVED_ATTRS = frozenset({"n_particles", "n_contacts", "periodic", "tilt", "time", "step", "scalars", "index"})


def _scalars(attrs: Any) -> dict[str, float]:
    """A snapshot group's scalars: those its ``scalars`` attribute names, or (files written
    before snapshots had scalars) its ``axial_strain`` attribute."""
    if "scalars" in attrs:
        names = [n.decode() if isinstance(n, bytes) else str(n) for n in np.atleast_1d(attrs["scalars"])]
    else:
        names = ["axial_strain"] if "axial_strain" in attrs else []
    return {name: float(attrs[name]) for name in names}


def _write_snapshot_group(
    group: h5py.Group, snapshot: Snapshot, *, compression: str | None, step: int | None
) -> None:
    def put(name: str, value: ArrayLike | None) -> None:
        if value is not None:
            _write_array(
                group,
                name,
                value,
                units=_SNAPSHOT_UNITS[name],
                compression=compression,
                where=f"snapshot.{name}",
            )

    metadata = _dumps(dict(snapshot.metadata), "snapshot.metadata")
    for name in ("positions", "radii", "ids", "rotations", "kind", "contact_i", "contact_j"):
        put(name, getattr(snapshot, name))
    for name in ("normal_force", "shear_force", "contact_normal", "contact_point", "box"):
        put(name, getattr(snapshot, name))
    for owner in ("contact_fields", "particle_fields"):
        sub = group.create_group(owner, track_order=True)
        for key, value in getattr(snapshot, owner).items():
            if owner == "particle_fields" and key in _GRAIN_FIELDS:
                continue  # one row per grain, in the grain datasets below
            _check_name(f"snapshot.{owner}", key)
            _write_array(
                sub,
                key,
                value,
                units=_FIELD_UNITS.get(key),
                compression=compression,
                where=f"snapshot.{owner}[{key!r}]",
            )
    _write_grains(group, snapshot.particle_fields, compression)
    _write_text(group, "metadata", metadata)
    group.attrs["n_particles"] = np.int64(snapshot.n_particles)
    group.attrs["n_contacts"] = np.int64(snapshot.n_contacts)
    group.attrs["periodic"] = np.array(snapshot.periodic, dtype=np.int8)
    if snapshot.tilt != 0.0:  # a leaning periodic cell (absent: a rectangle)
        group.attrs["tilt"] = np.float64(snapshot.tilt)
    if snapshot.time is not None:
        group.attrs["time"] = np.float64(snapshot.time)
    for name, value in snapshot.scalars.items():  # each an attribute of its own name
        if name in _RESERVED_ATTRS:
            raise ValueError(f"snapshot.scalars: {name!r} is a name the snapshot group uses already")
        _check_name("snapshot.scalars", name)
        group.attrs[name] = np.float64(value)
    if snapshot.scalars:
        group.attrs["scalars"] = np.array(list(snapshot.scalars), dtype=h5py.string_dtype())
    if step is not None:
        group.attrs["step"] = np.int64(step)


#: The per-particle fields of the grains, stored one row per grain (version 3).
_GRAIN_FIELDS = (GRAIN_FIELD, GRAIN_CENTROID_FIELD, GRAIN_ANGLE_FIELD)
#: Each per-grain dataset of the ``grains`` group: its per-particle field, units and width.
_GRAIN_ROWS = {"centroid": (GRAIN_CENTROID_FIELD, "m", (2,)), "angle": (GRAIN_ANGLE_FIELD, "rad", ())}


def _write_grains(group: h5py.Group, fields: Mapping[str, NDArray[Any]], compression: str | None) -> None:
    """The grain of every particle as ``grain`` (N,) and one row per grain, in increasing
    label, as ``grains/label``, ``grains/centroid``, ``grains/angle`` (the Snapshot has checked
    that a grain's particles agree, so the rows keep every particle's value to the bit)."""
    if GRAIN_FIELD not in fields:
        return
    grain = np.asarray(fields[GRAIN_FIELD], dtype=np.int64)
    label, first = np.unique(grain, return_index=True)
    _write_array(group, "grain", grain, units="", compression=compression, where="snapshot.grain")
    rows = group.create_group("grains", track_order=True)
    _write_array(rows, "label", label, units="", compression=compression, where="snapshot.grains.label")
    for name, (field, units, _) in _GRAIN_ROWS.items():
        if field in fields:
            values = np.asarray(fields[field])[first]
            _write_array(rows, name, values, units=units, compression=compression, where=f"snapshot.grains.{name}")


def _read_grains(group: h5py.Group, path: Path) -> dict[str, NDArray[Any]]:
    """The grain fields of a version-3 snapshot group, one value per particle (none when
    the snapshot has no grains)."""
    if "grain" not in group:
        return {}
    grain = np.asarray(group["grain"][()], dtype=np.int64)
    rows = group.get("grains")
    if rows is None or "label" not in rows:
        raise ResultsFileError(path, f"{group.name}: a 'grain' dataset without 'grains/label'")
    label = np.asarray(rows["label"][()], dtype=np.int64)
    if np.any(np.diff(label) <= 0):
        raise ResultsFileError(path, f"{group.name}/grains/label: the labels do not increase")
    row = np.searchsorted(label, grain)
    found = row < len(label)
    found[found] = label[row[found]] == grain[found]
    if not found.all():
        k = int(np.argmin(found))
        raise ResultsFileError(path, f"{group.name}/grain: particle {k}'s grain {int(grain[k])} is not in grains/label")
    fields: dict[str, NDArray[Any]] = {GRAIN_FIELD: grain}
    for name, (field, _, width) in _GRAIN_ROWS.items():
        if name in rows:
            values = rows[name][()]
            if values.shape != (len(label), *width):
                raise ResultsFileError(
                    path, f"{group.name}/grains/{name}: shape {values.shape}, expected {(len(label), *width)}"
                )
            fields[field] = values[row]
    return fields


def _read_snapshot_group_v3(group: h5py.Group, path: Path) -> Snapshot:
    """Version 3: version 1's group and its grains (:func:`_read_grains`)."""
    return _read_snapshot_group_v1(group, path, _read_grains(group, path))


def _read_snapshot_group_v1(
    group: h5py.Group, path: Path, grains: Mapping[str, NDArray[Any]] | None = None
) -> Snapshot:
    def get(name: str) -> NDArray[Any] | None:
        return group[name][()] if name in group else None

    def fields(owner: str) -> dict[str, NDArray[Any]]:
        if owner not in group:
            return {}
        sub = group[owner]
        return {key: sub[key][()] for key in sub}

    try:
        metadata = json.loads(_read_text(group["metadata"])) if "metadata" in group else {}
    except json.JSONDecodeError as error:
        raise ResultsFileError(path, f"{group.name}/metadata: not valid JSON ({error})") from None
    attrs = group.attrs
    periodic = tuple(bool(p) for p in attrs.get("periodic", (0, 0)))
    try:
        return Snapshot(
            positions=group["positions"][()],
            radii=group["radii"][()],
            ids=get("ids"),
            rotations=get("rotations"),
            kind=get("kind"),
            contact_i=get("contact_i"),
            contact_j=get("contact_j"),
            normal_force=get("normal_force"),
            shear_force=get("shear_force"),
            contact_normal=get("contact_normal"),
            contact_point=get("contact_point"),
            contact_fields=fields("contact_fields"),
            particle_fields=fields("particle_fields") | dict(grains or {}),
            box=get("box"),
            periodic=periodic,  # type: ignore[arg-type]
            tilt=float(attrs.get("tilt", 0.0)),
            time=float(attrs["time"]) if "time" in attrs else None,
            scalars=_scalars(attrs),
            metadata=metadata,
        )
    except KeyError as error:
        raise ResultsFileError(path, f"{group.name}: missing dataset ({error})") from None
    except ValueError as error:
        raise ResultsFileError(path, f"{group.name}: invalid snapshot ({error})") from None


#: A name :func:`snapshot_name` wrote with its default prefix: ``strain_<axial strain>``.
_AXIAL_STRAIN_NAME = re.compile(r"^strain_([-+]?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?)$")


def snapshot_strain(info: Any) -> float:
    """The axial strain (a fraction, compression positive) a snapshot was written at.

    ``info`` is a :class:`SnapshotInfo` or a :class:`~grainlab.snapshot.Snapshot`
    listing (anything with ``axial_strain`` and ``name``). The one fallback
    rule: the recorded ``axial_strain`` when it is finite; else the strain in
    a name :func:`snapshot_name` wrote with its default prefix
    (``strain_0.0150`` gives 0.015); else NaN (a simple-shear ``gamma_*``
    snapshot has no axial strain).

    >>> from types import SimpleNamespace as S
    >>> snapshot_strain(S(axial_strain=0.0151, name="strain_0.0150")), snapshot_strain(S(axial_strain=None, name="strain_0.0150"))
    (0.0151, 0.015)
    >>> snapshot_strain(S(axial_strain=None, name="gamma_0.3000"))
    nan
    """
    value = getattr(info, "axial_strain", None)
    if value is not None and math.isfinite(value):
        return float(value)
    match = _AXIAL_STRAIN_NAME.match(str(getattr(info, "name", "")))
    return float(match.group(1)) if match else math.nan


@dataclass(frozen=True)
class SnapshotInfo:
    """What a results file says about one of its snapshots, without loading it."""

    #: Group name under ``/snapshots``.
    name: str
    #: Position in the order written (0 first).
    index: int
    #: Simulated time, s (None if not recorded).
    time: float | None
    #: Axial strain, compression positive, a fraction (None if not recorded).
    axial_strain: float | None
    #: Engine step count (None if not recorded).
    step: int | None
    #: Number of particles N.
    n_particles: int
    #: Number of contacts Nc (particle–particle and wall).
    n_contacts: int
    #: The snapshot's scalars (:attr:`grainlab.snapshot.Snapshot.scalars`), ``axial_strain`` among them.
    scalars: Mapping[str, float] = dataclasses.field(default_factory=dict)


def _snapshot_order(group: h5py.Group) -> list[tuple[str, int]]:
    out = []
    for name in group:
        index = group[name].attrs.get("index")
        if index is not None:
            out.append((name, int(index)))
    return sorted(out, key=lambda item: item[1])


def _snapshot_infos_v1(f: h5py.File) -> tuple[SnapshotInfo, ...]:
    if "snapshots" not in f:
        return ()
    group = f["snapshots"]
    infos = []
    for name, index in _snapshot_order(group):
        a = group[name].attrs
        infos.append(
            SnapshotInfo(
                name=name,
                index=index,
                time=float(a["time"]) if "time" in a else None,
                axial_strain=float(a["axial_strain"]) if "axial_strain" in a else None,
                step=int(a["step"]) if "step" in a else None,
                n_particles=int(a.get("n_particles", group[name]["positions"].shape[0])),
                n_contacts=int(a.get("n_contacts", 0)),
                scalars=_scalars(a),
            )
        )
    return tuple(infos)
