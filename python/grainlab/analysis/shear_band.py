r"""Shear band detection from a per-particle shear strain field.

The band is modelled as a straight slab: a centre line at angle
:math:`\beta` (CCW from +x, in [0°, 180°)) and a thickness :math:`w`.

1. **Orientation.** For a trial angle :math:`\beta` the particles are
   projected on the slab normal :math:`n = (-\sin\beta, \cos\beta)`,
   :math:`s = (x - \bar x) \cdot n`, and binned in ``s`` (bins of
   ``bin_width``, default half a mean diameter). The score is the adjusted
   correlation ratio of the strain with the bin,

   .. math::

      \eta^2 = \frac{\sum_b n_b (\bar\gamma_b - \bar\gamma)^2}
                    {\sum_p (\gamma_p - \bar\gamma)^2},\qquad
      \eta^2_{adj} = 1 - (1 - \eta^2)\frac{M - 1}{M - B},

   (M particles, B occupied bins), the share of the strain variance that the
   profile across the slab explains. It is largest when the bins run
   parallel to the band. A 1° scan over [0°, 180°) is refined with 0.05°
   steps around the best angle and a parabola through the top three scores.
2. **Profile and thickness.** At the best angle the bin means
   :math:`\bar\gamma_b` form the profile across the band. With the background
   :math:`\gamma_0` the median strain and the peak :math:`\gamma_{max}` the
   largest bin mean (3-bin running mean), the band is the run of bins around
   the peak where the profile is above half height
   :math:`\gamma_0 + (\gamma_{max} - \gamma_0)/2`; its edges are
   interpolated linearly between the mean positions of the particles in
   neighbouring bins. ``thickness`` is their
   distance (m); ``thickness_diameters`` divides by the mean diameter.
3. **Members.** Sample particles whose centre lies inside the slab.

Only the dominant band is found (a conjugate second band counts as
background). ``contrast = (gamma_max - gamma_0) / gamma_max`` in [0, 1]
tells how clear the band is (0: no band stands out).

Which field to pass: :attr:`LocalStrain.excess_shear_strain` (the shear
invariant of each particle's strain minus the background strain) separates a
band from a homogeneous deformation of the whole sample better than the total
:attr:`LocalStrain.shear_strain`, whose invariant mixes the two non-linearly;
:func:`grainlab.analysis.analyze_snapshot` uses it.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from grainlab.analysis._util import Computable, finite_mean
from grainlab.snapshot import Snapshot

__all__ = ["ShearBand"]


def _scores(
    p: NDArray[np.float64], g: NDArray[np.float64], angles: NDArray[np.float64], width: float
) -> NDArray[np.float64]:
    """Adjusted eta^2 of g against bins of the projection on each angle's normal."""
    m = p.shape[0]
    normal = np.stack([-np.sin(angles), np.cos(angles)], axis=1)  # (K, 2)
    s = normal @ p.T  # (K, M)
    s -= s.min(axis=1, keepdims=True)
    b = (s / width).astype(np.int64)
    nb = int(b.max()) + 1
    key = (np.arange(angles.size)[:, None] * nb + b).ravel()
    counts = np.bincount(key, minlength=angles.size * nb).reshape(angles.size, nb)
    sums = np.bincount(key, weights=np.broadcast_to(g, s.shape).ravel(), minlength=angles.size * nb)
    sums = sums.reshape(angles.size, nb)
    mean = g.mean()
    total = float(((g - mean) ** 2).sum())
    if total <= 0.0:
        return np.zeros(angles.size)
    occupied = counts > 0
    between = (sums**2 / np.where(occupied, counts, 1)).sum(axis=1) - m * mean**2
    eta2 = between / total
    n_bins = occupied.sum(axis=1)
    return 1.0 - (1.0 - eta2) * (m - 1) / np.maximum(m - n_bins, 1)


class ShearBand(Computable):
    r"""Locate the dominant shear band in a per-particle shear strain field.

    See the module docstring for the method.

    Parameters
    ----------
    bin_width : float, optional
        Bin width across the band, in mean diameters (default 0.5).
    max_points : int, default 20000
        Particles used for the coarse angle scan (a fixed-seed random subset
        when there are more); the refinement uses up to 5 times as many.

    Attributes (after :meth:`compute`)
    ----------------------------------
    angle : float
        Band direction, rad in [0, pi), CCW from +x.
    angle_degrees : float
    thickness : float, m
    thickness_diameters : float
        Thickness in mean particle diameters.
    center : (2,) float, m
        A point on the band's centre line.
    members : (N,) bool
        Sample particles inside the band.
    mean_lambda_inside, mean_lambda_outside : float
        Mean stability index inside / outside the band (particles with at
        least 2 contacts when ``n_contacts`` is given); NaN without lambda.
    contrast, peak_strain, background_strain : float
    profile : tuple of (B,) arrays
        Bin centres ``s`` (m, from the centre line) and mean strain.

    Example
    -------
    >>> import numpy as np
    >>> x, y = np.meshgrid(np.arange(40.0), np.arange(40.0))
    >>> pos = np.c_[x.ravel(), y.ravel()]
    >>> gamma = np.where(np.abs(pos[:, 1] - 20.0) <= 3.0, 0.1, 0.0)  # 7 rows: y = 17..23
    >>> band = ShearBand().compute(pos, gamma, np.full(1600, 0.5))
    >>> bool(min(band.angle_degrees, 180.0 - band.angle_degrees) < 1.0)
    True
    >>> round(band.thickness_diameters, 2), int(band.members.sum())
    (7.0, 280)
    """

    def __init__(self, bin_width: float = 0.5, max_points: int = 20000) -> None:
        if not np.isfinite(bin_width) or bin_width <= 0:
            raise ValueError(f"bin_width: must be > 0 (mean diameters), got {bin_width!r}")
        if int(max_points) != max_points or max_points < 10:
            raise ValueError(f"max_points: must be an integer >= 10, got {max_points!r}")
        self.bin_width = float(bin_width)
        self.max_points = int(max_points)

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
        """
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
        d_mean = float(np.mean(2.0 * rad[considered]))
        width = self.bin_width * d_mean
        origin = pos[valid].mean(axis=0)
        p = pos[valid] - origin
        g = gamma[valid]

        rng = np.random.default_rng(0)
        coarse = np.radians(np.arange(0.0, 180.0, 1.0))
        pc, gc = self._subset(p, g, self.max_points, rng)
        sc = _scores(pc, gc, coarse, width)
        best = coarse[int(np.argmax(sc))]
        fine = best + np.radians(np.arange(-1.5, 1.5 + 1e-9, 0.05))
        pf, gf = self._subset(p, g, 5 * self.max_points, rng)
        sf = _scores(pf, gf, fine, width)
        k = int(np.argmax(sf))
        angle = fine[k]
        if 0 < k < fine.size - 1:
            y0, y1, y2 = sf[k - 1], sf[k], sf[k + 1]
            curv = y0 - 2 * y1 + y2
            if curv < 0:
                angle += 0.5 * (y0 - y2) / curv * (fine[1] - fine[0])
        angle = float(np.mod(angle, np.pi))

        normal = np.array([-np.sin(angle), np.cos(angle)])
        s = p @ normal
        lo = s.min()
        b = ((s - lo) / width).astype(np.int64)
        counts = np.bincount(b)
        sums = np.bincount(b, weights=g)
        occupied = counts > 0
        # profile coordinate: mean position of the particles in each bin
        centers = np.bincount(b, weights=s)[occupied] / counts[occupied]
        prof = sums[occupied] / counts[occupied]
        smooth = np.convolve(np.pad(prof, 1, mode="edge"), np.ones(3) / 3.0, mode="valid")
        background = float(np.median(g))
        ipeak = int(np.argmax(smooth))
        peak = float(smooth[ipeak])
        half = background + 0.5 * (peak - background)
        above = prof >= half
        above[ipeak] = True
        left = ipeak
        while left > 0 and above[left - 1]:
            left -= 1
        right = ipeak
        while right < prof.size - 1 and above[right + 1]:
            right += 1

        def crossing(inside: int, outside: int) -> float:
            if outside < 0 or outside >= prof.size:
                return float(centers[inside])
            gi, go = prof[inside], prof[outside]
            t = (gi - half) / (gi - go) if gi != go else 0.5
            return float(centers[inside] + t * (centers[outside] - centers[inside]))

        s_lo = crossing(left, left - 1)
        s_hi = crossing(right, right + 1)
        thickness = max(s_hi - s_lo, 0.0)
        s_mid = 0.5 * (s_lo + s_hi)
        center = origin + s_mid * normal

        s_all = (pos - center) @ normal
        members = considered & (np.abs(s_all) <= 0.5 * thickness)
        lam_in = lam_out = float("nan")
        if stability_index is not None:
            lam = np.asarray(stability_index, dtype=np.float64)
            use = considered.copy()
            if n_contacts is not None:
                use &= np.asarray(n_contacts) >= 2
            lam_in = finite_mean(lam, use & members)
            lam_out = finite_mean(lam, use & ~members)
        self._store(
            angle=angle,
            thickness=float(thickness),
            thickness_diameters=float(thickness / d_mean),
            center=center,
            normal=normal,
            members=members,
            mean_lambda_inside=lam_in,
            mean_lambda_outside=lam_out,
            contrast=float((peak - background) / peak) if peak > 0 else 0.0,
            peak_strain=peak,
            background_strain=background,
            profile=(centers - s_mid, prof),
            mean_diameter=d_mean,
            positions=pos,
            radii=rad,
            shear_strain=gamma,
        )
        return self

    @staticmethod
    def _subset(p: NDArray[np.float64], g: NDArray[np.float64], k: int, rng: np.random.Generator):
        if p.shape[0] <= k:
            return p, g
        pick = rng.choice(p.shape[0], size=k, replace=False)
        return p[pick], g[pick]

    @property
    def angle(self) -> float:
        """Band direction, rad in [0, pi), CCW from +x."""
        return self._result("angle")

    @property
    def angle_degrees(self) -> float:
        """Band direction in degrees, [0, 180)."""
        return float(np.degrees(self.angle))

    @property
    def thickness(self) -> float:
        """Band thickness, m."""
        return self._result("thickness")

    @property
    def thickness_diameters(self) -> float:
        """Band thickness in mean particle diameters."""
        return self._result("thickness_diameters")

    @property
    def center(self) -> NDArray[np.float64]:
        """(2,) a point on the centre line, m."""
        return self._result("center")

    @property
    def normal(self) -> NDArray[np.float64]:
        """(2,) unit normal of the band."""
        return self._result("normal")

    @property
    def members(self) -> NDArray[np.bool_]:
        """(N,) particles inside the band."""
        return self._result("members")

    @property
    def mean_lambda_inside(self) -> float:
        """Mean stability index of the band's particles."""
        return self._result("mean_lambda_inside")

    @property
    def mean_lambda_outside(self) -> float:
        """Mean stability index of the other particles."""
        return self._result("mean_lambda_outside")

    @property
    def contrast(self) -> float:
        """(peak - background) / peak of the strain profile, in [0, 1]."""
        return self._result("contrast")

    @property
    def peak_strain(self) -> float:
        """Largest (3-bin smoothed) mean strain across the band."""
        return self._result("peak_strain")

    @property
    def background_strain(self) -> float:
        """Median strain of the particles considered."""
        return self._result("background_strain")

    @property
    def profile(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Distance from the centre line (m) and mean strain of each bin."""
        return self._result("profile")

    def outline(self, extent: ArrayLike | None = None) -> list[NDArray[np.float64]]:
        """The two band edges as (2, 2) segments clipped to ``extent`` ``[[x0, x1], [y0, y1]]``.

        ``extent`` defaults to the bounding box of the particles.
        """
        if extent is None:
            pos = self._result("positions")
            extent = np.array(
                [[pos[:, 0].min(), pos[:, 0].max()], [pos[:, 1].min(), pos[:, 1].max()]]
            )
        ext = np.asarray(extent, dtype=np.float64)
        t = np.array([np.cos(self.angle), np.sin(self.angle)])
        edges = []
        for side in (-0.5, 0.5):
            p0 = self.center + side * self.thickness * self.normal
            seg = _clip_line(p0, t, ext)
            if seg is not None:
                edges.append(seg)
        return edges

    def plot(self, ax: Any = None, **kwargs: Any) -> Any:
        """Particle map coloured by shear strain with the band outlined; returns the axes."""
        from grainlab import plot

        ax = plot.particle_map(
            self._result("positions"),
            self._result("radii"),
            self._result("shear_strain"),
            ax=ax,
            label=r"local shear strain $\gamma$",
            **kwargs,
        )
        plot.outline_shear_band(ax, self)
        return ax

    def __repr__(self) -> str:
        return f"ShearBand(bin_width={self.bin_width}, max_points={self.max_points})"


def _clip_line(p0: NDArray[np.float64], t: NDArray[np.float64], ext: NDArray[np.float64]):
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
