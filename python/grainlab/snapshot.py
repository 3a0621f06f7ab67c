"""The common data model between the engine, files and analysis: :class:`Snapshot`.

One state of a 2D assembly of disks: particles as one array per property,
contacts as parallel arrays. Fields, units and codes: docs/analysis.md, "The
snapshot"; signs and boundary bodies: docs/conventions.md; grains: docs/bodies.md.

Example
-------
>>> import numpy as np
>>> from grainlab.snapshot import Snapshot
>>> snap = Snapshot.from_geometry(
...     positions=[[0.0, 0.0], [2.0, 0.0], [1.0, 3.0**0.5]],
...     radii=[1.0, 1.0, 1.0],
...     tolerance=1e-9,
... )
>>> snap.n_contacts
3
>>> np.degrees(snap.contact_angles()).round(6).tolist()
[0.0, 60.0, 120.0]
"""

from __future__ import annotations

import dataclasses
import enum
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial import cKDTree

from grainlab import _core, _kernels

__all__ = [
    "BODY_FIELD",
    "GRAIN_ANGLE_FIELD",
    "GRAIN_CENTROID_FIELD",
    "GRAIN_FIELD",
    "ParticleKind",
    "Snapshot",
    "detect_contacts",
    "wall_code",
]

TWO_PI = 2.0 * np.pi

#: Name of the per-particle field that labels each membrane particle's chain.
BODY_FIELD = "body"

#: Names of the per-particle fields of the grain (rigid body) of each particle:
#: its label, its centroid (N, 2) and its angle (N,).
GRAIN_FIELD = "grain"
GRAIN_CENTROID_FIELD = "grain_centroid"
GRAIN_ANGLE_FIELD = "grain_angle"

#: Ways of counting a particle's contacts with boundary bodies (see
#: :meth:`Snapshot.contact_counts`): ``"body"`` once per body, ``"each"`` every contact.
BOUNDARY_COUNTING = ("body", "each")


class ParticleKind(enum.IntEnum):
    """Per-particle role codes stored in :attr:`Snapshot.kind`."""

    #: An ordinary soil grain.
    SOIL = 0
    #: A disk of a flexible membrane / boundary chain; not part of the sample.
    MEMBRANE = 1
    #: A soil grain currently acting as the flexible boundary (variant B).
    BOUNDARY = 2


def wall_code(wall_id: ArrayLike) -> NDArray[np.int64]:
    """The ``contact_j`` value that denotes wall ``wall_id`` (``-1 - wall_id``).

    >>> wall_code([0, 3]).tolist()
    [-1, -4]
    """
    w = np.asarray(wall_id, dtype=np.int64)
    if np.any(w < 0):
        raise ValueError("wall_id: wall ids must be >= 0")
    return -1 - w


def _readonly(a: NDArray[Any]) -> NDArray[Any]:
    """A read-only view (the caller's array keeps its own flags)."""
    v = a.view()
    v.flags.writeable = False
    return v


def _as_float(name: str, value: ArrayLike, shape: tuple[int | None, ...]) -> NDArray[np.float64]:
    try:
        a = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as error:
        raise ValueError(f"{name}: cannot convert to float64 ({error})") from None
    _check_shape(name, a, shape)
    bad = ~np.isfinite(a)
    if bad.any():
        first = np.argwhere(bad)[0]
        where = first[0] if a.ndim == 1 else tuple(int(k) for k in first)
        raise ValueError(f"{name}: non-finite value (NaN or inf) at index {where}")
    return a


def _as_int(name: str, value: ArrayLike, shape: tuple[int | None, ...]) -> NDArray[np.int64]:
    a = np.asarray(value)
    if a.size and not (np.issubdtype(a.dtype, np.integer) or a.dtype == bool):
        if (
            np.issubdtype(a.dtype, np.floating)
            and np.all(np.isfinite(a))
            and np.all(a == np.round(a))
        ):
            pass
        else:
            raise ValueError(f"{name}: must hold integers, got dtype {a.dtype}")
    a = a.astype(np.int64, copy=False)
    _check_shape(name, a, shape)
    return a


def _labels(name: str, value: ArrayLike, n: int, least: int) -> NDArray[np.int64]:
    """(n,) integer labels, each >= ``least``."""
    labels = _as_int(f"particle_fields[{name!r}]", value, (n,))
    if labels.size and labels.min() < least:
        k = int(np.argmin(labels))
        what = "body labels must be >= 0 (or -1 for none)" if least < 0 else "grain labels must be >= 0"
        raise ValueError(f"particle_fields[{name!r}]: {what}, got {int(labels[k])} at index {k}")
    return _readonly(labels)


def _labelled_fields(fields: dict[str, NDArray[Any]], n: int) -> dict[str, NDArray[Any]]:
    """The per-particle fields with the boundary body and grain labels checked
    (:data:`BODY_FIELD`, :data:`GRAIN_FIELD` and the grain's centroid and angle)."""
    if BODY_FIELD in fields:
        fields[BODY_FIELD] = _labels(BODY_FIELD, fields[BODY_FIELD], n, -1)
    if GRAIN_FIELD in fields:
        fields[GRAIN_FIELD] = _labels(GRAIN_FIELD, fields[GRAIN_FIELD], n, 0)
    for name, shape in ((GRAIN_CENTROID_FIELD, (n, 2)), (GRAIN_ANGLE_FIELD, (n,))):
        if name in fields:
            if GRAIN_FIELD not in fields:
                raise ValueError(f"particle_fields[{name!r}]: given without particle_fields[{GRAIN_FIELD!r}]")
            values = _as_float(f"particle_fields[{name!r}]", fields[name], shape)
            _check_one_value_per_grain(name, values, fields[GRAIN_FIELD])
            fields[name] = _readonly(values)
    return fields


def _check_one_value_per_grain(name: str, values: NDArray[np.float64], grain: NDArray[np.int64]) -> None:
    """Every particle of a grain carries the same bits of ``values`` (its grain's centroid
    or angle), so that one row per grain (``run.h5``) keeps them all."""
    order = np.argsort(grain, kind="stable")
    bits = values.view(np.uint64).reshape(len(grain), -1)[order]
    same_grain = grain[order][1:] == grain[order][:-1]
    differ = same_grain & np.any(bits[1:] != bits[:-1], axis=1)
    if differ.any():
        k = int(np.argmax(differ))
        first, second = sorted((int(order[k]), int(order[k + 1])))
        raise ValueError(
            f"particle_fields[{name!r}]: particles {first} and {second} are of grain {int(grain[first])} "
            f"but carry different values ({values[first].tolist()} and {values[second].tolist()}): "
            "a rigid grain has one centroid and one angle"
        )


def _check_shape(name: str, a: NDArray[Any], shape: tuple[int | None, ...]) -> None:
    ok = a.ndim == len(shape) and all(
        s is None or s == d for s, d in zip(shape, a.shape, strict=True)
    )
    if not ok:
        want = (
            "("
            + ", ".join("*" if s is None else str(s) for s in shape)
            + ("," if len(shape) == 1 else "")
            + ")"
        )
        raise ValueError(f"{name}: expected shape {want}, got {a.shape}")



def _wall_pairs(wall_i: ArrayLike | None, wall_id: ArrayLike | None) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """The wall contacts' particles and their ``contact_j`` codes (``-1 - wall_id``)."""
    if wall_i is None:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    if wall_id is None:
        raise ValueError("wall_id: required with wall_i")
    wi = np.asarray(wall_i, dtype=np.int64).reshape(-1)
    wj = wall_code(np.asarray(wall_id, dtype=np.int64).reshape(-1))
    if wj.shape != wi.shape:
        raise ValueError(f"wall_id: expected shape {wi.shape}, got {wj.shape}")
    return wi, wj


class _ContactJoin:
    """Joins a per-contact array of the particle contacts and one of the ``n_wall``
    wall contacts (:meth:`Snapshot.from_engine_arrays`)."""

    def __init__(self, n_wall: int) -> None:
        self.n_wall = n_wall

    def __call__(
        self, name: str, particle: ArrayLike | None, wall: ArrayLike | None, width: int | None, fill: Any
    ) -> NDArray[Any] | None:
        """Both joined, particle contacts first; None when neither is given; a missing
        wall array filled with ``fill`` (refused when ``fill`` is None)."""
        if particle is None and wall is None:
            return None
        if particle is None:
            raise ValueError(f"{name}: wall values given but no particle-contact values")
        p = np.asarray(particle)
        nw = self.n_wall
        if wall is None:
            if nw and fill is None:
                raise ValueError(f"{name}: needs the wall-contact values too (wall_*)")
            shape = (nw,) if width is None else (nw, width)
            w = np.full(shape, fill, dtype=p.dtype)
        else:
            w = np.asarray(wall, dtype=p.dtype)
        return np.concatenate([p, w])


def _checked_particles(
    positions: ArrayLike, radii: ArrayLike, ids: ArrayLike | None, rotations: ArrayLike | None,
    kind: ArrayLike | None,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.int64], NDArray[np.float64] | None,
           NDArray[np.int8]]:
    """A snapshot's particles checked: positions (N, 2), radii > 0, unique ids
    (default 0..N-1), rotations and known kind codes (default grains)."""
    pos = _as_float("positions", positions, (None, 2))
    n = pos.shape[0]
    rad = _as_float("radii", radii, (n,))
    if np.any(rad <= 0.0):
        k = int(np.argmax(rad <= 0.0))
        raise ValueError(f"radii: must be > 0, got {rad[k]!r} at index {k}")
    labels = np.arange(n, dtype=np.int64) if ids is None else _as_int("ids", ids, (n,))
    if n > 1:
        order = np.argsort(labels, kind="stable")
        dup = labels[order[1:]] == labels[order[:-1]]
        if dup.any():
            raise ValueError(f"ids: duplicate id {int(labels[order[1:]][dup][0])}")
    turns = None if rotations is None else _as_float("rotations", rotations, (n,))
    if kind is None:
        codes = np.zeros(n, dtype=np.int8)
    else:
        given = _as_int("kind", kind, (n,))
        allowed = [int(k) for k in ParticleKind]
        bad = ~np.isin(given, allowed)
        if bad.any():
            raise ValueError(f"kind: unknown code {int(given[bad][0])} (allowed {allowed})")
        codes = given.astype(np.int8)
    return pos, rad, labels, turns, codes


def _checked_pairs(
    contact_i: ArrayLike | None, contact_j: ArrayLike | None, n: int
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """A snapshot's contact pairs checked: both or neither, indices in range (j < 0:
    a wall), no particle with itself."""
    if (contact_i is None) != (contact_j is None):
        raise ValueError("contact_i / contact_j: give both or neither")
    ci = np.zeros(0, np.int64) if contact_i is None else _as_int("contact_i", contact_i, (None,))
    nc = ci.shape[0]
    cj = np.zeros(0, np.int64) if contact_j is None else _as_int("contact_j", contact_j, (nc,))
    if nc:
        if ci.min() < 0 or ci.max() >= n:
            k = int(np.argmax((ci < 0) | (ci >= n)))
            raise ValueError(f"contact_i: index {int(ci[k])} out of range [0, {n}) at contact {k}")
        if cj.max() >= n:
            k = int(np.argmax(cj >= n))
            raise ValueError(f"contact_j: index {int(cj[k])} out of range [0, {n}) at contact {k}")
        if np.any(ci == cj):
            k = int(np.argmax(ci == cj))
            raise ValueError(f"contact_j: particle {int(ci[k])} in contact with itself at contact {k}")
    return ci, cj


def _checked_normals(
    contact_normal: ArrayLike | None, cj: NDArray[np.int64], has_points: bool
) -> NDArray[np.float64] | None:
    """The contact normals checked to be unit vectors; without them, wall contacts
    need the contact points."""
    nc = cj.shape[0]
    if contact_normal is None:
        if nc and np.any(cj < 0) and not has_points:
            raise ValueError(
                "contact_normal: wall contacts (contact_j < 0) need contact_normal or contact_point"
            )
        return None
    normal = _as_float("contact_normal", contact_normal, (nc, 2))
    length = np.hypot(normal[:, 0], normal[:, 1])
    bad = np.abs(length - 1.0) > 1e-6
    if bad.any():
        k = int(np.argmax(bad))
        raise ValueError(f"contact_normal: not a unit vector at contact {k} (length {length[k]:.6g})")
    return normal


def _checked_cell(
    box: ArrayLike | None, periodic: tuple[bool, bool], tilt: float
) -> tuple[NDArray[np.float64] | None, tuple[bool, bool], float]:
    """The box bounds, periodic flags and tilt checked against one another."""
    flags = tuple(bool(p) for p in periodic)
    if len(flags) != 2:
        raise ValueError(f"periodic: expected two flags (x, y), got {periodic!r}")
    bounds = None
    if box is not None:
        bounds = _as_float("box", box, (2, 2))
        if np.any(bounds[:, 1] <= bounds[:, 0]):
            raise ValueError(f"box: need xlo < xhi and ylo < yhi, got {bounds.tolist()}")
    elif any(flags):
        raise ValueError("box: a periodic direction needs the box bounds")
    lean = float(tilt)
    if not np.isfinite(lean):
        raise ValueError(f"tilt: must be finite, got {tilt!r}")
    if lean != 0.0 and not flags[1]:
        raise ValueError(f"tilt: a leaning cell ({lean!r} m) needs y periodic")
    return bounds, (flags[0], flags[1]), lean


def _checked_scalars(scalars: Mapping[str, float] | None, axial_strain: float | None) -> dict[str, float]:
    """The named scalars (``axial_strain`` among them when given), finite."""
    values = dict(scalars or {})
    if axial_strain is not None:
        if "axial_strain" in values and values["axial_strain"] != axial_strain:
            raise ValueError("axial_strain: given twice, as axial_strain and in scalars, with other values")
        values["axial_strain"] = axial_strain
    checked: dict[str, float] = {}
    for name, scalar in values.items():
        if not isinstance(name, str) or not name:
            raise ValueError(f"scalars: names must be non-empty strings, got {name!r}")
        number = float(scalar)
        if not np.isfinite(number):
            raise ValueError(f"scalars[{name!r}]: must be finite, got {number}")
        checked[name] = number
    return checked

@dataclass(frozen=True, eq=False, init=False)
class Snapshot:
    """One state of a 2D disk assembly: particles and their contacts.

    Every field (``positions``, ``radii``, ``ids``, ``rotations``, ``kind``, the
    contact arrays, ``contact_fields``, ``particle_fields``, ``box``, ``periodic``,
    ``tilt``, ``time``, ``scalars``, ``axial_strain``, ``metadata``), its shape and
    unit: docs/analysis.md, "The snapshot". Without ``contact_normal``,
    particle-particle normals come from the centres (minimum image) and wall
    normals from ``contact_point``.

    Raises
    ------
    ValueError
        On construction, naming the field: wrong shape, NaN / inf, radius
        <= 0, duplicate ids, contact index out of range, self contact, a
        wall contact without normal or contact point, a normal that is not
        of unit length.

    Notes
    -----
    Arrays are stored as read-only views; build a new snapshot (for example
    with :func:`dataclasses.replace` or :meth:`with_contacts`) to change one.
    """

    positions: NDArray[np.float64]
    radii: NDArray[np.float64]
    ids: NDArray[np.int64]
    rotations: NDArray[np.float64] | None
    kind: NDArray[np.int8]
    contact_i: NDArray[np.int64]
    contact_j: NDArray[np.int64]
    normal_force: NDArray[np.float64] | None
    shear_force: NDArray[np.float64] | None
    contact_normal: NDArray[np.float64] | None
    contact_point: NDArray[np.float64] | None
    contact_fields: Mapping[str, NDArray[Any]]
    particle_fields: Mapping[str, NDArray[Any]]
    box: NDArray[np.float64] | None
    periodic: tuple[bool, bool]
    tilt: float
    time: float | None
    scalars: Mapping[str, float]
    metadata: Mapping[str, Any]
    _cache: dict[str, NDArray[Any]] = field(init=False, repr=False, compare=False)

    # ------------------------------------------------------------------ build
    def __init__(
        self,
        positions: ArrayLike,
        radii: ArrayLike,
        ids: ArrayLike | None = None,
        rotations: ArrayLike | None = None,
        kind: ArrayLike | None = None,
        contact_i: ArrayLike | None = None,
        contact_j: ArrayLike | None = None,
        normal_force: ArrayLike | None = None,
        shear_force: ArrayLike | None = None,
        contact_normal: ArrayLike | None = None,
        contact_point: ArrayLike | None = None,
        contact_fields: Mapping[str, ArrayLike] | None = None,
        particle_fields: Mapping[str, ArrayLike] | None = None,
        box: ArrayLike | None = None,
        periodic: tuple[bool, bool] = (False, False),
        time: float | None = None,
        axial_strain: float | None = None,
        metadata: Mapping[str, Any] | None = None,
        scalars: Mapping[str, float] | None = None,
        tilt: float = 0.0,
    ) -> None:
        # the inputs are checked and stored as read-only arrays (the dataclass is
        # frozen, so the fields are set through object.__setattr__ once, here)
        def put(name: str, value: object) -> None:
            object.__setattr__(self, name, value)

        put("_cache", {})
        pos, rad, labels, turns, codes = _checked_particles(positions, radii, ids, rotations, kind)
        n = pos.shape[0]
        put("positions", _readonly(pos))
        put("radii", _readonly(rad))
        put("ids", _readonly(labels))
        put("rotations", None if turns is None else _readonly(turns))
        put("kind", _readonly(codes))
        ci, cj = _checked_pairs(contact_i, contact_j, n)
        nc = ci.shape[0]
        put("contact_i", _readonly(ci))
        put("contact_j", _readonly(cj))
        for name, value in (("normal_force", normal_force), ("shear_force", shear_force)):
            put(name, None if value is None else _readonly(_as_float(name, value, (nc,))))
        point = (
            None if contact_point is None else _as_float("contact_point", contact_point, (nc, 2))
        )
        put("contact_point", None if point is None else _readonly(point))
        normal = _checked_normals(contact_normal, cj, point is not None)
        put("contact_normal", None if normal is None else _readonly(normal))
        put(
            "contact_fields",
            {
                k: _readonly(self._field(k, v, nc, "contact_fields"))
                for k, v in dict(contact_fields or {}).items()
            },
        )
        per_particle = {
            k: _readonly(self._field(k, v, n, "particle_fields"))
            for k, v in dict(particle_fields or {}).items()
        }
        put("particle_fields", _labelled_fields(per_particle, n))
        bounds, flags, lean = _checked_cell(box, periodic, tilt)
        put("periodic", flags)
        put("box", None if bounds is None else _readonly(bounds))
        put("tilt", lean)
        if time is not None:
            time = float(time)
            if not np.isfinite(time):
                raise ValueError(f"time: must be finite, got {time}")
        put("time", time)
        put("scalars", _checked_scalars(scalars, axial_strain))
        put("metadata", dict(metadata or {}))

    @staticmethod
    def _field(key: str, value: ArrayLike, length: int, owner: str) -> NDArray[Any]:
        a = np.asarray(value)
        if a.ndim == 0 or a.shape[0] != length:
            raise ValueError(f"{owner}[{key!r}]: expected length {length}, got shape {a.shape}")
        if np.issubdtype(a.dtype, np.floating) and not np.all(np.isfinite(a)):
            raise ValueError(f"{owner}[{key!r}]: non-finite value (NaN or inf)")
        return a

    @classmethod
    def from_geometry(
        cls,
        positions: ArrayLike,
        radii: ArrayLike,
        ids: ArrayLike | None = None,
        *,
        tolerance: float = 0.0,
        **kwargs: Any,
    ) -> Snapshot:
        """A snapshot whose contacts are detected from the geometry.

        A pair is in contact when its centre distance is ``< r_i + r_j +
        tolerance`` (``tolerance`` in m, >= 0; use a small positive value for
        lattices of exactly touching disks). Uses a cell list, O(N)
        (:func:`detect_contacts`).
        ``box`` / ``periodic`` in ``kwargs`` are honoured (minimum image).
        """
        pos = _as_float("positions", positions, (None, 2))
        rad = _as_float("radii", radii, (pos.shape[0],))
        i, j = detect_contacts(
            pos,
            rad,
            tolerance=tolerance,
            box=kwargs.get("box"),
            periodic=kwargs.get("periodic", (False, False)),
            tilt=kwargs.get("tilt", 0.0),
        )
        metadata = dict(kwargs.pop("metadata", {}) or {})
        metadata.setdefault("contacts", f"detected from geometry (tolerance {tolerance:g} m)")
        return cls(pos, rad, ids, contact_i=i, contact_j=j, metadata=metadata, **kwargs)

    @classmethod
    def from_engine_arrays(
        cls,
        positions: ArrayLike,
        radii: ArrayLike,
        ids: ArrayLike | None = None,
        *,
        contact_i: ArrayLike,
        contact_j: ArrayLike,
        contact_point: ArrayLike | None = None,
        contact_normal: ArrayLike | None = None,
        normal_force: ArrayLike | None = None,
        shear_force: ArrayLike | None = None,
        overlap: ArrayLike | None = None,
        sliding: ArrayLike | None = None,
        bonded: ArrayLike | None = None,
        wall_i: ArrayLike | None = None,
        wall_id: ArrayLike | None = None,
        wall_point: ArrayLike | None = None,
        wall_normal: ArrayLike | None = None,
        wall_normal_force: ArrayLike | None = None,
        wall_shear_force: ArrayLike | None = None,
        wall_overlap: ArrayLike | None = None,
        wall_sliding: ArrayLike | None = None,
        **kwargs: Any,
    ) -> Snapshot:
        """Build a snapshot from separate particle–particle and wall contact arrays.

        This is the constructor for the engine: particle–particle contacts
        (``contact_*`` plus ``overlap``, ``sliding``, ``bonded`` and forces,
        all of length K) and particle–wall contacts (``wall_*``, length W, with
        the particle index ``wall_i`` and ``wall_id >= 0``) are concatenated
        into one contact list, particle contacts first; wall contacts get
        ``contact_j = -1 - wall_id``. ``overlap`` / ``sliding`` / ``bonded``
        go into :attr:`contact_fields` (``bonded`` is False for wall
        contacts). An optional per-contact array must be given for both kinds
        or neither, except that wall arrays default to zeros / False when the
        particle array is given and the wall one is not.
        """
        ci = np.asarray(contact_i, dtype=np.int64).reshape(-1)
        cj = np.asarray(contact_j, dtype=np.int64).reshape(-1)
        wi, wj = _wall_pairs(wall_i, wall_id)
        join = _ContactJoin(wi.shape[0])
        normals = join("contact_normal", contact_normal, wall_normal, 2, None)
        points = join("contact_point", contact_point, wall_point, 2, None)
        fields = dict(kwargs.pop("contact_fields", {}) or {})
        for name, p, w, fill in (
            ("overlap", overlap, wall_overlap, 0.0),
            ("sliding", sliding, wall_sliding, False),
            ("bonded", bonded, None, False),
        ):
            joined = join(name, p, w, None, fill)
            if joined is not None:
                fields[name] = joined
        return cls(
            positions,
            radii,
            ids,
            contact_i=np.concatenate([ci, wi]),
            contact_j=np.concatenate([cj, wj]),
            contact_normal=normals,
            contact_point=points,
            normal_force=join("normal_force", normal_force, wall_normal_force, None, None),
            shear_force=join("shear_force", shear_force, wall_shear_force, None, None),
            contact_fields=fields,
            **kwargs,
        )

    def with_boundary_bodies(self, body: ArrayLike) -> Snapshot:
        """The same snapshot with ``particle_fields["body"]`` set to ``body`` (N,) int:
        the chain (>= 0) each membrane particle belongs to, -1 for other particles."""
        return dataclasses.replace(
            self, particle_fields={**self.particle_fields, BODY_FIELD: np.asarray(body)}
        )

    def with_contacts(
        self, contact_i: ArrayLike, contact_j: ArrayLike, **contact_arrays: Any
    ) -> Snapshot:
        """The same particles with a new contact list (other contact arrays reset)."""
        reset: dict[str, Any] = dict(
            normal_force=None,
            shear_force=None,
            contact_normal=None,
            contact_point=None,
            contact_fields={},
        )
        reset.update(contact_arrays)
        return dataclasses.replace(
            self, contact_i=np.asarray(contact_i), contact_j=np.asarray(contact_j), **reset
        )

    def select_contacts(self, mask: ArrayLike) -> Snapshot:
        """The same particles with only the contacts where ``mask`` is true."""
        m = np.asarray(mask, dtype=bool)
        if m.shape != (self.n_contacts,):
            raise ValueError(f"mask: expected shape ({self.n_contacts},), got {m.shape}")

        def take(a: NDArray[np.float64] | None) -> NDArray[np.float64] | None:
            return None if a is None else a[m]

        return dataclasses.replace(
            self,
            contact_i=self.contact_i[m],
            contact_j=self.contact_j[m],
            normal_force=take(self.normal_force),
            shear_force=take(self.shear_force),
            contact_normal=take(self.contact_normal),
            contact_point=take(self.contact_point),
            contact_fields={k: v[m] for k, v in self.contact_fields.items()},
        )

    # ------------------------------------------------------------- properties
    @property
    def n_particles(self) -> int:
        """Number of particles N (all kinds)."""
        return int(self.positions.shape[0])

    @property
    def n_contacts(self) -> int:
        """Number of contacts Nc (particle–particle and wall)."""
        return int(self.contact_i.shape[0])

    @property
    def diameters(self) -> NDArray[np.float64]:
        """Disk diameters 2 r, m."""
        return 2.0 * self.radii

    @property
    def is_sample(self) -> NDArray[np.bool_]:
        """(N,) mask of the particles that belong to the sample (kind != MEMBRANE)."""
        return np.asarray(self.kind != ParticleKind.MEMBRANE, dtype=np.bool_)

    def grains(self) -> NDArray[np.int64]:
        """(N,) the grain (rigid body) of each particle, labels 0, 1, ...: pebbles of
        one clump share theirs (:data:`GRAIN_FIELD`); without the field every
        particle is a grain of its own (``arange(N)``)."""
        if GRAIN_FIELD not in self.particle_fields:
            return _readonly(np.arange(self.n_particles, dtype=np.int64))
        return _readonly(np.asarray(self.particle_fields[GRAIN_FIELD], dtype=np.int64))

    @property
    def n_grains(self) -> int:
        """Number of grains (rigid bodies) of all kinds: :meth:`grains` labels."""
        labels = self.grains()
        return int(np.unique(labels).size)

    def grain_centroids(self) -> NDArray[np.float64]:
        """(N, 2) m: the centroid of each particle's grain (:data:`GRAIN_CENTROID_FIELD`;
        the pebbles of a clump share their clump's). Without the field, a snapshot whose
        grains are single disks gives each disk's centre.

        Raises ValueError for a snapshot that labels clumps (grains of more than one
        particle) without their centroids, such as a file read with grain labels only.
        """
        return self._of_grains(GRAIN_CENTROID_FIELD, self.positions, "centroids")

    def grain_angles(self) -> NDArray[np.float64]:
        """(N,) rad: the angle of each particle's grain, CCW positive
        (:data:`GRAIN_ANGLE_FIELD`; a clump's angle turns its pebbles' offsets from the
        body frame). Without the field, a snapshot whose grains are single disks gives
        each disk's rotation.

        Raises ValueError for a snapshot that labels clumps without their angles, or
        whose disks carry no rotations.
        """
        return self._of_grains(GRAIN_ANGLE_FIELD, self.rotations, "angles")

    def _of_grains(self, name: str, own: NDArray[np.float64] | None, what: str) -> NDArray[np.float64]:
        if name in self.particle_fields:
            return _readonly(np.asarray(self.particle_fields[name], dtype=np.float64))
        if self.n_grains != self.n_particles:
            raise ValueError(
                f"grain {what}: the snapshot labels clumps (particle_fields[{GRAIN_FIELD!r}]) "
                f"without particle_fields[{name!r}]"
            )
        if own is None:
            raise ValueError(f"grain {what}: the snapshot has no rotations, so its disks' angles are unknown")
        return own

    @property
    def is_wall_contact(self) -> NDArray[np.bool_]:
        """(Nc,) mask of the contacts with a wall (``contact_j < 0``)."""
        return self.contact_j < 0

    @property
    def wall_ids(self) -> NDArray[np.int64]:
        """(Nc,) wall id of each contact, -1 for particle–particle contacts."""
        cj = np.asarray(self.contact_j)
        return np.where(cj < 0, -1 - cj, -1)

    @property
    def is_boundary_contact(self) -> NDArray[np.bool_]:
        """(Nc,) mask of contacts with a wall or with a membrane particle."""
        cj = self.contact_j
        membrane = np.asarray(self.kind == ParticleKind.MEMBRANE, dtype=np.bool_)
        wall = cj < 0
        partner = np.where(wall, 0, cj)
        return wall | (membrane[partner] & ~wall) | membrane[self.contact_i]

    def boundary_bodies(self) -> NDArray[np.int64]:
        """(N,) the boundary body (membrane chain) of each ``MEMBRANE`` particle; -1 for the others.

        Read from ``particle_fields["body"]`` when the snapshot has it (a
        membrane particle labelled -1 there is a body of its own and gets a
        new label). Otherwise the chains are found from the geometry: membrane
        particles that touch or overlap, centre distance below
        ``(r_i + r_j)(1 + 1e-6)`` (minimum image), belong to one body, as the
        overlapping disks of a membrane chain do; grainlab's own snapshots
        carry the label. Labels are 0, 1, ... (the stored ones are kept).
        """
        if "bodies" in self._cache:
            return self._cache["bodies"]
        membrane = np.flatnonzero(np.asarray(self.kind) == ParticleKind.MEMBRANE)
        body = np.full(self.n_particles, -1, dtype=np.int64)
        if BODY_FIELD in self.particle_fields:
            stored = np.asarray(self.particle_fields[BODY_FIELD])[membrane]
            unlabelled = stored < 0
            stored[unlabelled] = stored.max(initial=-1) + 1 + np.arange(int(unlabelled.sum()))
            body[membrane] = stored
        elif membrane.size:
            from scipy.sparse import coo_matrix
            from scipy.sparse.csgraph import connected_components

            r = self.radii[membrane]
            i, j = detect_contacts(
                self.positions[membrane],
                r,
                tolerance=2e-6 * float(r.max()),
                box=self.box,
                periodic=self.periodic,
            )
            d = self.minimum_image(self.positions[membrane[j]] - self.positions[membrane[i]])
            near = np.hypot(d[:, 0], d[:, 1]) < (r[i] + r[j]) * (1.0 + 1e-6)
            m = membrane.size
            graph = coo_matrix((np.ones(int(near.sum())), (i[near], j[near])), shape=(m, m))
            body[membrane] = connected_components(graph, directed=False)[1]
        body = _readonly(body)
        self._cache["bodies"] = body
        return body

    def boundary_body_keys(self) -> NDArray[np.int64]:
        """(Nc, 2) the boundary body on the far side of each contact end.

        Column 0 is the end on particle ``contact_i``, column 1 the end on
        ``contact_j``. The value is a key naming the body (``2 w`` for wall
        ``w``, ``2 b + 1`` for membrane chain ``b`` of :meth:`boundary_bodies`),
        or -1 when the far side is not a boundary body (a sample particle, a
        particle of the end's own chain) or the end does not exist (column 1 of
        a wall contact).
        """
        ci = np.asarray(self.contact_i)
        cj = np.asarray(self.contact_j)
        body = self.boundary_bodies()
        wall = cj < 0
        body_i = body[ci]
        body_j = np.where(wall, -1, body[np.where(wall, 0, cj)])
        on_i = np.where(wall, -2 - 2 * cj, np.where(body_j >= 0, 2 * body_j + 1, -1))
        on_i[~wall & (body_j == body_i)] = -1
        on_j = np.where(~wall & (body_i >= 0) & (body_i != body_j), 2 * body_i + 1, -1)
        return np.column_stack([on_i, on_j]).astype(np.int64)

    def index_of(self, ids: ArrayLike) -> NDArray[np.int64]:
        """Indices of the particles with the given ids; -1 where an id is absent."""
        want = np.asarray(ids, dtype=np.int64)
        if self.n_particles == 0:
            return np.full(want.shape, -1, dtype=np.int64)
        order = self._id_order()
        sorted_ids = self.ids[order]
        pos = np.minimum(np.searchsorted(sorted_ids, want), len(sorted_ids) - 1)
        return np.where(sorted_ids[pos] == want, order[pos], -1).astype(np.int64)

    def _id_order(self) -> NDArray[np.int64]:
        if "id_order" not in self._cache:
            self._cache["id_order"] = np.argsort(self.ids, kind="stable")
        return self._cache["id_order"]

    def minimum_image(self, d: NDArray[np.float64]) -> NDArray[np.float64]:
        """Apply the minimum-image convention to separation vectors ``d`` (..., 2):
        in a leaning cell (:attr:`tilt`) along y first, by whole ``(tilt, Ly)``,
        then along x, as LAMMPS does for a triclinic box."""
        if not any(self.periodic):
            return d
        assert self.box is not None  # the constructor refuses a periodic direction without it
        return _minimum_image(d, self.box[:, 1] - self.box[:, 0], self.periodic, self.tilt)

    def contact_normals(self) -> NDArray[np.float64]:
        """(Nc, 2) unit normals from particle i towards j (or towards the wall).

        The stored :attr:`contact_normal` when given; otherwise computed from
        the centres (particle–particle) and from ``contact_point`` (walls).
        """
        if self.contact_normal is not None:
            return np.asarray(self.contact_normal)
        if "normals" in self._cache:
            return self._cache["normals"]
        ci = self.contact_i
        cj = self.contact_j
        if _kernels.compiled() and not (cj.size and cj.min() < 0) and self.tilt == 0.0:
            lengths: list[float | None] = [None, None]
            if any(self.periodic):
                assert self.box is not None  # the constructor refuses periodic without it
                span = self.box[:, 1] - self.box[:, 0]
                lengths = [float(span[a]) if self.periodic[a] else None for a in (0, 1)]
            normals, angles = _core.contact_normals(
                np.ascontiguousarray(self.positions),
                np.ascontiguousarray(ci),
                np.ascontiguousarray(cj),
                lengths[0],
                lengths[1],
                _kernels.threads(),
            )
            self._cache["normals"] = _readonly(normals)
            self._cache.setdefault("angles", _readonly(angles))
            return self._cache["normals"]
        wall = cj < 0
        other = np.where(wall, ci, cj)
        d = self.positions[other] - self.positions[ci]
        d = self.minimum_image(d)
        if wall.any():
            d[wall] = self.minimum_image(
                np.asarray(self.contact_point)[wall] - self.positions[ci[wall]]
            )
        length = np.hypot(d[:, 0], d[:, 1])
        if np.any(length == 0.0):
            k = int(np.argmax(length == 0.0))
            raise ValueError(
                f"contact_normal: undefined for contact {k} "
                "(coincident centres or contact point at the centre)"
            )
        normals = _readonly(d / length[:, None])
        self._cache["normals"] = normals
        return normals

    def contact_angles(self) -> NDArray[np.float64]:
        """(Nc,) angle of each contact on particle i, rad in [0, 2 pi), CCW from +x.

        The angle on particle j of a particle–particle contact is this plus pi.
        """
        if "angles" not in self._cache:
            n = self.contact_normals()
            a = np.arctan2(n[:, 1], n[:, 0])
            a = np.where(a < 0.0, a + TWO_PI, a)
            a[a >= TWO_PI] = 0.0
            self._cache["angles"] = _readonly(a)
        return self._cache["angles"]

    def contact_counts(
        self, *, include_boundary: bool = True, boundary: str = "body"
    ) -> NDArray[np.int64]:
        """(N,) number of contacts of each particle (each contact counts for both ends).

        ``boundary="body"`` (default) counts a particle's contacts with one
        boundary body (a wall, one membrane chain: :meth:`boundary_bodies`) as
        one contact; ``"each"`` counts every contact, each membrane disk
        touched as one. With ``include_boundary=False`` contacts with walls and
        membrane particles are not counted.
        """
        if boundary not in BOUNDARY_COUNTING:
            raise ValueError(f"boundary: must be 'body' or 'each', got {boundary!r}")
        ci = np.asarray(self.contact_i)
        cj = np.asarray(self.contact_j)
        keep = np.ones(ci.shape, bool) if include_boundary else ~self.is_boundary_contact
        pp = keep & (cj >= 0)
        owner = np.concatenate([ci[keep], cj[pp]])
        if boundary == "body" and include_boundary:
            keys = self.boundary_body_keys()
            key = np.concatenate([keys[keep, 0], keys[pp, 1]])
            owner = owner[boundary_end_groups(owner, key) == np.arange(owner.size)]
        return np.bincount(owner, minlength=self.n_particles)

    @property
    def axial_strain(self) -> float | None:
        """The run's axial strain at this snapshot (``scalars["axial_strain"]``), None when it has none."""
        return self.scalars.get("axial_strain")

    def _repr_html_(self) -> str:
        from grainlab._repr import snapshot_html

        return snapshot_html(self)

    def __repr__(self) -> str:
        return (
            f"Snapshot(n_particles={self.n_particles}, n_contacts={self.n_contacts}, "
            f"time={self.time}, axial_strain={self.axial_strain})"
        )


def boundary_end_groups(owner: ArrayLike, key: ArrayLike) -> NDArray[np.int64]:
    """Group contact ends by particle and boundary body.

    ``owner`` (K,) is the particle of each end, ``key`` (K,) the boundary body
    on its far side (:meth:`Snapshot.boundary_body_keys`, -1 for none). Ends
    of one particle with the same key >= 0 form one group; every other end is
    a group of its own. Returns (K,) the index of the first end of each end's
    group, so ``groups == arange(K)`` marks one end per group.

    >>> boundary_end_groups([0, 0, 1, 0], [3, -1, 3, 3]).tolist()
    [0, 1, 2, 0]
    """
    o = np.asarray(owner, dtype=np.int64).reshape(-1)
    k = np.asarray(key, dtype=np.int64).reshape(-1)
    groups = np.arange(o.size, dtype=np.int64)
    ends = np.flatnonzero(k >= 0)
    if ends.size:
        pairs = np.column_stack([o[ends], k[ends]])
        _, first, inverse = np.unique(pairs, axis=0, return_index=True, return_inverse=True)
        groups[ends] = ends[first[inverse.reshape(-1)]]
    return groups


def _minimum_image(
    d: ArrayLike, lengths: NDArray[np.float64], periodic: tuple[bool, bool], tilt: float
) -> NDArray[np.float64]:
    """``d`` (..., 2) brought to its nearest image: along y first (by whole
    ``(tilt, Ly)``), then along x (by whole ``Lx``)."""
    d = np.array(d, dtype=np.float64, copy=True)
    if periodic[1]:
        k = np.round(d[..., 1] / lengths[1])
        d[..., 0] -= k * tilt
        d[..., 1] -= k * lengths[1]
    if periodic[0]:
        d[..., 0] -= lengths[0] * np.round(d[..., 0] / lengths[0])
    return d


def _detect_in_leaning_cell(
    pos: NDArray[np.float64],
    rad: NDArray[np.float64],
    tolerance: float,
    box: ArrayLike | None,
    periodic: tuple[bool, bool],
    tilt: float,
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """:func:`detect_contacts` in a leaning cell: the cell sheared back to its
    rectangle (``x - tilt (y - ylo) / Ly``), where the same lattice of images is
    a rectangular one, the search made there with the tolerance widened by the
    map's largest stretch, and the candidates kept by their true distance."""
    if box is None:
        raise ValueError("box: a periodic direction needs the box bounds")
    b = _as_float("box", box, (2, 2))
    lengths = b[:, 1] - b[:, 0]
    shear = tilt / lengths[1]
    back = pos.copy()
    back[:, 0] -= shear * (pos[:, 1] - b[1, 0])
    # |S^-1 v| <= stretch |v| for the back-shear S^-1 = [[1, -shear], [0, 1]]
    stretch = 0.5 * (abs(shear) + np.sqrt(shear * shear + 4.0))
    wide = (stretch - 1.0) * 2.0 * float(rad.max()) + stretch * tolerance
    i, j = detect_contacts(back, rad, tolerance=wide, box=b, periodic=periodic)
    d = _minimum_image(pos[j, :2] - pos[i, :2], lengths, periodic, tilt)
    touching = np.hypot(d[:, 0], d[:, 1]) < rad[i] + rad[j] + tolerance
    return i[touching], j[touching]


def detect_contacts(
    positions: ArrayLike,
    radii: ArrayLike,
    *,
    tolerance: float = 0.0,
    box: ArrayLike | None = None,
    periodic: tuple[bool, bool] = (False, False),
    tilt: float = 0.0,
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Pairs of disks in contact: centre distance ``< r_i + r_j + tolerance``.

    Parameters
    ----------
    positions : (N, 2) float, m
        Disk centres; (N, 3) for spheres (the readers' projection of 3D
        data), the third direction never periodic.
    radii : (N,) float, m
    tolerance : float, m, >= 0
        Touching tolerance added to the radius sum.
    box, periodic, tilt
        As in :class:`Snapshot` (x and y); periodic directions use the
        minimum image (a leaning cell: sheared back to its rectangle for the
        search, which finds the same pairs).

    Returns
    -------
    i, j : (Nc,) int64
        Particle indices with ``i < j``, sorted by ``i`` then ``j``.

    Raises
    ------
    ValueError
        Before any work, naming the input: a tolerance < 0 or not finite,
        positions not (N, 2) / (N, 3), radii not (N,), a non-finite
        coordinate, a radius <= 0, a periodic direction without ``box``.

    Notes
    -----
    Runs in the Rust engine crate with a cell list on every core
    (docs/analysis.md, "Speed"); the result does not depend on the number of
    threads and equals that of the k-d tree reference
    (:func:`_detect_contacts_numpy`).
    """
    pos = np.asarray(positions, dtype=np.float64)
    rad = np.asarray(radii, dtype=np.float64)
    if tolerance < 0 or not np.isfinite(tolerance):
        raise ValueError(f"tolerance: must be a finite value >= 0, got {tolerance}")
    if tilt != 0.0 and pos.ndim == 2 and pos.shape[0] >= 2:
        if not periodic[1]:
            raise ValueError(f"tilt: a leaning cell ({tilt!r} m) needs y periodic")
        return _detect_in_leaning_cell(pos, rad, float(tolerance), box, periodic, float(tilt))
    if not _kernels.compiled():
        return _detect_contacts_numpy(pos, rad, tolerance=tolerance, box=box, periodic=periodic)
    if pos.shape[0] < 2:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    if pos.ndim != 2 or pos.shape[1] not in (2, 3):
        raise ValueError(f"positions: expected shape (N, 2) or (N, 3), got {pos.shape}")
    if rad.shape != (pos.shape[0],):
        raise ValueError(f"radii: expected shape ({pos.shape[0]},), got {rad.shape}")
    flags = tuple(bool(p) for p in periodic)
    periods: list[tuple[float, float] | None] = [None, None]
    if any(flags):
        if box is None:
            raise ValueError("box: a periodic direction needs the box bounds")
        b = _as_float("box", box, (2, 2))
        lengths = b[:, 1] - b[:, 0]
        for axis in (0, 1):
            if flags[axis]:
                periods[axis] = (float(b[axis, 0]), float(lengths[axis]))
    i, j = _core.detect_contacts(
        np.ascontiguousarray(pos),
        np.ascontiguousarray(rad),
        float(tolerance),
        periods[0],
        periods[1],
        _kernels.threads(),
    )
    return i, j


def _detect_contacts_numpy(
    pos: NDArray[np.float64],
    rad: NDArray[np.float64],
    *,
    tolerance: float,
    box: ArrayLike | None,
    periodic: tuple[bool, bool],
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """The k-d tree reference of :func:`detect_contacts` (same arguments and result)."""
    if pos.shape[0] < 2:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    flags = tuple(bool(p) for p in periodic)
    boxsize = None
    if any(flags):
        if box is None:
            raise ValueError("box: a periodic direction needs the box bounds")
        b = np.asarray(box, dtype=np.float64)
        lengths = b[:, 1] - b[:, 0]
        pos = pos.copy()
        boxsize = np.zeros(2)
        for axis in (0, 1):
            if flags[axis]:
                pos[:, axis] = np.mod(pos[:, axis] - b[axis, 0], lengths[axis])
                pos[pos[:, axis] >= lengths[axis], axis] = 0.0
                boxsize[axis] = lengths[axis]
    if boxsize is not None and pos.shape[1] > 2:
        boxsize = np.r_[boxsize, np.zeros(pos.shape[1] - 2)]
    cutoff = 2.0 * float(rad.max()) + tolerance
    tree = cKDTree(pos, boxsize=boxsize)
    pairs = tree.query_pairs(cutoff, output_type="ndarray").astype(np.int64)
    if pairs.size == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    i, j = pairs[:, 0], pairs[:, 1]
    d = pos[j] - pos[i]
    if boxsize is not None:
        for axis in (0, 1):
            if boxsize[axis] > 0:
                d[:, axis] -= boxsize[axis] * np.round(d[:, axis] / boxsize[axis])
    dist = np.hypot(d[:, 0], d[:, 1]) if d.shape[1] == 2 else np.linalg.norm(d, axis=1)
    touching = dist < rad[i] + rad[j] + tolerance
    i, j = i[touching], j[touching]
    lo, hi = np.minimum(i, j), np.maximum(i, j)
    order = np.argsort(lo * np.int64(pos.shape[0]) + hi)
    return lo[order], hi[order]
