r"""Fabric measures: coordination numbers, the contact-normal distribution, anisotropy.

Angles in rad, CCW from +x; only contacts between sample particles count unless
``include_boundary``. Formulas (Z, Z_m, Eq. 6-8, a_n), binning effects and lattice
answers: docs/fabric.md, "Coordination number Z" to "Contact-force anisotropy a_n".
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from grainlab import _core, _kernels
from grainlab.analysis._compute import Compute, Computed
from grainlab.analysis._util import contact_ends, has_boundary, repeated_boundary_contacts
from grainlab.snapshot import BOUNDARY_COUNTING, TWO_PI, Snapshot

__all__ = [
    "EDGE_TOLERANCE_RAD",
    "ContactAnisotropy",
    "CoordinationNumber",
    "anisotropy_eq7",
    "anisotropy_fourier",
    "angular_histogram",
    "fabric_tensor",
    "rattlers",
]


# --------------------------------------------------------------------------- functions
def rattlers(
    contact_i: ArrayLike,
    contact_j: ArrayLike,
    n_particles: int,
    *,
    min_contacts: int = 2,
    candidates: ArrayLike | None = None,
) -> NDArray[np.bool_]:
    """Iteratively find the rattlers: particles left with < ``min_contacts`` contacts.

    ``contact_j < 0`` (walls) count for particle i only. ``candidates`` (N,)
    bool limits which particles may be removed (others are kept and never
    counted as rattlers; default all). Returns an (N,) bool mask.
    """
    ci = np.asarray(contact_i, dtype=np.int64)
    cj = np.asarray(contact_j, dtype=np.int64)
    if _kernels.compiled():
        mask = None if candidates is None else np.ascontiguousarray(candidates, dtype=bool)
        return _core.rattlers(
            np.ascontiguousarray(ci.reshape(-1)),
            np.ascontiguousarray(cj.reshape(-1)),
            int(n_particles),
            int(min_contacts),
            mask,
            _kernels.threads(),
        )
    return _rattlers_numpy(ci, cj, n_particles, min_contacts, candidates)


def _rattlers_numpy(
    ci: NDArray[np.int64],
    cj: NDArray[np.int64],
    n_particles: int,
    min_contacts: int,
    candidates: ArrayLike | None,
) -> NDArray[np.bool_]:
    """The NumPy reference of :func:`rattlers`: rounds of removal until none is left."""
    removable = np.ones(n_particles, bool) if candidates is None else np.asarray(candidates, bool)
    removed = np.zeros(n_particles, bool)
    alive = np.ones(ci.shape, bool)
    pp = cj >= 0
    cj_safe = np.where(pp, cj, 0)
    while True:  # iterations of removal, not a loop over particles
        counts = np.bincount(ci[alive], minlength=n_particles)
        counts += np.bincount(cj[alive & pp], minlength=n_particles)
        newly = removable & ~removed & (counts < min_contacts)
        if not newly.any():
            return removed
        removed |= newly
        alive &= ~removed[ci] & ~(pp & removed[cj_safe])


#: Angles (rad) closer than this to a bin edge count half to each neighbouring bin:
#: far above the round-off of an angle computed from positions (about 1e-15 rad),
#: far below any physical spread of contact directions.
EDGE_TOLERANCE_RAD = 1e-9


def angular_histogram(
    angles: ArrayLike,
    bins: int = 18,
    weights: ArrayLike | None = None,
    *,
    edge_tolerance: float = EDGE_TOLERANCE_RAD,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Histogram of contact normals over [0, 2 pi), each counted in both directions.

    Returns ``(values (bins,), edges (bins + 1,))``; ``values`` are counts, or
    sums of ``weights``. Bin g covers ``[edges[g], edges[g+1])``; an angle
    closer than ``edge_tolerance`` (rad, >= 0) to an edge counts half to each
    of the two bins beside it (0: every angle in the bin that holds it).

    >>> angular_histogram([0.0, np.pi / 4], bins=4)[0].tolist()
    [1.5, 0.5, 1.5, 0.5]
    """
    if int(bins) != bins or bins < 2:
        raise ValueError(f"bins: must be an integer >= 2, got {bins!r}")
    tol = float(edge_tolerance)
    width = TWO_PI / int(bins)
    if not 0.0 <= tol < 0.5 * width:
        raise ValueError(
            f"edge_tolerance: must be >= 0 and below half a bin ({0.5 * width:g} rad), got {edge_tolerance!r}"
        )
    bins = int(bins)
    angles_in = np.asarray(angles, dtype=np.float64).reshape(-1)
    w = (
        np.ones(angles_in.shape)
        if weights is None
        else np.asarray(weights, dtype=np.float64).reshape(-1)
    )
    if w.shape != angles_in.shape:
        raise ValueError(f"weights: expected shape {angles_in.shape}, got {w.shape}")
    if _kernels.compiled():  # the kernel takes the angles modulo 2 pi itself
        values = _core.angular_histogram(
            np.ascontiguousarray(angles_in),
            None if weights is None else np.ascontiguousarray(w),
            bins,
            tol,
            _kernels.threads(),
        )
        return values, np.linspace(0.0, TWO_PI, bins + 1)
    a = np.mod(angles_in, TWO_PI)
    values = np.zeros(bins)
    for end in (a, np.mod(a + np.pi, TWO_PI)):
        u = end / width
        edge = np.rint(u)
        on_edge = np.abs(u - edge) * width < tol
        inside = np.floor(u)
        lower = np.where(on_edge, edge - 1, inside).astype(np.int64) % bins
        upper = np.where(on_edge, edge, inside).astype(np.int64) % bins
        values += np.bincount(lower, weights=0.5 * w, minlength=bins)
        values += np.bincount(upper, weights=0.5 * w, minlength=bins)
    return values, np.linspace(0.0, TWO_PI, bins + 1)


def anisotropy_eq7(values: ArrayLike) -> tuple[float, float]:
    """``(a, theta_a)`` from a histogram by Eq. 7–8 as printed (theta_a in rad, [0, pi)).

    ``values`` are the bin contents N_g of ``ng`` equal bins starting at 0.
    Returns (nan, nan) for an empty histogram.
    """
    ng_values = np.asarray(values, dtype=np.float64).reshape(-1)
    ng = ng_values.size
    total = ng_values.sum()
    if total <= 0:
        return float("nan"), float("nan")
    dtheta = TWO_PI / ng
    arg = (2 * np.arange(1, ng + 1) - 1) * dtheta
    s = float(np.dot(ng_values, np.sin(arg)))
    c = float(np.dot(ng_values, np.cos(arg)))
    a = 2.0 * np.sin(dtheta) / (total * dtheta) * np.hypot(s, c)
    return float(a), float(np.mod(0.5 * np.arctan2(s, c), np.pi))


def anisotropy_fourier(angles: ArrayLike, weights: ArrayLike | None = None) -> tuple[float, float]:
    """Unbinned ``(a, theta_a)`` from the second Fourier moment (theta_a in rad, [0, pi))."""
    a = np.asarray(angles, dtype=np.float64).reshape(-1)
    if _kernels.compiled():
        w = None if weights is None else np.asarray(weights, dtype=np.float64).reshape(-1)
        if w is not None and w.shape != a.shape:
            raise ValueError(f"weights: expected shape {a.shape}, got {w.shape}")
        s, c, total = _core.fourier_moment(
            np.ascontiguousarray(a),
            None if w is None else np.ascontiguousarray(w),
            _kernels.threads(),
        )
        if a.size == 0 or total <= 0:
            return float("nan"), float("nan")
    else:
        w = np.ones_like(a) if weights is None else np.asarray(weights, dtype=np.float64).reshape(-1)
        total = w.sum()
        if a.size == 0 or total <= 0:
            return float("nan"), float("nan")
        two = 2.0 * a
        s = float(np.dot(w, np.sin(two)))
        c = float(np.dot(w, np.cos(two)))
    return float(2.0 * np.hypot(s, c) / total), float(np.mod(0.5 * np.arctan2(s, c), np.pi))


def fabric_tensor(normals: ArrayLike, weights: ArrayLike | None = None) -> NDArray[np.float64]:
    """2D fabric tensor ``phi = sum w n (x) n / sum w`` (2, 2), trace 1.

    ``normals`` (Nc, 2) unit vectors (sign irrelevant); ``weights`` (Nc,)
    optional (e.g. normal forces). NaN matrix when empty.
    """
    n = np.asarray(normals, dtype=np.float64).reshape(-1, 2)
    if _kernels.compiled():
        w = None if weights is None else np.asarray(weights, dtype=np.float64).reshape(-1)
        if w is not None and w.shape != (n.shape[0],):
            raise ValueError(f"weights: expected shape ({n.shape[0]},), got {w.shape}")
        phi, _ = _core.fabric_tensor(
            np.ascontiguousarray(n),
            None if w is None else np.ascontiguousarray(w),
            _kernels.threads(),
        )
        return phi
    w = (
        np.ones(n.shape[0])
        if weights is None
        else np.asarray(weights, dtype=np.float64).reshape(-1)
    )
    total = w.sum()
    if n.shape[0] == 0 or total <= 0:
        return np.full((2, 2), np.nan)
    xx = np.dot(w, n[:, 0] * n[:, 0])
    yy = np.dot(w, n[:, 1] * n[:, 1])
    xy = np.dot(w, n[:, 0] * n[:, 1])
    tensor: NDArray[np.float64] = np.array([[xx, xy], [xy, yy]]) / total
    return tensor


# --------------------------------------------------------------------------- classes
class CoordinationNumber(Compute):
    """Coordination number Z, mechanical coordination number Z_m (after the iterative
    rattler removal), contact counts: docs/fabric.md, "Coordination number Z" and
    "Mechanical coordination number Z_m".

    Parameters
    ----------
    min_contacts : int, default 2
        Rattler threshold: particles with fewer contacts are removed,
        iteratively, before computing Z_m.
    include_boundary : bool, default False
        Count contacts with walls and membrane particles.
    boundary : {"body", "each"}, default "body"
        With ``include_boundary``: ``"body"`` counts a grain's contacts with
        one boundary body (a wall, one membrane chain) as one contact, as
        :class:`~grainlab.analysis.StabilityIndex` does; ``"each"`` counts
        every contact (every membrane disk touched).

    Example
    -------
    >>> import numpy as np
    >>> from grainlab.snapshot import Snapshot
    >>> x, y = np.meshgrid(np.arange(6.0), np.arange(6.0))
    >>> snap = Snapshot.from_geometry(np.c_[x.ravel(), y.ravel()], np.full(36, 0.5),
    ...                               box=[[0, 6], [0, 6]], periodic=(True, True), tolerance=1e-9)
    >>> CoordinationNumber().compute(snap).coordination_number
    4.0
    """

    _parameters = ("min_contacts", "include_boundary", "boundary")

    def __init__(
        self, min_contacts: int = 2, include_boundary: bool = False, boundary: str = "body"
    ) -> None:
        if int(min_contacts) != min_contacts or min_contacts < 0:
            raise ValueError(f"min_contacts: must be an integer >= 0, got {min_contacts!r}")
        if boundary not in BOUNDARY_COUNTING:
            raise ValueError(f"boundary: must be 'body' or 'each', got {boundary!r}")
        self.min_contacts = int(min_contacts)
        self.include_boundary = bool(include_boundary)
        self.boundary = boundary

    def compute(self, snapshot: Snapshot) -> CoordinationNumber:
        """Compute the coordination numbers of ``snapshot``; returns ``self``."""
        n = snapshot.n_particles
        sample = snapshot.is_sample
        fast = _kernels.compiled() and not has_boundary(snapshot)
        if fast:  # no wall, no membrane: each contact counts for both its particles
            counts = np.bincount(np.asarray(snapshot.contact_i), minlength=n)
            counts += np.bincount(np.asarray(snapshot.contact_j), minlength=n)
        else:
            owner, _, used = contact_ends(
                snapshot, include_boundary=self.include_boundary, boundary=self.boundary
            )
            if self.include_boundary and self.boundary == "body":
                used = used & ~repeated_boundary_contacts(snapshot, used)
            counts = np.bincount(owner, minlength=n)
        n_p = int(sample.sum())
        z = float(counts[sample].sum() / n_p) if n_p else float("nan")
        if fast:  # every particle in the sample, every contact between two of them
            a = np.asarray(snapshot.contact_i)
            b = np.asarray(snapshot.contact_j)
            rat = rattlers(a, b, n, min_contacts=self.min_contacts)
            core = ~rat
            alive = core[a] & core[b]
        else:
            # Contact list seen from the sample: an end on a membrane particle is dropped
            # (j = -1 then means "counts for i only", like a wall).
            a = np.asarray(snapshot.contact_i)[used]
            b = np.asarray(snapshot.contact_j)[used]
            b_is_p = b >= 0
            b_sample = b_is_p & sample[np.where(b_is_p, b, 0)]
            a_sample = sample[a]
            a, b = np.where(a_sample, a, b), np.where(a_sample, np.where(b_sample, b, -1), -1)
            on_sample = a_sample | b_sample
            a, b = a[on_sample], b[on_sample]
            rat = rattlers(a, b, n, min_contacts=self.min_contacts, candidates=sample)
            core = sample & ~rat
            alive = core[a] & ((b < 0) | core[np.where(b >= 0, b, 0)])
        n_m = int(core.sum())
        z_m = float((alive.sum() + (alive & (b >= 0)).sum()) / n_m) if n_m else float("nan")
        dist = np.bincount(counts[sample]).astype(np.float64) if n_p else np.zeros(1)
        if n_p:
            dist /= n_p
        self._store(
            coordination_number=z,
            mechanical_coordination_number=z_m,
            n_contacts=counts,
            rattlers=rat,
            count_distribution=dist,
            n_particles=n_p,
            n_contacts_total=int(a.size),
        )
        return self

    coordination_number = Computed[float]("Z = 2 Nc / Np.")
    mechanical_coordination_number = Computed[float](
        "Z_m over the particles left after iterative rattler removal."
    )
    n_contacts = Computed[NDArray[np.int64]]("(N,) contacts per particle (0 for membrane particles).")
    rattlers = Computed[NDArray[np.bool_]]("(N,) mask of the rattlers.")
    count_distribution = Computed[NDArray[np.float64]](
        "Fraction of sample particles with k contacts, k = 0, 1, 2, ..."
    )
    n_particles = Computed[int]("N_p, the number of sample particles.")
    n_contacts_total = Computed[int]("N_c, the number of contacts used.")

    def plot(self, ax: Any = None) -> Any:
        """Bar chart of the contact-count distribution; returns the axes."""
        from grainlab import plot

        return plot.contact_count_distribution(self.count_distribution, ax=ax)


class ContactAnisotropy(Compute):
    """Contact-normal (or normal-force) distribution and its anisotropy (Eq. 6–8).

    The headline :attr:`anisotropy` and :attr:`direction` are the exact (unbinned)
    estimate from the second Fourier moment; :attr:`anisotropy_binned` and
    :attr:`direction_binned` the paper's Eq. 7–8 on the histogram (docs/fabric.md,
    "Contact-normal distribution and anisotropy (Eq. 6–8)").

    Parameters
    ----------
    bins : int, default 18
        Number of angular bins ``ng`` over 360° (18 bins of 20° in the paper),
        for the histogram and the binned value.
    weight : {"count", "normal_force"}, default "count"
        ``"count"`` gives a and theta_a; ``"normal_force"`` weights each
        contact by its normal force, giving a_n (the snapshot needs forces).
    include_boundary : bool, default False
        Include contacts with walls and membrane particles (every contact:
        the distribution is one of contact normals).
    edge_tolerance : float, rad, default :data:`EDGE_TOLERANCE_RAD`
        Angles this close to a bin edge count half to each neighbouring bin.

    Example
    -------
    >>> import numpy as np
    >>> from grainlab.snapshot import Snapshot
    >>> x, y = np.meshgrid(np.arange(6.0), np.arange(6.0))
    >>> snap = Snapshot.from_geometry(np.c_[x.ravel(), y.ravel()], np.full(36, 0.5),
    ...                               box=[[0, 6], [0, 6]], periodic=(True, True), tolerance=1e-9)
    >>> fabric = ContactAnisotropy().compute(snap)  # a square lattice
    >>> round(fabric.anisotropy, 12), round(fabric.anisotropy_binned, 4)
    (0.0, 0.0591)
    """

    _parameters = ("bins", "weight", "include_boundary", "edge_tolerance")

    def __init__(
        self,
        bins: int = 18,
        weight: str = "count",
        include_boundary: bool = False,
        edge_tolerance: float = EDGE_TOLERANCE_RAD,
    ) -> None:
        if int(bins) != bins or bins < 2:
            raise ValueError(f"bins: must be an integer >= 2, got {bins!r}")
        if weight not in ("count", "normal_force"):
            raise ValueError(f"weight: must be 'count' or 'normal_force', got {weight!r}")
        self.bins = int(bins)
        self.weight = weight
        self.include_boundary = bool(include_boundary)
        self.edge_tolerance = float(edge_tolerance)
        angular_histogram(np.zeros(0), self.bins, edge_tolerance=self.edge_tolerance)  # checks it

    def compute(self, snapshot: Snapshot) -> ContactAnisotropy:
        """Compute the distribution for ``snapshot``; returns ``self``."""
        ci = np.asarray(snapshot.contact_i)
        cj = np.asarray(snapshot.contact_j)
        if self.weight == "normal_force" and snapshot.normal_force is None:
            raise ValueError("normal_force: the snapshot has no contact forces (needed for a_n)")
        used: slice | NDArray[np.bool_]
        if _kernels.compiled() and not has_boundary(snapshot):
            used = slice(None)  # every contact is between sample particles
            n_used = ci.size
        else:
            sample = snapshot.is_sample
            mask = (
                np.ones(ci.shape, bool) if self.include_boundary else ~snapshot.is_boundary_contact
            )
            # a contact between two membrane particles is not part of the sample's fabric
            mask &= sample[ci] | ((cj >= 0) & sample[np.where(cj >= 0, cj, 0)])
            used, n_used = mask, int(mask.sum())
        angles = np.asarray(snapshot.contact_angles())[used]
        weights = None
        if self.weight == "normal_force":
            weights = np.asarray(snapshot.normal_force)[used]
        values, edges = angular_histogram(
            angles, self.bins, weights, edge_tolerance=self.edge_tolerance
        )
        a7, t7 = anisotropy_eq7(values)
        normals = np.asarray(snapshot.contact_normals())[used]
        phi = fabric_tensor(normals, weights)
        if _kernels.compiled() and snapshot.contact_normal is None:
            # unit normals from the centres: e^{2 i theta} = (n_x + i n_y)^2, so the
            # moment comes from the tensor, a = 2 (phi_1 - phi_2), without trigonometry
            if np.isfinite(phi[0, 0]):
                s2, c2 = 2.0 * phi[0, 1], phi[0, 0] - phi[1, 1]
                af = float(2.0 * np.hypot(s2, c2))
                tf = float(np.mod(0.5 * np.arctan2(s2, c2), np.pi))
            else:
                af, tf = float("nan"), float("nan")
        else:
            af, tf = anisotropy_fourier(angles, weights)
        self._store(
            histogram=values,
            bin_edges=edges,
            anisotropy=af,
            direction=tf,
            anisotropy_binned=a7,
            direction_binned=t7,
            fabric_tensor=phi,
            total=float(n_used if weights is None else weights.sum()),
        )
        return self

    histogram = Computed[NDArray[np.float64]](
        "(bins,) bin contents, each contact counted in both directions."
    )
    bin_edges = Computed[NDArray[np.float64]]("(bins + 1,) bin edges, rad.")

    @property
    def bin_centers(self) -> NDArray[np.float64]:
        """(bins,) bin centres, rad."""
        e = self.bin_edges
        return 0.5 * (e[1:] + e[:-1])

    anisotropy = Computed[float](
        "a (or a_n), exact: twice the modulus of the mean of exp(2 i theta)."
    )
    direction = Computed[float](
        "theta_a, exact: half the argument of the mean of exp(2 i theta), rad in [0, pi)."
    )
    anisotropy_binned = Computed[float]("a (or a_n) by Eq. 7 as printed, from the histogram.")
    direction_binned = Computed[float](
        "theta_a by Eq. 8 (atan2 form) from the histogram, rad in [0, pi)."
    )

    @property
    def anisotropy_fourier(self) -> float:
        """The exact a, :attr:`anisotropy` under its earlier name."""
        return self.anisotropy

    fabric_tensor = Computed[NDArray[np.float64]](
        "(2, 2) fabric tensor (force-weighted for weight='normal_force')."
    )
    total = Computed[float]("Contacts used (or their total normal force, N).")

    def plot(self, ax: Any = None, **kwargs: Any) -> Any:
        """Polar diagram with the fitted E(theta) (paper Figs. 6–7); returns the axes."""
        from grainlab import plot

        return plot.polar_distribution(
            self.histogram,
            anisotropy=self.anisotropy,
            direction=self.direction,
            ax=ax,
            kind="forces" if self.weight == "normal_force" else "contacts",
            **kwargs,
        )
