r"""Measures per body: a snapshot of pebbles read as its rigid bodies.

:func:`body_view` gives a snapshot with one particle per body, on which any
measure runs per body; :class:`BodyCoordination`, :class:`BodyStabilityIndex`
and :class:`BodyOrientation` need more than the view. A snapshot of single disks
is its own view (the same bits). Formulas and choices: docs/fabric.md, "Measures
per body".
"""

from __future__ import annotations

import dataclasses
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from grainlab.analysis._compute import Compute, Computed
from grainlab.analysis._util import EndAngles, axial_direction, sample_bounds
from grainlab.analysis.fabric import CoordinationNumber, anisotropy_fourier, fabric_tensor
from grainlab.analysis.stability import StabilityIndex, lambda_of
from grainlab.analysis.stress import contact_points
from grainlab.bodies import clump_mass_properties
from grainlab.snapshot import (
    BODY_FIELD,
    GRAIN_ANGLE_FIELD,
    GRAIN_CENTROID_FIELD,
    TWO_PI,
    Snapshot,
)

__all__ = [
    "BODY_DIRECTIONS",
    "BodyCoordination",
    "BodyOrientation",
    "BodyStabilityIndex",
    "BodyView",
    "body_view",
    "has_clumps",
]

#: The directions lambda per body reads a contact at: from the body's centroid to
#: the contact point (default), or the contact normal.
BODY_DIRECTIONS = ("contact_point", "normal")

#: A body's pebble layout has no long axis when the two eigenvalues of its second
#: moment differ by less than this fraction of their sum (a disk, an equilateral trimer).
AXIS_TOLERANCE = 1e-9


@dataclasses.dataclass(frozen=True, eq=False)
class BodyView:
    """A snapshot of pebbles and the snapshot of its bodies (:func:`body_view`)."""

    #: The snapshot given, one particle per pebble.
    pebbles: Snapshot
    #: One particle per body, in the order of each body's first pebble; every
    #: contact between two bodies (the pebbles' contacts between them, in list order).
    snapshot: Snapshot
    #: (N,) the body of each pebble (an index into :attr:`snapshot`).
    body: NDArray[np.int64]
    #: (K,) the pebbles' contact behind each contact of :attr:`snapshot`.
    contact: NDArray[np.int64]
    #: (N, 2) each pebble's centre from its body's centroid, m (minimum image).
    offsets: NDArray[np.float64]
    #: (B,) pebbles per body.
    n_pebbles: NDArray[np.int64]
    #: (B,) each body's area (the union of its pebbles), m^2.
    area: NDArray[np.float64]

    @property
    def identity(self) -> bool:
        """True when every body is one disk: the view is the snapshot itself."""
        return self.snapshot is self.pebbles

    @property
    def n_bodies(self) -> int:
        """B, the number of bodies (all kinds)."""
        return self.snapshot.n_particles

    def pairs(self) -> Snapshot:
        """:attr:`snapshot` with one contact per touching pair of bodies (a body and
        a wall a pair too): the first in the list of the pair's contacts."""
        s = self.snapshot
        ci, cj = np.asarray(s.contact_i), np.asarray(s.contact_j)
        wall = cj < 0
        low = np.where(wall, ci, np.minimum(ci, cj))
        high = np.where(wall, cj, np.maximum(ci, cj))
        _, first = np.unique(np.column_stack([low, high]), axis=0, return_index=True)
        keep = np.zeros(ci.size, bool)
        keep[first] = True
        return s if keep.all() else s.select_contacts(keep)

    def end_angles(self) -> EndAngles:
        """The angle (rad, [0, 2 pi)) of each body contact seen from each of its
        bodies' centroids: towards the contact point; a single disk's end keeps
        its normal's angle (theta on i, theta + pi on j), as for disks."""
        s = self.snapshot
        ci, cj = np.asarray(s.contact_i), np.asarray(s.contact_j)
        wall = cj < 0
        cjs = np.where(wall, ci, cj)
        on_i = np.asarray(s.contact_angles())
        on_j = on_i + np.pi
        on_j[on_j >= TWO_PI] -= TWO_PI
        if s.n_contacts == 0 or s.contact_point is None:
            return on_i, on_j
        x = np.asarray(s.positions)
        point = np.asarray(s.contact_point)
        clump = self.n_pebbles > 1
        towards_i = _angles(s.minimum_image(point - x[ci]))
        towards_j = _angles(s.minimum_image(point - x[cjs]))
        return (
            np.where(clump[ci], towards_i, on_i),
            np.where(~wall & clump[cjs], towards_j, on_j),
        )


def _angles(d: NDArray[np.float64]) -> NDArray[np.float64]:
    """Angles of vectors (K, 2), rad in [0, 2 pi) (a zero vector gives 0)."""
    a = np.arctan2(d[:, 1], d[:, 0])
    a = np.where(a < 0.0, a + TWO_PI, a)
    a[a >= TWO_PI] = 0.0
    return np.asarray(a, dtype=np.float64)


def has_clumps(snapshot: Snapshot) -> bool:
    """Whether some grain of ``snapshot`` has more than one pebble."""
    return snapshot.n_grains != snapshot.n_particles


def body_view(snapshot: Snapshot) -> BodyView:
    """The bodies of ``snapshot`` (docs/fabric.md): the snapshot itself when every
    grain is one disk, else a snapshot with one particle per body.

    A body's centroid is its ``grain_centroid`` field, else the centroid of its
    pebbles' union (:func:`grainlab.bodies.clump_mass_properties`, its pebbles
    taken in one periodic image); its rotation the ``grain_angle`` field (none
    without it, unless every body is a disk); its area the union's. The region
    of the measures is the pebbles' (their box, else the rectangle bounding them).
    """
    n = snapshot.n_particles
    if not has_clumps(snapshot):
        return BodyView(
            snapshot, snapshot, np.arange(n, dtype=np.int64), np.arange(snapshot.n_contacts, dtype=np.int64),
            np.zeros((n, 2)), np.ones(n, dtype=np.int64), np.pi * np.asarray(snapshot.radii) ** 2,
        )
    _, first, inverse = np.unique(snapshot.grains(), return_index=True, return_inverse=True)
    rank = np.empty(first.size, dtype=np.int64)
    rank[np.argsort(first, kind="stable")] = np.arange(first.size)
    body = rank[inverse.reshape(-1)]
    first = np.sort(first)  # the first pebble of each body, in body order
    n_pebbles = np.bincount(body, minlength=first.size)
    centroid, area = _centroids_and_areas(snapshot, body, first, n_pebbles)
    offsets = snapshot.minimum_image(np.asarray(snapshot.positions) - centroid[body])
    bodies, contact = _body_snapshot(snapshot, body, first, n_pebbles, centroid, area)
    return BodyView(snapshot, bodies, body, contact, offsets, n_pebbles, area)


def _centroids_and_areas(
    snapshot: Snapshot, body: NDArray[np.int64], first: NDArray[np.int64], n_pebbles: NDArray[np.int64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(B, 2) centroids and (B,) areas of the bodies (a disk's own centre and pi r^2)."""
    x = np.asarray(snapshot.positions)
    r = np.asarray(snapshot.radii)
    centroid = x[first].copy()
    area = np.pi * r[first] ** 2
    stored = snapshot.particle_fields.get(GRAIN_CENTROID_FIELD)
    order = np.argsort(body, kind="stable")
    start = np.cumsum(n_pebbles) - n_pebbles
    for b in np.flatnonzero(n_pebbles > 1):
        members = order[start[b] : start[b] + n_pebbles[b]]
        local = snapshot.minimum_image(x[members] - x[first[b]])
        props = clump_mass_properties(local, r[members], density=1.0)
        area[b] = props.area_m2
        centroid[b] = x[first[b]] + props.centroid_m if stored is None else np.asarray(stored)[first[b]]
    return centroid, area


def _body_snapshot(
    snapshot: Snapshot,
    body: NDArray[np.int64],
    first: NDArray[np.int64],
    n_pebbles: NDArray[np.int64],
    centroid: NDArray[np.float64],
    area: NDArray[np.float64],
) -> tuple[Snapshot, NDArray[np.int64]]:
    """The snapshot of the bodies and the pebbles' contact behind each of its contacts."""
    r = np.asarray(snapshot.radii)
    radius = np.where(n_pebbles > 1, np.sqrt(area / np.pi), r[first])
    ids = np.full(first.size, np.iinfo(np.int64).max, dtype=np.int64)
    np.minimum.at(ids, body, np.asarray(snapshot.ids))
    rotations = None
    if GRAIN_ANGLE_FIELD in snapshot.particle_fields:
        rotations = np.asarray(snapshot.particle_fields[GRAIN_ANGLE_FIELD])[first].copy()
        if snapshot.rotations is not None:
            single = n_pebbles == 1
            rotations[single] = np.asarray(snapshot.rotations)[first][single]
    ci, cj = np.asarray(snapshot.contact_i), np.asarray(snapshot.contact_j)
    wall = cj < 0
    bi, bj = body[ci], np.where(wall, cj, body[np.where(wall, 0, cj)])
    keep = wall | (bi != bj)
    chains = snapshot.particle_fields.get(BODY_FIELD)  # the membrane chains
    fields = {} if chains is None else {BODY_FIELD: np.asarray(chains)[first]}

    def kept(a: NDArray[Any] | None) -> NDArray[Any] | None:
        return None if a is None else np.asarray(a)[keep]

    bodies = Snapshot(
        centroid,
        radius,
        ids,
        rotations=rotations,
        kind=np.asarray(snapshot.kind)[first],
        contact_i=bi[keep],
        contact_j=bj[keep],
        normal_force=kept(snapshot.normal_force),
        shear_force=kept(snapshot.shear_force),
        contact_normal=np.asarray(snapshot.contact_normals())[keep],
        contact_point=contact_points(snapshot)[keep],
        # a pebble pair's overlap is not the bodies' (their branch is centroid to centroid)
        contact_fields={k: np.asarray(v)[keep] for k, v in snapshot.contact_fields.items() if k != "overlap"},
        particle_fields=fields,
        box=snapshot.box if snapshot.box is not None else sample_bounds(snapshot),
        periodic=snapshot.periodic,
        tilt=snapshot.tilt,
        time=snapshot.time,
        scalars=snapshot.scalars,
        metadata=snapshot.metadata,
    )
    return bodies, np.flatnonzero(keep).astype(np.int64)


def _view(snapshot: Snapshot | BodyView) -> BodyView:
    return snapshot if isinstance(snapshot, BodyView) else body_view(snapshot)


# --------------------------------------------------------------------------- measures
class BodyCoordination(Compute):
    r"""Coordination numbers of the bodies, both ways (docs/fabric.md, "Measures per body").

    .. math:: Z = \frac{2 N_{pairs}}{N_b}, \qquad Z_c = \frac{2 N_c}{N_b}, \qquad Z_c \ge Z,

    the rattlers by the pairs, as :class:`~grainlab.analysis.CoordinationNumber`'s rule;
    for disks every number is CoordinationNumber's.

    Parameters
    ----------
    min_contacts, include_boundary, boundary
        As :class:`~grainlab.analysis.CoordinationNumber`'s (a wall, or a
        membrane disk, touched at two pebbles is one pair).
    """

    _parameters = ("min_contacts", "include_boundary", "boundary")

    def __init__(
        self, min_contacts: int = 2, include_boundary: bool = False, boundary: str = "body"
    ) -> None:
        CoordinationNumber(min_contacts, include_boundary, boundary)  # checks them
        self.min_contacts = int(min_contacts)
        self.include_boundary = bool(include_boundary)
        self.boundary = boundary

    def compute(self, snapshot: Snapshot | BodyView) -> BodyCoordination:
        """Compute the bodies' coordination numbers of ``snapshot`` (or of its
        :func:`body_view`); returns ``self``."""
        view = _view(snapshot)
        s = view.snapshot
        rule = (self.include_boundary, self.boundary)
        pairs = CoordinationNumber(self.min_contacts, *rule).compute(view.pairs())
        contacts = CoordinationNumber(0, *rule).compute(s)
        core = s.is_sample & ~pairs.rattlers
        ci, cj = np.asarray(s.contact_i), np.asarray(s.contact_j)
        other = np.where(cj >= 0, cj, ci)
        among = core[ci] & ((cj < 0) | core[other] | ~s.is_sample[other])
        among |= ~s.is_sample[ci] & core[other]
        kept = CoordinationNumber(0, *rule).compute(s.select_contacts(among))
        n_m = int(core.sum())
        z_cm = float(kept.n_contacts[core].sum() / n_m) if n_m else float("nan")
        self._store(
            coordination_number=pairs.coordination_number,
            contact_coordination_number=contacts.coordination_number,
            mechanical_coordination_number=pairs.mechanical_coordination_number,
            mechanical_contact_coordination_number=z_cm,
            n_neighbours=pairs.n_contacts,
            n_contacts=contacts.n_contacts,
            rattlers=pairs.rattlers,
            count_distribution=pairs.count_distribution,
            n_bodies=pairs.n_particles,
            n_pairs_total=pairs.n_contacts_total,
            n_contacts_total=contacts.n_contacts_total,
        )
        return self

    coordination_number = Computed[float]("Z = 2 N_pairs / N_b: touching pairs of bodies per body.")
    contact_coordination_number = Computed[float]("Z_c = 2 N_c / N_b: contacts per body.")
    mechanical_coordination_number = Computed[float]("Z_m: Z over the bodies left after rattler removal.")
    mechanical_contact_coordination_number = Computed[float](
        "Z_c,m: Z_c over the bodies left after rattler removal, their contacts among them."
    )
    n_neighbours = Computed[NDArray[np.int64]]("(B,) bodies (and walls) each body touches.")
    n_contacts = Computed[NDArray[np.int64]]("(B,) contacts of each body.")
    rattlers = Computed[NDArray[np.bool_]]("(B,) mask of the rattler bodies.")
    count_distribution = Computed[NDArray[np.float64]](
        "Fraction of sample bodies with k neighbours, k = 0, 1, 2, ..."
    )
    n_bodies = Computed[int]("N_b, the number of sample bodies.")
    n_pairs_total = Computed[int]("N_pairs, the touching pairs used.")
    n_contacts_total = Computed[int]("N_c, the contacts used.")


class BodyStabilityIndex(StabilityIndex):
    r"""The stability index lambda of every body (docs/fabric.md, "Measures per body").

    Eqs. 9-11 on the directions of a body's contacts seen from its centroid:
    towards each contact point (``direction="contact_point"``, default), or
    along each contact's normal (``"normal"``); for a disk the two are one, and
    a disk's ends keep the normal's angle. Results as
    :class:`~grainlab.analysis.StabilityIndex`'s, one per body.

    Parameters
    ----------
    include_boundary, boundary, slots, anchor, deviation
        As :class:`~grainlab.analysis.StabilityIndex`'s.
    direction : {"contact_point", "normal"}, default "contact_point"
    """

    _parameters: ClassVar[tuple[str, ...]] = (
        "include_boundary", "boundary", "direction", "slots", "anchor", "deviation"
    )

    def __init__(
        self,
        include_boundary: bool = True,
        boundary: str = "body",
        *,
        direction: str = BODY_DIRECTIONS[0],
        slots: str = "angular",
        anchor: str = "min",
        deviation: str = "sum",
    ) -> None:
        super().__init__(include_boundary, boundary, slots=slots, anchor=anchor, deviation=deviation)
        if direction not in BODY_DIRECTIONS:
            raise ValueError(f"direction: must be 'contact_point' or 'normal', got {direction!r}")
        self.direction = direction

    def compute(self, snapshot: Snapshot | BodyView) -> BodyStabilityIndex:
        """Compute lambda for every body of ``snapshot`` (or of its :func:`body_view`);
        returns ``self``."""
        view = _view(snapshot)
        s = view.snapshot
        ends = None if view.identity or self.direction == "normal" else view.end_angles()
        reading = (self.slots, self.anchor, self.deviation)
        lam, counts = lambda_of(s, self.include_boundary, self.boundary, reading, ends)
        self._store_lambda(s, lam, counts)
        return self


class BodyOrientation(Compute):
    r"""Each body's long axis and the orientation fabric (docs/fabric.md, "Measures per body").

    A body's axis is the major eigenvector of its pebbles' area-weighted second moment
    (NaN for a disk, or when the two eigenvalues differ by less than ``AXIS_TOLERANCE`` of
    their sum); the axes' fabric is the contact normals' (Eq. 6): :math:`a_p = 2(\phi_1 -
    \phi_2)` in [0, 2], :math:`\theta_p` in [0, pi).
    """

    def compute(self, snapshot: Snapshot | BodyView) -> BodyOrientation:
        """Compute the axes of the sample bodies of ``snapshot`` (or of its
        :func:`body_view`) and their fabric; returns ``self``."""
        view = _view(snapshot)
        axis = _long_axes(view)
        axis[~view.snapshot.is_sample] = np.nan
        ok = np.isfinite(axis)
        units = np.column_stack([np.cos(axis[ok]), np.sin(axis[ok])])
        a, direction = anisotropy_fourier(axis[ok])
        self._store(
            axis=axis,
            tensor=fabric_tensor(units),
            anisotropy=a,
            direction=direction,
            n_oriented=int(ok.sum()),
        )
        return self

    axis = Computed[NDArray[np.float64]](
        "(B,) each body's long axis, rad in [0, pi); NaN without one (a disk, a membrane disk)."
    )
    tensor = Computed[NDArray[np.float64]]("(2, 2) fabric tensor of the axes, trace 1.")
    anisotropy = Computed[float]("a_p = 2 |mean exp(2 i theta_b)|, in [0, 2].")
    direction = Computed[float]("theta_p, the mean axis, rad in [0, pi).")
    n_oriented = Computed[int]("Bodies with an axis.")


def _long_axes(view: BodyView) -> NDArray[np.float64]:
    """(B,) the long axis of each body (:class:`BodyOrientation`), NaN without one."""
    b = view.n_bodies
    w = np.pi * np.asarray(view.pebbles.radii) ** 2
    o = view.offsets
    total = np.bincount(view.body, weights=w, minlength=b)
    mean = np.column_stack([np.bincount(view.body, weights=w * o[:, k], minlength=b) for k in (0, 1)])
    d = o - mean[view.body] / total[view.body, None]
    xx = np.bincount(view.body, weights=w * d[:, 0] ** 2, minlength=b)
    yy = np.bincount(view.body, weights=w * d[:, 1] ** 2, minlength=b)
    xy = np.bincount(view.body, weights=w * d[:, 0] * d[:, 1], minlength=b)
    gap = np.hypot(0.5 * (xx - yy), xy)
    axis = np.asarray(axial_direction(np.arctan2(2.0 * xy, xx - yy)), dtype=np.float64)
    return np.where(2.0 * gap > AXIS_TOLERANCE * (xx + yy), axis, np.nan)
