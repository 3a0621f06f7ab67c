r"""The shear band as a straight slab in a per-particle strain field (pass
:attr:`LocalStrain.excess_shear_strain`). The method, its thresholds and how to
read the angle: docs/fabric.md, "Shear band".
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.ndimage import uniform_filter1d

from grainlab.analysis._compute import Compute, Computed
from grainlab.analysis._util import finite_mean, json_number, random_subset
from grainlab.analysis.band_acceptance import (
    FLANK_D,
    MIN_EXCESS,
    profile_prominence,
    strain_band_problems,
)
from grainlab.snapshot import Snapshot

__all__ = ["ShearBand", "Slab", "SlabBand"]

#: The second band's direction differs from the first's by at least this much (rad).
_SECOND_SEPARATION = np.radians(20.0)
#: Width (mean diameters) of the running mean over the profile bins.
_SMOOTH_D = 2.0
#: Width of the window (mean diameters) over which bin counts are summed to judge
#: how much of the sample a slab crosses.
_FILL_WINDOW_D = 2.0


def _slab_bins(
    s: NDArray[np.float64], width: float, window: int, min_fill: float
) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.bool_]]:
    """Bin index of each point, bin counts and the bins that cross the sample.

    ``s`` is (K, M) (or (M,)): the projections on K trial normals. A bin
    crosses the sample when the particles within ``window`` bins of it are at
    least ``min_fill`` times as many as around the fullest bin of the same
    angle; the others are the slab ends that only clip a corner.
    """
    s = np.atleast_2d(s)
    b = ((s - s.min(axis=1, keepdims=True)) / width).astype(np.int64)
    nb = int(b.max()) + 1
    k = s.shape[0]
    key = (np.arange(k)[:, None] * nb + b).ravel()
    counts = np.bincount(key, minlength=k * nb).reshape(k, nb)
    around = uniform_filter1d(counts.astype(np.float64), size=window, axis=1, mode="constant")
    crossing = (counts > 0) & (around >= min_fill * around.max(axis=1, keepdims=True))
    return b, counts, crossing


def _scores(
    p: NDArray[np.float64],
    g: NDArray[np.float64],
    angles: NDArray[np.float64],
    width: float,
    window: int = 1,
    min_fill: float = 0.0,
) -> NDArray[np.float64]:
    """Adjusted eta^2 of g against bins across the slab, for each trial angle.

    Only the particles in bins that cross the sample (:func:`_slab_bins`) count.
    """
    normal = np.stack([-np.sin(angles), np.cos(angles)], axis=1)  # (K, 2)
    b, _, crossing = _slab_bins(normal @ p.T, width, window, min_fill)
    k, nb = crossing.shape
    use = np.take_along_axis(crossing, b, axis=1).astype(np.float64)  # (K, M)
    key = (np.arange(k)[:, None] * nb + b).ravel()
    counts = np.bincount(key, weights=use.ravel(), minlength=k * nb).reshape(k, nb)
    sums = np.bincount(key, weights=(use * g).ravel(), minlength=k * nb).reshape(k, nb)
    m = use.sum(axis=1)
    mean = (use @ g) / np.maximum(m, 1.0)
    total = use @ (g * g) - m * mean**2
    occupied = counts > 0
    between = (sums**2 / np.where(occupied, counts, 1.0)).sum(axis=1) - m * mean**2
    ok = total > 1e-12 * np.maximum(use @ (g * g), 1e-300)
    eta2 = between / np.where(ok, total, 1.0)
    n_bins = occupied.sum(axis=1)
    adj = 1.0 - (1.0 - eta2) * (m - 1) / np.maximum(m - n_bins, 1)
    return np.where(ok, adj, 0.0)


def _best(scores: NDArray[np.float64]) -> int:
    """Index of the largest score; the middle of the run when neighbours tie for it."""
    top = float(np.max(scores))
    k = int(np.argmax(scores))
    tie = scores >= top - 1e-12 * max(abs(top), 1.0)
    lo = hi = k
    while lo > 0 and tie[lo - 1]:
        lo -= 1
    while hi + 1 < scores.size and tie[hi + 1]:
        hi += 1
    return (lo + hi) // 2


@dataclass(frozen=True)
class _BandInput:
    """The checked input of :meth:`ShearBand.compute`: every particle's position,
    radius and strain, which are considered and valid (finite strain), and the
    valid ones' positions relative to their centroid."""

    pos: NDArray[np.float64]
    rad: NDArray[np.float64]
    gamma: NDArray[np.float64]
    considered: NDArray[np.bool_]
    valid: NDArray[np.bool_]
    d_mean: float
    origin: NDArray[np.float64]
    p: NDArray[np.float64]
    g: NDArray[np.float64]

    @classmethod
    def of(
        cls,
        positions: ArrayLike | Snapshot,
        shear_strain: ArrayLike,
        radii: ArrayLike | None,
        mask: ArrayLike | None,
    ) -> _BandInput:
        if isinstance(positions, Snapshot):
            snap = positions
            pos = np.asarray(snap.positions)
            radii = snap.radii if radii is None else radii
            mask = snap.is_sample if mask is None else mask
        else:
            pos = np.asarray(positions, dtype=np.float64)
        if radii is None:
            raise ValueError("radii: needed to express the thickness in mean diameters")
        rad = np.asarray(radii, dtype=np.float64)
        gamma = np.asarray(shear_strain, dtype=np.float64)
        n = pos.shape[0]
        if pos.shape != (n, 2) or rad.shape != (n,) or gamma.shape != (n,):
            raise ValueError(
                f"positions, radii, shear_strain: expected shapes (N, 2), (N,), (N,), got "
                f"{pos.shape}, {rad.shape}, {gamma.shape}"
            )
        considered = np.ones(n, bool) if mask is None else np.asarray(mask, bool)
        valid = considered & np.isfinite(gamma)
        if valid.sum() < 10:
            raise ValueError(
                "shear_strain: need at least 10 particles with a finite strain, "
                f"got {int(valid.sum())}"
            )
        origin = pos[valid].mean(axis=0)
        return cls(pos, rad, gamma, considered, valid, float(np.mean(2.0 * rad[considered])), origin,
                   pos[valid] - origin, gamma[valid])


@dataclass(frozen=True)
class _Profile:
    """The strain profile across the band (one entry per occupied bin) and the
    band's edges on it."""

    centers: NDArray[np.float64]
    """Mean coordinate across the band of each bin's particles."""
    mean_strain: NDArray[np.float64]
    smooth: NDArray[np.float64]
    """Mean strain within about ``_SMOOTH_D / 2`` mean diameters of each bin."""
    crossing: NDArray[np.bool_]
    """Bins that cross the sample (filled enough along the band)."""
    background: float
    peak: float
    s_lo: float
    s_hi: float

    @property
    def thickness(self) -> float:
        return max(self.s_hi - self.s_lo, 0.0)

    @property
    def s_mid(self) -> float:
        return 0.5 * (self.s_lo + self.s_hi)


def binned_profile(
    b: NDArray[np.int64],
    counts: NDArray[Any],
    values: NDArray[np.float64],
    s: NDArray[np.float64],
    bin_width: float,
) -> tuple[NDArray[np.bool_], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """A profile of ``values`` across a band from the bin ``b`` of each point and the
    bins' ``counts``: the occupied bins, their points' mean ``s`` and mean value, and
    the mean value of the points within about ``_SMOOTH_D / 2`` mean diameters of
    each (``bin_width`` in mean diameters); the last three for occupied bins only."""
    sums = np.bincount(b, weights=values, minlength=counts.size)
    occupied = counts > 0
    centers = np.bincount(b, weights=s, minlength=counts.size)[occupied] / counts[occupied]
    half_window = max(1, int(np.floor(0.5 * _SMOOTH_D / bin_width + 0.5)))
    kernel = np.ones(2 * half_window + 1)
    near_sums = np.convolve(sums, kernel, mode="same")
    near_counts = np.convolve(counts.astype(np.float64), kernel, mode="same")
    smooth = (near_sums / np.maximum(near_counts, 1.0))[occupied]
    return occupied, centers, sums[occupied] / counts[occupied], smooth


def _band_profile(
    s: NDArray[np.float64], g: NDArray[np.float64], width: float, window: int, bin_width: float, min_fill: float
) -> _Profile:
    """Step 2: the profile across the band at coordinates ``s`` and its
    half-height edges around the highest smoothed bin that crosses the sample."""
    b2, counts2, crossing2 = _slab_bins(s, width, window, min_fill)
    b, counts, crossing = b2[0], counts2[0], crossing2[0]
    occupied, centers, prof, smooth = binned_profile(b, counts, g, s, bin_width)
    keep = crossing[occupied]
    background = float(np.median(g))
    ipeak = int(np.argmax(np.where(keep, smooth, -np.inf)))
    peak = float(smooth[ipeak])
    half = background + 0.5 * (peak - background)
    inside = keep & (smooth >= half)
    inside[ipeak] = True
    left = ipeak
    while left > 0 and inside[left - 1]:
        left -= 1
    right = ipeak
    while right < prof.size - 1 and inside[right + 1]:
        right += 1

    def edge(i_in: int, i_out: int) -> float:
        """Half-height crossing between a band bin and its outer neighbour."""
        if i_out < 0 or i_out >= prof.size or smooth[i_out] >= half:
            return float(centers[i_in])  # the band reaches the end of the profile used
        gi, go = smooth[i_in], smooth[i_out]
        t = (gi - half) / (gi - go) if gi != go else 0.5
        return float(centers[i_in] + t * (centers[i_out] - centers[i_in]))

    return _Profile(centers, prof, smooth, keep, background, peak, edge(left, left - 1), edge(right, right + 1))


class SlabBand(Compute):
    """A band modelled as a straight slab (a centre line, a thickness): the results
    and the outline that every reading of the band shares (:class:`ShearBand`,
    :class:`~grainlab.analysis.band_readings.DisplacementBand`). How the slab is
    found and accepted, and so what its thickness measures, is the subclass's."""

    found = Computed[bool]("Whether the band passed the acceptance tests (the class docstring).")
    reason = Computed[str](
        "Why the band was not accepted (empty when :attr:`found`); the other results "
        "describe the candidate either way."
    )
    angle = Computed[float]("Band direction, rad in [0, pi), CCW from +x.")

    @property
    def angle_degrees(self) -> float:
        """Band direction in degrees, [0, 180), CCW from +x."""
        return float(np.degrees(self.angle))

    @property
    def inclination(self) -> float:
        """Acute angle between the band and the x axis, rad in [0, pi/2]."""
        return float(min(self.angle, np.pi - self.angle))

    @property
    def inclination_degrees(self) -> float:
        """Acute angle between the band and the x axis (the horizontal sigma_3
        direction of a biaxial test loaded along y), degrees in [0, 90]."""
        return float(np.degrees(self.inclination))

    thickness = Computed[float]("Band thickness, m (the class docstring says what it measures).")
    thickness_diameters = Computed[float]("Band thickness in mean particle diameters.")
    mean_diameter = Computed[float]("Mean diameter of the particles considered, m.")
    center = Computed[NDArray[np.float64]]("(2,) a point on the centre line, m.")
    normal = Computed[NDArray[np.float64]]("(2,) unit normal of the band, (-sin angle, cos angle) (into block B of a displacement band).")
    members = Computed[NDArray[np.bool_]]("(N,) particles inside the band.")
    _positions = Computed[NDArray[np.float64]]("(N, 2) the particles' positions, m.")
    _radii = Computed[NDArray[np.float64]]("(N,) the particles' radii, m.")

    @property
    def slab(self) -> Slab:
        """The band's straight slab alone (no per-particle data): what a results file stores of it."""
        pos = self._positions
        extent = (
            np.array([[pos[:, 0].min(), pos[:, 0].max()], [pos[:, 1].min(), pos[:, 1].max()]])
            if pos.shape[0]
            else np.full((2, 2), np.nan)
        )
        return Slab(
            found=self.found,
            angle=self.angle,
            center=np.array(self.center, dtype=np.float64),
            normal=np.array(self.normal, dtype=np.float64),
            thickness=self.thickness,
            thickness_diameters=self.thickness_diameters,
            extent=extent,
        )

    def _slab_summary(self) -> dict[str, Any]:
        """The first entries of every reading's ``summary()``: found, reason, angles
        (degrees), thickness (m and mean diameters), JSON-ready."""
        return {
            "found": self.found,
            "reason": self.reason,
            "angle_deg": json_number(self.angle_degrees),
            "inclination_deg": json_number(self.inclination_degrees),
            "thickness_m": json_number(self.thickness),
            "thickness_diameters": json_number(self.thickness_diameters),
        }

    def outline(self, extent: ArrayLike | None = None) -> list[NDArray[np.float64]]:
        """The two band edges as (2, 2) segments clipped to ``extent`` ``[[x0, x1], [y0, y1]]``.

        ``extent`` defaults to the bounding box of the particles.
        """
        return self.slab.outline(extent)


@dataclass(frozen=True, eq=False)
class Slab:
    """A band as a straight slab: its centre line and thickness, and the box of
    the particles it was found among (the default extent of :meth:`outline`).

    What :attr:`SlabBand.slab` gives of any reading of the band, and what the
    results file's analysis group stores (``docs/file-formats.md``)."""

    #: Whether the band passed its reading's acceptance tests.
    found: bool
    #: Direction of the centre line, rad in [0, pi), CCW from +x.
    angle: float
    #: (2,) a point on the centre line, m.
    center: NDArray[np.float64]
    #: (2,) unit normal of the slab.
    normal: NDArray[np.float64]
    #: Thickness, m.
    thickness: float
    #: Thickness in mean diameters of the particles the band was found among.
    thickness_diameters: float
    #: (2, 2) ``[[x0, x1], [y0, y1]]``: the bounding box of those particles.
    extent: NDArray[np.float64]

    @property
    def angle_degrees(self) -> float:
        """Direction in degrees, [0, 180), CCW from +x."""
        return float(np.degrees(self.angle))

    @property
    def inclination_degrees(self) -> float:
        """Acute angle between the slab and the x axis, degrees in [0, 90]."""
        return float(np.degrees(min(self.angle, np.pi - self.angle)))

    def members(self, positions: ArrayLike) -> NDArray[np.bool_]:
        """(N,) whether each point of ``positions`` (N, 2) lies inside the slab."""
        p = np.asarray(positions, dtype=np.float64).reshape(-1, 2)
        return np.asarray(np.abs((p - self.center) @ self.normal) <= 0.5 * self.thickness)

    def outline(self, extent: ArrayLike | None = None) -> list[NDArray[np.float64]]:
        """The two edges as (2, 2) segments clipped to ``extent`` ``[[x0, x1], [y0, y1]]``
        (default :attr:`extent`)."""
        ext = np.asarray(self.extent if extent is None else extent, dtype=np.float64)
        t = np.array([np.cos(self.angle), np.sin(self.angle)])
        edges = []
        for side in (-0.5, 0.5):
            seg = _clip_line(self.center + side * self.thickness * self.normal, t, ext)
            if seg is not None:
                edges.append(seg)
        return edges

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Slab):
            return NotImplemented
        return (
            (self.found, self.angle, self.thickness, self.thickness_diameters)
            == (other.found, other.angle, other.thickness, other.thickness_diameters)
            and np.array_equal(self.center, other.center)
            and np.array_equal(self.normal, other.normal)
            and np.array_equal(self.extent, other.extent, equal_nan=True)
        )

    __hash__ = None  # type: ignore[assignment]


class ShearBand(SlabBand):
    r"""Locate the dominant shear band (and a second one) in a per-particle strain field.

    The method, its thresholds and how to read the angle: docs/fabric.md, "Shear band".
    :meth:`summary` gives the scalars (and the second band's) as a JSON-ready dict.

    Parameters
    ----------
    bin_width : float, default 0.5
        Bin width across the band, in mean diameters.
    max_points : int, default 20000
        Particles used for the coarse angle scan (a fixed-seed random subset
        when there are more); the refinement uses up to 5 times as many.
    min_fill : float, default 0.5
        A bin counts only where the slab crosses the sample: the particles
        within 2 mean diameters of it are at least ``min_fill`` times those at
        the fullest position of that angle (0: every bin).
    min_thickness : float, default 1.0
        Thinnest band accepted (:attr:`found`), in mean diameters.
    min_prominence : float, default 2.0
        Least :attr:`prominence` of an accepted band.
    second : bool, default True
        Also look for a second (conjugate) band, :attr:`second`.

    Example
    -------
    >>> import numpy as np
    >>> x, y = np.meshgrid(np.arange(40.0), np.arange(40.0))
    >>> pos = np.c_[x.ravel(), y.ravel()]
    >>> gamma = np.where(np.abs(pos[:, 1] - 20.0) <= 3.0, 0.1, 0.0)  # 7 rows: y = 17..23
    >>> band = ShearBand().compute(pos, gamma, np.full(1600, 0.5))
    >>> band.found, bool(band.inclination_degrees < 1.0)
    (True, True)
    >>> round(band.thickness_diameters, 2), int(band.members.sum())
    (7.0, 280)
    >>> band.second is not None and band.second.found  # nothing else stands out
    False
    """

    _parameters = (
        "bin_width",
        "max_points",
        "min_fill",
        "min_thickness",
        "min_prominence",
        "second=find_second",
    )

    def __init__(
        self,
        bin_width: float = 0.5,
        max_points: int = 20000,
        *,
        min_fill: float = 0.5,
        min_thickness: float = 1.0,
        min_prominence: float = 2.0,
        second: bool = True,
    ) -> None:
        if not np.isfinite(bin_width) or bin_width <= 0:
            raise ValueError(f"bin_width: must be > 0 (mean diameters), got {bin_width!r}")
        if int(max_points) != max_points or max_points < 10:
            raise ValueError(f"max_points: must be an integer >= 10, got {max_points!r}")
        if not 0.0 <= min_fill <= 1.0:
            raise ValueError(f"min_fill: must be in [0, 1], got {min_fill!r}")
        if not np.isfinite(min_thickness) or min_thickness < 0:
            raise ValueError(f"min_thickness: must be >= 0 (mean diameters), got {min_thickness!r}")
        if not np.isfinite(min_prominence) or min_prominence < 1.0:
            raise ValueError(f"min_prominence: must be >= 1, got {min_prominence!r}")
        self.bin_width = float(bin_width)
        self.max_points = int(max_points)
        self.min_fill = float(min_fill)
        self.min_thickness = float(min_thickness)
        self.min_prominence = float(min_prominence)
        self.find_second = bool(second)
        self._avoid: float | None = None  # set on the instance searching for a second band

    def compute(
        self,
        positions: ArrayLike | Snapshot,
        shear_strain: ArrayLike,
        radii: ArrayLike | None = None,
        *,
        stability_index: ArrayLike | None = None,
        n_contacts: ArrayLike | None = None,
        mask: ArrayLike | None = None,
    ) -> ShearBand:
        """Find the band; returns ``self``.

        ``positions`` (N, 2) m, or a :class:`Snapshot` (then ``radii`` and
        ``mask`` default to the snapshot's radii and sample particles);
        ``shear_strain`` (N,), NaN entries are ignored; ``radii`` (N,) m;
        ``mask`` (N,) bool restricts the particles considered.

        Steps: :meth:`_orientation`, :func:`_band_profile`, :meth:`_acceptance`,
        lambda inside and outside, :meth:`_second_band`.
        """
        data = _BandInput.of(positions, shear_strain, radii, mask)
        width = self.bin_width * data.d_mean
        window = max(1, int(round(_FILL_WINDOW_D / self.bin_width)))
        angle, score = self._orientation(data.p, data.g, width, window)
        normal = np.array([-np.sin(angle), np.cos(angle)])
        profile = _band_profile(data.p @ normal, data.g, width, window, self.bin_width, self.min_fill)
        center = data.origin + profile.s_mid * normal
        excess, prominence, problems = self._acceptance(profile, data)
        s_all = (data.pos - center) @ normal
        members = data.considered & (np.abs(s_all) <= 0.5 * profile.thickness)
        lam_in = lam_out = float("nan")
        if stability_index is not None:
            lam = np.asarray(stability_index, dtype=np.float64)
            use = data.considered.copy()
            if n_contacts is not None:
                use &= np.asarray(n_contacts) >= 2
            lam_in = finite_mean(lam, use & members)
            lam_out = finite_mean(lam, use & ~members)
        second = None
        if self.find_second:
            rest = data.valid & (np.abs(s_all) > 0.5 * profile.thickness + FLANK_D * data.d_mean)
            second = self._second_band(data, rest, angle, stability_index, n_contacts)
        peak = profile.peak
        self._store(
            found=not problems,
            reason="; ".join(problems),
            angle=angle,
            thickness=float(profile.thickness),
            thickness_diameters=float(profile.thickness / data.d_mean),
            center=center,
            normal=normal,
            members=members,
            mean_lambda_inside=lam_in,
            mean_lambda_outside=lam_out,
            contrast=float(excess / peak) if peak > 0 and excess > 0 else 0.0,
            prominence=float(prominence),
            score=score,
            peak_strain=peak,
            background_strain=profile.background,
            profile=(profile.centers - profile.s_mid, profile.mean_strain),
            profile_crossing=profile.crossing,
            second=second,
            mean_diameter=data.d_mean,
            _positions=data.pos,
            _radii=data.rad,
            _shear_strain=data.gamma,
        )
        return self

    def _orientation(
        self, p: NDArray[np.float64], g: NDArray[np.float64], width: float, window: int
    ) -> tuple[float, float]:
        """Step 1: the band angle (a 1 degree scan, a 0.05 degree refinement, a
        parabola through the best three) and its score."""
        rng = np.random.default_rng(0)
        coarse = np.radians(np.arange(0.0, 180.0, 1.0))
        pc, gc = random_subset(p, g, self.max_points, rng)
        sc = _scores(pc, gc, coarse, width, window, self.min_fill)
        sc[self._avoided(coarse)] = -np.inf
        best = coarse[_best(sc)]
        fine = best + np.radians(np.arange(-1.5, 1.5 + 1e-9, 0.05))
        pf, gf = random_subset(p, g, 5 * self.max_points, rng)
        sf = _scores(pf, gf, fine, width, window, self.min_fill)
        sf[self._avoided(fine)] = -np.inf
        k = _best(sf)
        angle = fine[k]
        if (
            0 < k < fine.size - 1
            and np.isfinite(sf[k - 1 : k + 2]).all()
            and sf[k - 1] < sf[k] > sf[k + 1]
        ):
            y0, y1, y2 = sf[k - 1], sf[k], sf[k + 1]
            curv = y0 - 2 * y1 + y2
            if curv < 0:
                angle += 0.5 * (y0 - y2) / curv * (fine[1] - fine[0])
        angle = float(np.mod(angle, np.pi))
        score = float(_scores(p, g, np.array([angle]), width, window, self.min_fill)[0])
        return angle, score

    def _acceptance(self, profile: _Profile, data: _BandInput) -> tuple[float, float, list[str]]:
        """Step 3: the band's excess strain over the background, its prominence and
        what fails (:mod:`~grainlab.analysis.band_acceptance`)."""
        excess = profile.peak - profile.background
        if excess <= max(MIN_EXCESS, MIN_EXCESS * float(np.max(np.abs(data.g)))):
            excess = 0.0  # round-off: a uniform (affine) deformation has no band
        prominence, elsewhere = profile_prominence(
            excess, profile.smooth, profile.centers - profile.s_mid, profile.crossing,
            profile.background, profile.thickness, data.d_mean,
        )
        problems = strain_band_problems(
            excess, prominence, elsewhere, profile.thickness / data.d_mean,
            self.min_thickness, self.min_prominence,
        )
        return excess, prominence, problems

    def _second_band(
        self,
        data: _BandInput,
        rest: NDArray[np.bool_],
        angle: float,
        stability_index: ArrayLike | None,
        n_contacts: ArrayLike | None,
    ) -> ShearBand | None:
        """Step 4: the same search without the first band and its flanks (``rest``),
        at angles at least ``_SECOND_SEPARATION`` from the first."""
        if rest.sum() < 10:
            return None
        second = ShearBand(
            self.bin_width,
            self.max_points,
            min_fill=self.min_fill,
            min_thickness=self.min_thickness,
            min_prominence=self.min_prominence,
            second=False,
        )
        second._avoid = angle
        return second.compute(
            data.pos,
            np.where(rest, data.gamma, np.nan),
            data.rad,
            stability_index=stability_index,
            n_contacts=n_contacts,
            mask=data.considered,
        )

    def _avoided(self, angles: NDArray[np.float64]) -> NDArray[np.bool_]:
        """Trial angles too close to the angle to avoid (the first band's, for the second)."""
        if self._avoid is None:
            return np.zeros(angles.shape, bool)
        diff = np.mod(angles - self._avoid + 0.5 * np.pi, np.pi) - 0.5 * np.pi
        close: NDArray[np.bool_] = np.abs(diff) < _SECOND_SEPARATION
        return close

    mean_lambda_inside = Computed[float](
        "Mean stability index of the band's particles (those with at least 2 contacts when "
        "``n_contacts`` is given); NaN without lambda."
    )
    mean_lambda_outside = Computed[float]("The same of the other particles.")
    contrast = Computed[float]("(peak - background) / peak of the strain profile, in [0, 1].")
    prominence = Computed[float](
        "Excess strain of the band over the background divided by the largest excess elsewhere on "
        "the profile (inf when nothing else is above it)."
    )
    score = Computed[float](
        "Adjusted eta² of the strain with the bins across the band (share of the strain variance "
        "that the profile explains), at the band's angle."
    )
    peak_strain = Computed[float]("Largest (3-bin smoothed) mean strain across the band.")
    background_strain = Computed[float]("Median strain of the particles considered.")
    profile = Computed[tuple[NDArray[np.float64], NDArray[np.float64]]](
        "Distance from the centre line (m) and mean strain of each bin."
    )
    profile_crossing = Computed[NDArray[np.bool_]](
        "(B,) bins of :attr:`profile` that cross the sample (used for the peak)."
    )
    _shear_strain = Computed[NDArray[np.float64]]("(N,) the strain field searched.")
    second = Computed["ShearBand | None"](
        "The strongest band among the particles outside this one and its flanks (its own "
        ":attr:`found`, ...); None with ``second=False`` or fewer than 10 particles left."
    )

    def summary(self) -> dict[str, Any]:
        """JSON-ready scalars (NaN and inf as None, angles in degrees), with
        ``second`` the same dict of the second band (or None)."""
        second = self.second
        return {
            **self._slab_summary(),
            "contrast": json_number(self.contrast),
            "prominence": json_number(self.prominence),
            "score": json_number(self.score),
            "n_particles": int(self.members.sum()),
            "mean_lambda_inside": json_number(self.mean_lambda_inside),
            "mean_lambda_outside": json_number(self.mean_lambda_outside),
            "second": second.summary() if second is not None else None,
        }

    def plot(self, ax: Any = None, **kwargs: Any) -> Any:
        """Particle map coloured by shear strain with the band outlined; returns the axes."""
        from grainlab import plot

        ax = plot.particle_map(
            self._positions,
            self._radii,
            self._shear_strain,
            ax=ax,
            label=r"local shear strain $\gamma$",
            **kwargs,
        )
        plot.outline_shear_band(ax, self)
        return ax


def _clip_line(
    p0: NDArray[np.float64], t: NDArray[np.float64], ext: NDArray[np.float64]
) -> NDArray[np.float64] | None:
    """Segment of the line p0 + u t inside the rectangle ext, or None."""
    lo, hi = -np.inf, np.inf
    for axis in (0, 1):
        if abs(t[axis]) < 1e-15:
            if not ext[axis, 0] <= p0[axis] <= ext[axis, 1]:
                return None
            continue
        u0 = (ext[axis, 0] - p0[axis]) / t[axis]
        u1 = (ext[axis, 1] - p0[axis]) / t[axis]
        lo, hi = max(lo, min(u0, u1)), min(hi, max(u0, u1))
    if lo > hi:
        return None
    return np.array([p0 + lo * t, p0 + hi * t])
