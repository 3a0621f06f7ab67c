r"""Kinematics between two snapshots: displacement, rotation, local strain, D2min.

Particles matched by id; results indexed like the current snapshot, NaN where
unmatched. Formulas and signs: docs/fabric.md, "Local strain and D2min".
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from grainlab.analysis._compute import Compute, Computed
from grainlab.snapshot import Snapshot

__all__ = ["LocalStrain", "match_ids", "neighbour_pairs"]


def match_ids(reference: Snapshot, current: Snapshot) -> NDArray[np.int64]:
    """(N_current,) index in ``reference`` of each current particle, -1 if absent."""
    return reference.index_of(np.asarray(current.ids))


def neighbour_pairs(
    snapshot: Snapshot, cutoff: float
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Unordered pairs ``i < j`` of particles with centre distance < ``cutoff`` (m)."""
    if not np.isfinite(cutoff) or cutoff <= 0:
        raise ValueError(f"cutoff: must be a positive length in m, got {cutoff!r}")
    if snapshot.tilt != 0.0:
        raise ValueError(
            f"tilt: neighbour pairs in a leaning periodic cell (tilt {snapshot.tilt!r} m) are not supported"
        )
    pos = np.asarray(snapshot.positions, dtype=np.float64)
    boxsize = None
    if any(snapshot.periodic):
        box = np.asarray(snapshot.box)
        lengths = box[:, 1] - box[:, 0]
        pos = pos.copy()
        boxsize = np.zeros(2)
        for axis in (0, 1):
            if snapshot.periodic[axis]:
                pos[:, axis] = np.mod(pos[:, axis] - box[axis, 0], lengths[axis])
                pos[pos[:, axis] >= lengths[axis], axis] = 0.0
                boxsize[axis] = lengths[axis]
    pairs = (
        cKDTree(pos, boxsize=boxsize).query_pairs(cutoff, output_type="ndarray").astype(np.int64)
    )
    if pairs.size == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    return pairs[:, 0], pairs[:, 1]


def _deformation_gradients(
    own: NDArray[np.int64],
    d0: NDArray[np.float64],
    d: NDArray[np.float64],
    n: int,
    matched: NDArray[np.bool_],
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.int64]]:
    """Each particle's best-fit ``F`` (N, 2, 2) mapping its reference branch vectors
    ``d0`` (K, 2) to the current ones ``d`` (K, 2) (``own`` (K,): the owner of each),
    the residual D2min (N,) m² and the neighbour count (N,); NaN where fewer than 2
    neighbours or a degenerate neighbourhood leave F undetermined."""

    def acc(w: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.bincount(own, weights=w, minlength=n).astype(np.float64)

    x = np.stack(
        [
            acc(d[:, 0] * d0[:, 0]),
            acc(d[:, 0] * d0[:, 1]),
            acc(d[:, 1] * d0[:, 0]),
            acc(d[:, 1] * d0[:, 1]),
        ],
        axis=1,
    ).reshape(n, 2, 2)
    y00, y01, y11 = acc(d0[:, 0] ** 2), acc(d0[:, 0] * d0[:, 1]), acc(d0[:, 1] ** 2)
    det = y00 * y11 - y01 * y01
    count = np.bincount(own, minlength=n)
    good = (count >= 2) & (det > 1e-10 * (y00 + y11) ** 2) & matched
    inv = np.zeros((n, 2, 2))
    safe = np.where(good, det, 1.0)
    inv[:, 0, 0] = y11 / safe
    inv[:, 1, 1] = y00 / safe
    inv[:, 0, 1] = inv[:, 1, 0] = -y01 / safe
    F = np.einsum("nij,njk->nik", x, inv)
    F[~good] = np.nan

    resid = d - np.einsum("kij,kj->ki", F[own], d0)
    d2min = np.bincount(own, weights=np.einsum("ki,ki->k", resid, resid), minlength=n).astype(
        np.float64
    )
    d2min[~good] = np.nan
    return F, d2min, count


class LocalStrain(Compute):
    r"""Displacement, rotation, best-fit local strain and D2min between two snapshots.

    Formulas and sign conventions: docs/fabric.md.

    Parameters
    ----------
    neighbours : {"radius", "contacts"}, default "radius"
        Neighbourhood of each particle in the reference snapshot: all centres
        within ``cutoff``, or its particle–particle contacts.
    cutoff : float, m, optional
        Neighbour radius for ``"radius"``; default 2 mean diameters of the
        reference snapshot (about the second shell of neighbours).
    strain : {"small", "green"}, default "small"
        Infinitesimal strain from sym(F) or Green–Lagrange strain.

    Example
    -------
    >>> import numpy as np
    >>> from grainlab.snapshot import Snapshot
    >>> x, y = np.meshgrid(np.arange(8.0), np.arange(8.0))
    >>> ref = Snapshot(np.c_[x.ravel(), y.ravel()], np.full(64, 0.5))
    >>> F = np.array([[1.0, 0.02], [0.0, 1.0]])            # simple shear 0.02
    >>> cur = Snapshot(ref.positions @ F.T, ref.radii)
    >>> s = LocalStrain(cutoff=1.5).compute(ref, cur)
    >>> bool(np.allclose(s.shear_strain, 0.02)) and bool(np.allclose(s.d2min, 0.0))
    True
    """

    _parameters = ("neighbours", "cutoff", "strain=strain_measure")

    def __init__(
        self, neighbours: str = "radius", cutoff: float | None = None, strain: str = "small"
    ) -> None:
        if neighbours not in ("radius", "contacts"):
            raise ValueError(f"neighbours: must be 'radius' or 'contacts', got {neighbours!r}")
        if strain not in ("small", "green"):
            raise ValueError(f"strain: must be 'small' or 'green', got {strain!r}")
        if cutoff is not None and (not np.isfinite(cutoff) or cutoff <= 0):
            raise ValueError(f"cutoff: must be a positive length in m, got {cutoff!r}")
        self.neighbours = neighbours
        self.cutoff = cutoff
        self.strain_measure = strain

    def compute(self, reference: Snapshot, current: Snapshot) -> LocalStrain:
        """Compute the fields of ``current`` relative to ``reference``; returns ``self``."""
        n = current.n_particles
        to_ref = match_ids(reference, current)  # (n,) ref index or -1
        matched = to_ref >= 0
        # current index of each reference particle
        to_cur = np.full(reference.n_particles, -1, np.int64)
        to_cur[to_ref[matched]] = np.flatnonzero(matched)

        disp = np.full((n, 2), np.nan)
        disp[matched] = current.minimum_image(
            current.positions[matched] - reference.positions[to_ref[matched]]
        )
        rot = np.full(n, np.nan)
        if reference.rotations is not None and current.rotations is not None:
            rot[matched] = current.rotations[matched] - reference.rotations[to_ref[matched]]

        # neighbour pairs in the reference, mapped to current indices
        if self.neighbours == "contacts":
            ri, rj = np.asarray(reference.contact_i), np.asarray(reference.contact_j)
            pp = rj >= 0
            ri, rj = ri[pp], rj[pp]
            cutoff = float("nan")
        else:
            cutoff = (
                self.cutoff
                if self.cutoff is not None
                else 2.0 * float(np.mean(reference.diameters))
            )
            ri, rj = neighbour_pairs(reference, cutoff)
        a, b = to_cur[ri], to_cur[rj]
        ok = (a >= 0) & (b >= 0)
        ri, rj, a, b = ri[ok], rj[ok], a[ok], b[ok]
        # both directions: (owner, other)
        own = np.concatenate([a, b])
        d0 = reference.minimum_image(reference.positions[rj] - reference.positions[ri])
        d = current.minimum_image(current.positions[b] - current.positions[a])
        d0 = np.concatenate([d0, -d0])
        d = np.concatenate([d, -d])

        F, d2min, count = _deformation_gradients(own, d0, d, n, matched)

        eye = np.eye(2)
        if self.strain_measure == "small":
            eps = eye - 0.5 * (F + np.swapaxes(F, 1, 2))
        else:
            eps = -0.5 * (np.einsum("nki,nkj->nij", F, F) - eye)
        shear = np.hypot(eps[:, 0, 0] - eps[:, 1, 1], 2.0 * eps[:, 0, 1])
        finite = np.isfinite(eps[:, 0, 0])
        background = np.median(eps[finite], axis=0) if finite.any() else np.full((2, 2), np.nan)
        dev = eps - background
        excess = np.hypot(dev[:, 0, 0] - dev[:, 1, 1], 2.0 * dev[:, 0, 1])
        self._store(
            displacement=disp,
            rotation=rot,
            deformation_gradient=F,
            strain=eps,
            shear_strain=shear,
            excess_shear_strain=excess,
            background_strain=background,
            volumetric_strain=eps[:, 0, 0] + eps[:, 1, 1],
            d2min=d2min,
            n_neighbours=count,
            cutoff_used=cutoff,
            _current=current,
        )
        return self

    displacement = Computed[NDArray[np.float64]]("(N, 2) displacement from the reference, m.")

    @property
    def displacement_magnitude(self) -> NDArray[np.float64]:
        """(N,) |displacement|, m."""
        d = self.displacement
        return np.hypot(d[:, 0], d[:, 1])

    rotation = Computed[NDArray[np.float64]](
        "(N,) rotation increment, rad, CCW positive (NaN unless both snapshots have rotations)."
    )
    deformation_gradient = Computed[NDArray[np.float64]](
        "(N, 2, 2) best-fit local deformation gradient F."
    )
    strain = Computed[NDArray[np.float64]]("(N, 2, 2) local strain tensor, compression positive.")
    shear_strain = Computed[NDArray[np.float64]](
        "(N,) maximum engineering shear strain (2D shear invariant)."
    )
    excess_shear_strain = Computed[NDArray[np.float64]](
        "(N,) shear invariant of the local strain minus the background strain."
    )
    background_strain = Computed[NDArray[np.float64]](
        "(2, 2) component-wise median of the local strains (compression positive)."
    )
    volumetric_strain = Computed[NDArray[np.float64]](
        "(N,) volumetric strain, compression positive."
    )
    d2min = Computed[NDArray[np.float64]]("(N,) Falk–Langer D2min, m².")
    n_neighbours = Computed[NDArray[np.int64]](
        "(N,) number of reference neighbours used in the fit."
    )
    cutoff_used = Computed[float]("Neighbour radius used, m (NaN for neighbours='contacts').")
    _current = Computed[Snapshot]("The current snapshot (drawn by plot).")

    def plot(self, ax: Any = None, quantity: str = "displacement", **kwargs: Any) -> Any:
        """Particle map coloured by displacement magnitude (Fig. 11) or shear strain."""
        from grainlab import plot

        snap = self._current
        if quantity == "displacement":
            values, label = self.displacement_magnitude, "displacement magnitude (m)"
        elif quantity == "shear_strain":
            values, label = self.shear_strain, r"local shear strain $\gamma$"
        else:
            raise ValueError(
                f"quantity: must be 'displacement' or 'shear_strain', got {quantity!r}"
            )
        return plot.particle_map(snap.positions, snap.radii, values, ax=ax, label=label, **kwargs)
