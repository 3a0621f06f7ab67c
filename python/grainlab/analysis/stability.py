r"""The geometrical stability index lambda (paper Sec. 5, Eqs. 9-11).

Definition, range, the readings ``slots`` / ``anchor`` / ``deviation`` (only the
default runs in the compiled kernel) and boundary bodies: docs/fabric.md,
"Geometrical stability index λ".
"""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from grainlab import _core, _kernels
from grainlab.analysis._compute import Compute, Computed
from grainlab.analysis._util import (
    EndAngles,
    contact_ends,
    contact_ends_in_list_order,
    finite_mean,
    has_boundary,
)
from grainlab.snapshot import BOUNDARY_COUNTING, TWO_PI, Snapshot

__all__ = [
    "DEFAULT_READING",
    "LAMBDA_ANCHORS",
    "LAMBDA_DEVIATIONS",
    "LAMBDA_SLOTS",
    "StabilityIndex",
    "stability_index",
    "stability_index_of_angles",
]

#: Readings of Eq. 9-11 (docs/fabric.md), the default first in each.
LAMBDA_SLOTS = ("angular", "list", "nearest")
LAMBDA_ANCHORS = ("min", "mean")
LAMBDA_DEVIATIONS = ("sum", "per_contact")
#: :attr:`StabilityIndex.reading` of the default reading.
DEFAULT_READING = f"{LAMBDA_SLOTS[0]}/{LAMBDA_ANCHORS[0]}/{LAMBDA_DEVIATIONS[0]}"

#: Rows per block in the (m, n, n) kernel, to bound temporary memory.
_BLOCK_ELEMENTS = 1 << 21


def _check_reading(slots: str, anchor: str, deviation: str) -> bool:
    """Validate a reading of Eq. 9-11; True when it is the default one."""
    for option, value, allowed in (
        ("slots", slots, LAMBDA_SLOTS),
        ("anchor", anchor, LAMBDA_ANCHORS),
        ("deviation", deviation, LAMBDA_DEVIATIONS),
    ):
        if value not in allowed:
            names = ", ".join(repr(a) for a in allowed)
            raise ValueError(f"{option}: must be one of {names}, got {value!r}")
    return (slots, anchor, deviation) == (LAMBDA_SLOTS[0], LAMBDA_ANCHORS[0], LAMBDA_DEVIATIONS[0])


def _group_deviation(angles: NDArray[np.float64], n: int) -> NDArray[np.float64]:
    """D (rad) for an (m, n) block of contact angles, rows in any order."""
    a = np.sort(angles, axis=1)
    a -= (TWO_PI / n) * np.arange(n)
    diff = a[:, :, None] - a[:, None, :]
    np.abs(diff, out=diff)
    np.minimum(diff, TWO_PI - diff, out=diff)
    deviation: NDArray[np.float64] = diff.sum(axis=2).min(axis=1)
    return deviation


def _group_reading(
    angles: NDArray[np.float64], n: int, slots: str, anchor: str, deviation: str
) -> NDArray[np.float64]:
    """lambda of an (m, n) block of contact angles in [0, 2 pi], each row in the
    order its contacts were given, under any reading (docs/fabric.md)."""
    step = TWO_PI / n
    if slots == "nearest":
        diff = angles[:, None, :] - angles[:, :, None]  # [row, k, j] = phi_j - phi_k
        np.mod(diff, step, out=diff)
        np.minimum(diff, step - diff, out=diff)
    else:
        a = np.sort(angles, axis=1) if slots == "angular" else angles.copy()
        a -= step * np.arange(n)
        diff = a[:, None, :] - a[:, :, None]  # e_j - e_k, within (-4 pi, 4 pi) for "list"
        np.abs(diff, out=diff)
        np.mod(diff, TWO_PI, out=diff)
        np.minimum(diff, TWO_PI - diff, out=diff)
    per_reference = diff.sum(axis=2)  # dS_n^(k), [row, k]
    d = per_reference.min(axis=1) if anchor == "min" else per_reference.mean(axis=1)
    if deviation == "per_contact":
        d /= n - 1
    lam: NDArray[np.float64] = d / TWO_PI
    return lam


def stability_index(
    owner: ArrayLike,
    angles: ArrayLike,
    n_particles: int,
    *,
    slots: str = "angular",
    anchor: str = "min",
    deviation: str = "sum",
) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Stability index of every particle from its contact ends: ``owner`` (K,) int,
    the particle (``0 <= owner < n_particles``) of each end (a particle-particle
    contact gives two), and ``angles`` (K,) rad, CCW from +x (taken modulo 2 pi).

    Returns ``lam`` (n_particles,), lambda >= 0 (1 for 0 or 1 contact; at most
    floor(n^2/4)/n for n contacts under the default reading), and ``counts``
    (n_particles,), the ends of each particle. ``slots``, ``anchor``,
    ``deviation``: the reading of Eq. 9-11 (docs/fabric.md, "Readings of Eqs.
    9-11"; with ``slots="list"`` a particle's ends are taken in the order given);
    the default runs in the compiled kernel, the others in NumPy.
    """
    default = _check_reading(slots, anchor, deviation)
    owner = np.asarray(owner, dtype=np.int64).reshape(-1)
    ang = np.asarray(angles, dtype=np.float64).reshape(-1)
    if owner.shape != ang.shape:
        raise ValueError(f"angles: expected shape {owner.shape}, got {ang.shape}")
    if owner.size and (owner.min() < 0 or owner.max() >= n_particles):
        raise ValueError(f"owner: indices must be in [0, {n_particles})")
    if default and _kernels.compiled():  # the kernel takes the angles modulo 2 pi itself
        lam, counts = _core.stability_index(
            np.ascontiguousarray(owner), np.ascontiguousarray(ang), int(n_particles), _kernels.threads()
        )
        return lam, counts
    return _stability_index_numpy(
        owner, np.mod(ang, TWO_PI), n_particles, slots=slots, anchor=anchor, deviation=deviation
    )


def _stability_index_numpy(
    owner: NDArray[np.int64],
    ang: NDArray[np.float64],
    n_particles: int,
    *,
    slots: str = "angular",
    anchor: str = "min",
    deviation: str = "sum",
) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """The NumPy reference of :func:`stability_index` (angles already in [0, 2 pi]),
    the only implementation of the non-default readings."""
    default = _check_reading(slots, anchor, deviation)
    counts = np.bincount(owner, minlength=n_particles)
    lam = np.ones(n_particles, dtype=np.float64)
    if owner.size == 0:
        return lam, counts
    order = np.argsort(owner, kind="stable")  # each particle's ends as given ("list")
    ang_sorted = ang[order]
    offsets = np.cumsum(counts) - counts
    degrees = np.unique(counts)
    for n in degrees[degrees >= 2]:  # one pass per distinct contact count
        n = int(n)
        rows = np.flatnonzero(counts == n)
        block = max(1, _BLOCK_ELEMENTS // (n * n))
        cols = np.arange(n)
        for start in range(0, rows.size, block):
            r = rows[start : start + block]
            group = ang_sorted[offsets[r][:, None] + cols]
            if default:
                lam[r] = _group_deviation(group, n) / TWO_PI
            else:
                lam[r] = _group_reading(group, n, slots, anchor, deviation)
    return lam, counts


def stability_index_of_angles(
    angles: ArrayLike,
    *,
    degrees: bool = False,
    slots: str = "angular",
    anchor: str = "min",
    deviation: str = "sum",
) -> float:
    """lambda of one particle with contacts at ``angles`` (rad, or degrees), in
    the order given (which only ``slots="list"`` reads).

    >>> stability_index_of_angles([0, 60, 120], degrees=True)
    0.3333333333333333
    >>> stability_index_of_angles([0, 90], degrees=True)
    0.25
    >>> stability_index_of_angles([0, 120, 60], degrees=True, slots="list")
    0.5
    """
    _check_reading(slots, anchor, deviation)
    a = np.asarray(angles, dtype=np.float64).reshape(-1)
    if degrees:
        a = np.radians(a)
    lam, _ = stability_index(
        np.zeros(a.size, np.int64), a, 1, slots=slots, anchor=anchor, deviation=deviation
    )
    return float(lam[0])


def lambda_of(
    snapshot: Snapshot,
    include_boundary: bool,
    boundary: str,
    reading: tuple[str, str, str] = (LAMBDA_SLOTS[0], LAMBDA_ANCHORS[0], LAMBDA_DEVIATIONS[0]),
    end_angles: EndAngles | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """lambda and the contact counts of every particle of ``snapshot`` (what
    :class:`StabilityIndex` stores), under ``reading`` (slots, anchor, deviation);
    ``end_angles``: each contact's angle on i and on j instead of the normal's
    (:func:`grainlab.analysis._util.contact_ends`)."""
    slots, anchor, deviation = reading
    if not _check_reading(slots, anchor, deviation):
        # NumPy only; the ends in contact-list order, which "list" reads
        owner, ends, _ = contact_ends_in_list_order(
            snapshot, include_boundary=include_boundary, boundary=boundary, end_angles=end_angles
        )
        return stability_index(
            owner, ends, snapshot.n_particles, slots=slots, anchor=anchor, deviation=deviation
        )
    if end_angles is None and _kernels.compiled() and not has_boundary(snapshot):
        # no wall, no membrane: the kernel takes both ends of every contact itself
        lam, counts = _core.stability_index_of_contacts(
            np.ascontiguousarray(snapshot.contact_i),
            np.ascontiguousarray(snapshot.contact_j),
            np.ascontiguousarray(snapshot.contact_angles()),
            snapshot.n_particles,
            _kernels.threads(),
        )
        return lam, counts
    owner, ends, _ = contact_ends(
        snapshot, include_boundary=include_boundary, boundary=boundary, end_angles=end_angles
    )
    return stability_index(owner, ends, snapshot.n_particles)


class StabilityIndex(Compute):
    r"""Geometrical stability index lambda of every particle (paper Sec. 5).

    The formula: docs/fabric.md. Contact angles come from the
    snapshot's contact normals (direction from the particle's centre towards
    the other particle or the wall, docs/conventions.md).

    Parameters
    ----------
    include_boundary : bool, default True
        Count contacts with walls and membrane particles (the paper takes all
        of a particle's active contacts); False: only those between sample
        particles.
    boundary : {"body", "each"}, default "body"
        ``"body"``: each boundary body (a wall, one membrane chain) is one
        contact of the grain, at the normal-force-weighted mean direction of
        its contacts with it; ``"each"``: every contact (docs/fabric.md,
        "Boundary contacts").
    slots : {"angular", "list", "nearest"}, default "angular"
    anchor : {"min", "mean"}, default "min"
    deviation : {"sum", "per_contact"}, default "sum"
        Keyword only: the reading of Eq. 9-11 (docs/fabric.md, "Readings of
        Eqs. 9-11"; ``slots="list"`` takes a particle's contacts in the order
        of the contact list). The default runs in the compiled kernel, the
        others in NumPy.

    Example
    -------
    >>> from grainlab.snapshot import Snapshot
    >>> import numpy as np
    >>> angles = np.radians([0.0, 60.0, 120.0])
    >>> snap = Snapshot.from_geometry(
    ...     np.vstack([[0.0, 0.0], 2.0 * np.c_[np.cos(angles), np.sin(angles)]]),
    ...     np.ones(4), tolerance=1e-9)
    >>> round(float(StabilityIndex().compute(snap).stability_index[0]), 12)
    0.333333333333
    """

    _parameters: ClassVar[tuple[str, ...]] = ("include_boundary", "boundary", "slots", "anchor", "deviation")

    def __init__(
        self,
        include_boundary: bool = True,
        boundary: str = "body",
        *,
        slots: str = "angular",
        anchor: str = "min",
        deviation: str = "sum",
    ) -> None:
        if boundary not in BOUNDARY_COUNTING:
            raise ValueError(f"boundary: must be 'body' or 'each', got {boundary!r}")
        _check_reading(slots, anchor, deviation)
        self.include_boundary = bool(include_boundary)
        self.boundary = boundary
        self.slots = slots
        self.anchor = anchor
        self.deviation = deviation

    @property
    def reading(self) -> str:
        """The reading of Eq. 9-11 as ``"slots/anchor/deviation"`` (default
        ``"angular/min/sum"``)."""
        return f"{self.slots}/{self.anchor}/{self.deviation}"

    def compute(self, snapshot: Snapshot) -> StabilityIndex:
        """Compute lambda for every particle of ``snapshot``; returns ``self``."""
        lam, counts = lambda_of(
            snapshot, self.include_boundary, self.boundary, (self.slots, self.anchor, self.deviation)
        )
        return self._store_lambda(snapshot, lam, counts)

    def _store_lambda(
        self, snapshot: Snapshot, lam: NDArray[np.float64], counts: NDArray[np.int64]
    ) -> StabilityIndex:
        """Store lambda and the contact counts of ``snapshot``'s particles (NaN for
        membrane particles) with their means; returns ``self``."""
        sample = snapshot.is_sample
        lam[~sample] = np.nan
        self._store(
            stability_index=lam,
            n_contacts=counts,
            mean=finite_mean(lam, sample & (counts >= 2)),
            mean_all=finite_mean(lam, sample),
            _snapshot=snapshot,
        )
        return self

    stability_index = Computed[NDArray[np.float64]](
        "(N,) lambda >= 0 per particle (1 with 0 or 1 contact; above 1 under the default "
        "reading only with five or more crowded contacts); NaN for membrane particles."
    )
    n_contacts = Computed[NDArray[np.int64]](
        "(N,) contacts per particle as lambda counts them (each boundary body once with "
        "``boundary='body'``; 0 for membrane particles)."
    )
    mean = Computed[float](
        "Mean lambda over sample particles with >= 2 contacts (the paper filters out those "
        "with 0 or 1, whose lambda is 1 by definition)."
    )
    _snapshot = Computed[Snapshot]("The snapshot measured (drawn by plot).")
    mean_all = Computed[float]("Mean lambda over all sample particles (0/1 contact counted as 1).")

    def plot(self, ax: Any = None, **kwargs: Any) -> Any:
        """Particle map coloured by lambda (paper Fig. 12); returns the axes."""
        from grainlab import plot

        snap = self._snapshot
        return plot.particle_map(
            snap.positions,
            snap.radii,
            self.stability_index,
            ax=ax,
            label=r"geometrical stability index $\lambda$",
            vmin=0.0,
            vmax=1.0,
            **kwargs,
        )
