r"""The shear band read from the grains' cumulative displacements (paper Fig. 11).

:class:`DisplacementBand` splits the grains by a straight slip line into two
blocks of affine motion; the method and how its threshold was fixed:
docs/analysis.md, "Three readings of the shear band".
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from grainlab.analysis._compute import Computed
from grainlab.analysis._util import json_number, random_subset
from grainlab.analysis.band_acceptance import (
    crossing_problems,
    reduction_problems,
    transition_problems,
)
from grainlab.analysis.shear_band import SlabBand, _best, binned_profile

__all__ = ["MIN_GRAINS", "SHARE_HIGH", "SHARE_LOW", "DisplacementBand"]

#: The band's edges: the smoothed share of the relative motion crosses these.
SHARE_LOW, SHARE_HIGH = 0.1, 0.9
#: Flank (mean diameters) left out, with the band, of the blocks' refits; number of refits.
_FLANK_D = 1.0
_REFITS = 3
#: Trial angles per block of the scan (bounds the memory of the sums).
_ANGLE_BLOCK = 30
#: Spacing (mean diameters) of the splits tried across the sample: in the angle scan, and
#: at each angle of the refinement.
_SCAN_STEP_D = 0.25
_SPLIT_STEP_D = 0.05
#: Fewest grains with a finite displacement that :meth:`DisplacementBand.compute` takes.
MIN_GRAINS = 40
#: Fewest grains that a refitted block keeps.
_MIN_BLOCK = 10


def _moments(p: NDArray[np.float64], u: NDArray[np.float64]) -> NDArray[np.float64]:
    """(M, 14) per-grain terms whose sums give a block's affine fit (:func:`_residual`)."""
    x, y, ux, uy = p[:, 0], p[:, 1], u[:, 0], u[:, 1]
    one = np.ones_like(x)
    return np.stack(
        [one, x, y, x * x, x * y, y * y, ux, uy, x * ux, y * ux, x * uy, y * uy, ux * ux, uy * uy],
        axis=-1,
    )


def _residual(m: NDArray[np.float64]) -> NDArray[np.float64]:
    """Squared residual of the least-squares affine fit of the grains whose moments
    sum to ``m`` (..., 14); inf where the block is too small or its grains lie on
    one line."""
    n = m[..., 0]
    safe_n = np.maximum(n, 1.0)
    mx, my = m[..., 1] / safe_n, m[..., 2] / safe_n
    sxx = m[..., 3] - n * mx * mx
    sxy = m[..., 4] - n * mx * my
    syy = m[..., 5] - n * my * my
    det = sxx * syy - sxy * sxy
    ok = (n >= 4) & (det > 1e-9 * np.maximum(sxx * syy, 1e-300))
    det = np.where(ok, det, 1.0)
    total = np.zeros_like(n)
    for ix, iy, iu, iuu in ((8, 9, 6, 12), (10, 11, 7, 13)):  # u_x, then u_y
        cx = m[..., ix] - mx * m[..., iu]
        cy = m[..., iy] - my * m[..., iu]
        var = m[..., iuu] - m[..., iu] ** 2 / safe_n
        total = total + var - (syy * cx * cx - 2.0 * sxy * cx * cy + sxx * cy * cy) / det
    return np.where(ok, np.maximum(total, 0.0), np.inf)


def _affine_fit(
    p: NDArray[np.float64], u: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Least-squares affine motion of the points ``p`` moving by ``u``: (3, 2)
    coefficients of ``[1, x, y]`` and the fit evaluated at ``p``."""
    design = np.c_[np.ones(p.shape[0]), p]
    coef = np.asarray(np.linalg.lstsq(design, u, rcond=None)[0], dtype=np.float64)
    return coef, design @ coef


def _at(coef: NDArray[np.float64], p: NDArray[np.float64]) -> NDArray[np.float64]:
    """The affine motion ``coef`` (3, 2) evaluated at ``p`` (M, 2)."""
    at: NDArray[np.float64] = coef[0] + p @ coef[1:]
    return at


def _splits(
    p: NDArray[np.float64],
    u: NDArray[np.float64],
    angles: NDArray[np.float64],
    min_share: float,
    step: float,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Step 1 at each trial angle: the least two-block residual over the splits that
    leave both blocks at least ``min_share`` of the grains, and its offset. The
    splits are tried every ``step`` across the sample (the grains' moments summed
    in bins of that width, then over the bins on each side)."""
    terms = _moments(p, u)
    total = terms.sum(axis=0)
    m = p.shape[0]
    need = max(min_share * m, 4.0)
    best = np.full(angles.size, np.inf)
    offset = np.zeros(angles.size)
    for start in range(0, angles.size, _ANGLE_BLOCK):
        a = angles[start : start + _ANGLE_BLOCK]
        k = a.size
        s = np.stack([-np.sin(a), np.cos(a)], axis=1) @ p.T  # (k, M)
        s0 = s.min(axis=1)
        b = ((s - s0[:, None]) / step).astype(np.int64)
        nb = int(b.max()) + 1
        key = (np.arange(k)[:, None] * nb + b).ravel()
        sums = np.stack(
            [
                np.bincount(key, weights=np.broadcast_to(terms[:, q], (k, m)).ravel(), minlength=k * nb)
                for q in range(terms.shape[1])
            ],
            axis=-1,
        ).reshape(k, nb, -1)
        below = np.cumsum(sums, axis=1, dtype=np.float64)[:, :-1, :]  # block A: bins 0 .. j
        res = _residual(below) + _residual(total - below)
        res[(below[..., 0] < need) | (m - below[..., 0] < need)] = np.inf
        if res.shape[1] == 0:
            continue
        j = np.argmin(res, axis=1)
        rows = np.arange(k)
        best[start : start + k] = res[rows, j]
        offset[start : start + k] = s0 + (j + 1) * step
    return best, offset


@dataclass(frozen=True)
class _Transition:
    """The profile of the share of the relative motion across the slip line and
    the band's edges on it (coordinates from the slip line, mean diameters)."""

    centers: NDArray[np.float64]
    mean_share: NDArray[np.float64]
    smooth: NDArray[np.float64]
    s_lo: float
    s_hi: float
    problems: tuple[str, ...]

    @property
    def thickness(self) -> float:
        return max(self.s_hi - self.s_lo, 0.0)


def _no_transition(problem: str) -> _Transition:
    """No band on the profile, and why."""
    return _Transition(np.zeros(0), np.zeros(0), np.zeros(0), 0.0, 0.0, (problem,))


def _transition(s: NDArray[np.float64], t: NDArray[np.float64], bin_width: float) -> _Transition:
    """Step 2: the profile of ``t`` against ``s`` (mean diameters), binned and
    smoothed, and the run of bins around ``s = 0`` where it lies between
    SHARE_LOW and SHARE_HIGH, with the problems of the transition."""
    ok = np.isfinite(t)
    if ok.sum() < 2:
        return _no_transition("too few grains have a share of the relative motion")
    s_ok, t_ok = s[ok], t[ok]
    b = ((s_ok - s_ok.min()) / bin_width).astype(np.int64)
    counts = np.bincount(b).astype(np.float64)
    _, centers, mean, smooth = binned_profile(b, counts, t_ok, s_ok, bin_width)
    inside = (smooth > SHARE_LOW) & (smooth < SHARE_HIGH)
    if not inside.any():
        return _no_transition(
            f"the share of the relative motion never lies between {SHARE_LOW:g} and {SHARE_HIGH:g}"
        )
    i0 = int(np.flatnonzero(inside)[np.argmin(np.abs(centers[inside]))])
    left = right = i0
    while left > 0 and inside[left - 1]:
        left -= 1
    while right < centers.size - 1 and inside[right + 1]:
        right += 1

    def edge(i_in: int, i_out: int) -> tuple[float, float]:
        """Where the profile leaves the band between bins i_in and i_out, and the
        level crossed there (NaN: the band reaches the end of the profile)."""
        if i_out < 0 or i_out >= centers.size:
            return float(centers[i_in]), math.nan
        level = SHARE_LOW if smooth[i_out] <= SHARE_LOW else SHARE_HIGH
        f = (smooth[i_in] - level) / (smooth[i_in] - smooth[i_out])
        return float(centers[i_in] + f * (centers[i_out] - centers[i_in])), level

    s_lo, level_lo = edge(left, left - 1)
    s_hi, level_hi = edge(right, right + 1)
    reaches = level_lo == SHARE_LOW and level_hi == SHARE_HIGH
    problems = transition_problems(reaches, SHARE_LOW, SHARE_HIGH)
    return _Transition(centers, mean, smooth, s_lo, s_hi, tuple(problems))


def _two_block_residual(
    p: NDArray[np.float64],
    v: NDArray[np.float64],
    s: NDArray[np.float64],
    trans: _Transition,
    coef_a: NDArray[np.float64],
    coef_b: NDArray[np.float64],
) -> float:
    """Step 3: the squared residual of the two blocks' motions joined across the band,
    u_A + tau(s) (u_B - u_A), tau rising linearly through SHARE_LOW at the band's lower
    edge and SHARE_HIGH at its upper edge (a step at s = 0 when there is no band)."""
    if trans.thickness > 0.0:
        slope = (SHARE_HIGH - SHARE_LOW) / trans.thickness
        tau = np.clip(SHARE_LOW + slope * (s - trans.s_lo), 0.0, 1.0)
    else:
        tau = (s > 0.0).astype(np.float64)
    ua = _at(coef_a, p)
    model = ua + tau[:, None] * (_at(coef_b, p) - ua)
    return float(np.sum((v - model) ** 2))


@dataclass(frozen=True, eq=False)
class _Reading:
    """The band read at one angle (in mean diameters and units of the displacement's
    non-affine scale)."""

    angle: float
    offset: float
    """Offset of the slip line from the grains' centroid."""
    trans: _Transition
    share: NDArray[np.float64]
    coef_a: NDArray[np.float64]
    coef_b: NDArray[np.float64]
    residual: float
    """Residual of the two blocks joined across the band."""


class DisplacementBand(SlabBand):
    r"""The shear band as the zone between two blocks that move differently (Fig. 11).

    The method, the acceptance tests and how their threshold was fixed:
    docs/analysis.md, "Three readings of the shear band".

    Parameters
    ----------
    bin_width : float, default 0.5
        Bin width of the profile across the band, in mean diameters.
    max_points : int, default 20000
        Grains used for the 1 degree angle scan (a fixed-seed random subset
        when there are more); the refinement uses every grain.
    min_share : float, default 0.2
        Only lines that leave each block at least this share of the grains
        are tried (in (0, 0.5)): lines that cross the sample.
    min_reduction : float, default 0.6
        Least share of the one-block residual that the two blocks remove for
        the band to be accepted (:attr:`residual_reduction`), in (0, 1].
    crossing : float, default 0.75
        The band's centre line crosses at least this share of the sample's
        smaller side through the grains, and its members cover at least this
        share of that chord, in [0, 1].

    Example
    -------
    A lattice whose upper half slides 0.3 along the line y = 20, with a linear
    transition 6 rows wide (the 0.1-0.9 zone is 0.8 x 6 = 4.8 wide):

    >>> import numpy as np
    >>> x, y = np.meshgrid(np.arange(40.0), np.arange(40.0))
    >>> pos = np.c_[x.ravel(), y.ravel()]
    >>> share = np.clip((pos[:, 1] - 20.0) / 6.0 + 0.5, 0.0, 1.0)
    >>> u = np.c_[0.3 * share, np.zeros(1600)]
    >>> band = DisplacementBand().compute(pos, u, np.full(1600, 0.5))
    >>> band.found, round(band.inclination_degrees, 1), round(band.residual_reduction, 2)
    (True, 0.0, 1.0)
    >>> bool(abs(band.thickness_diameters - 4.8) < 0.5), round(band.slip, 2)
    (True, 0.3)
    """

    _parameters = ("bin_width", "max_points", "min_share", "min_reduction", "crossing")

    def __init__(
        self,
        bin_width: float = 0.5,
        max_points: int = 20000,
        *,
        min_share: float = 0.2,
        min_reduction: float = 0.6,
        crossing: float = 0.75,
    ) -> None:
        if not np.isfinite(bin_width) or bin_width <= 0:
            raise ValueError(f"bin_width: must be > 0 (mean diameters), got {bin_width!r}")
        if int(max_points) != max_points or max_points < 100:
            raise ValueError(f"max_points: must be an integer >= 100, got {max_points!r}")
        if not 0.0 < min_share < 0.5:
            raise ValueError(f"min_share: must be in (0, 0.5), got {min_share!r}")
        if not 0.0 < min_reduction <= 1.0:
            raise ValueError(f"min_reduction: must be in (0, 1], got {min_reduction!r}")
        if not 0.0 <= crossing <= 1.0:
            raise ValueError(f"crossing: must be in [0, 1], got {crossing!r}")
        self.bin_width = float(bin_width)
        self.max_points = int(max_points)
        self.min_share = float(min_share)
        self.min_reduction = float(min_reduction)
        self.crossing = float(crossing)

    def compute(
        self,
        positions: ArrayLike,
        displacement: ArrayLike,
        radii: ArrayLike,
        *,
        mask: ArrayLike | None = None,
    ) -> DisplacementBand:
        """Find the band; returns ``self``.

        ``positions`` (N, 2) m at the current state; ``displacement`` (N, 2) m
        since the reference (rows with a NaN are left out); ``radii`` (N,) m;
        ``mask`` (N,) bool restricts the grains considered.

        Steps: :meth:`_slip_line`, :meth:`_refined` (:meth:`_reading`, :meth:`_band`
        at each angle), :mod:`~grainlab.analysis.band_acceptance`.
        """
        pos, disp, rad, considered, valid = _checked(positions, displacement, radii, mask)
        d_mean = float(np.mean(2.0 * rad[considered]))
        origin = pos[valid].mean(axis=0)
        p = (pos[valid] - origin) / d_mean  # lengths in mean diameters from here on
        # what one affine motion of the whole sample leaves: the same two-block fits,
        # without the large common part (no round-off from it in the summed moments)
        _, whole = _affine_fit(p, disp[valid])
        rest = disp[valid] - whole
        one_block = float(np.sum(rest * rest))
        scale = math.sqrt(one_block / rest.shape[0]) if one_block > 0 else 1.0
        v = rest / scale
        r = self._refined(p, v, self._slip_line(p, v))
        trans = r.trans
        normal = np.array([-np.sin(r.angle), np.cos(r.angle)])
        # nothing left by one affine motion (beyond round-off): nothing for two blocks to explain
        affine = one_block <= 1e-20 * float(np.sum(disp[valid] ** 2))
        reduction = 0.0 if affine else max(1.0 - r.residual / float(np.sum(v * v)), 0.0)
        mid = 0.5 * (trans.s_lo + trans.s_hi)
        center = origin + (r.offset + mid) * d_mean * normal
        c = (center - origin) / d_mean
        jump = (_at(r.coef_b, c[None, :]) - _at(r.coef_a, c[None, :]))[0] * scale
        s_all = ((pos - center) @ normal) / d_mean
        members = considered & np.isfinite(pos).all(axis=1) & (np.abs(s_all) <= 0.5 * trans.thickness)
        problems = reduction_problems(reduction, self.min_reduction) + list(trans.problems)
        tangent = np.array([normal[1], -normal[0]])
        problems += crossing_problems(
            pos[valid], tangent, s_all[valid], trans.thickness, 1.0, d_mean, self.crossing
        )
        share = np.full(pos.shape[0], np.nan)
        share[valid] = r.share
        self._store(
            found=not problems,
            reason="; ".join(problems),
            angle=r.angle,
            thickness=trans.thickness * d_mean,
            thickness_diameters=trans.thickness,
            center=center,
            normal=normal,
            members=members,
            residual_reduction=float(reduction),
            jump=jump,
            relative_motion=share,
            profile=((trans.centers - mid) * d_mean, trans.mean_share),
            profile_smooth=trans.smooth,
            mean_diameter=d_mean,
            _positions=pos,
            _radii=rad,
            _displacement=disp,
        )
        return self

    def _slip_line(self, p: NDArray[np.float64], v: NDArray[np.float64]) -> float:
        """Step 1, the scan: the angle (rad, [0, pi)), in 1 degree steps, of the line
        whose two blocks, split at it (a step between them), fit best."""
        coarse = np.radians(np.arange(0.0, 180.0, 1.0))
        pc, vc = random_subset(p, v, self.max_points, np.random.default_rng(0))
        res, _ = _splits(pc, vc, coarse, self.min_share, _SCAN_STEP_D)
        if not np.isfinite(res).any():
            raise ValueError("positions: the grains lie on one line; no split leaves two blocks")
        return float(coarse[_best(-res)])

    def _refined(self, p: NDArray[np.float64], v: NDArray[np.float64], start: float) -> _Reading:
        """Step 3: the reading (:meth:`_reading`) whose two blocks joined
        across their band fit best, over angles within 1.5 degrees of ``start`` (0.1
        degree steps, a parabola through the best three)."""
        grid = start + np.radians(np.arange(-1.5, 1.5 + 1e-9, 0.1))
        readings = [self._reading(p, v, float(a)) for a in grid]
        res = np.array([r.residual for r in readings])
        k = _best(-res)
        best = readings[k]
        if 0 < k < grid.size - 1 and np.isfinite(res[k - 1 : k + 2]).all():
            y0, y1, y2 = res[k - 1], res[k], res[k + 1]
            curv = y0 - 2.0 * y1 + y2
            if curv > 0 and y0 >= y1 <= y2:
                vertex = self._reading(p, v, float(grid[k] + 0.5 * (y0 - y2) / curv * (grid[1] - grid[0])))
                if vertex.residual <= best.residual:
                    best = vertex
        return best

    def _reading(self, p: NDArray[np.float64], v: NDArray[np.float64], angle: float) -> _Reading:
        """The band read at one angle: the best split's offset, the blocks' motions and
        the profile across the line (:meth:`_band`), and the residual of the two blocks
        joined across the band (:func:`_two_block_residual`)."""
        angle = float(np.mod(angle, np.pi))
        res, off = _splits(p, v, np.array([angle]), self.min_share, _SPLIT_STEP_D)
        if not np.isfinite(res[0]):
            none = np.zeros((3, 2))
            no_share = np.full(p.shape[0], np.nan)
            return _Reading(angle, 0.0, _no_transition("no split at this angle"), no_share, none, none, math.inf)
        s = p @ np.array([-np.sin(angle), np.cos(angle)]) - off[0]
        trans, t, coef_a, coef_b = self._band(p, v, s)
        residual = _two_block_residual(p, v, s, trans, coef_a, coef_b)
        return _Reading(angle, float(off[0]), trans, t, coef_a, coef_b, residual)

    def _band(
        self, p: NDArray[np.float64], v: NDArray[np.float64], s: NDArray[np.float64]
    ) -> tuple[_Transition, NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """Step 2: the blocks' motions (refitted without the band and its flanks),
        each grain's share of the relative motion and the profile across the line."""
        in_a, in_b = s < 0.0, s > 0.0
        trans = None
        for _ in range(1 + _REFITS):
            coef_a, _ = _affine_fit(p[in_a], v[in_a])
            coef_b, _ = _affine_fit(p[in_b], v[in_b])
            ua = _at(coef_a, p)
            delta = _at(coef_b, p) - ua
            dd = np.sum(delta * delta, axis=1)
            ok = dd > 1e-12 * max(float(np.max(dd)), 1e-300)
            t = np.where(ok, np.sum((v - ua) * delta, axis=1) / np.where(ok, dd, 1.0), np.nan)
            trans = _transition(s, t, self.bin_width)
            if trans.thickness <= 0.0:
                break
            new_a = s < trans.s_lo - _FLANK_D
            new_b = s > trans.s_hi + _FLANK_D
            if min(new_a.sum(), new_b.sum()) < _MIN_BLOCK or (
                np.array_equal(new_a, in_a) and np.array_equal(new_b, in_b)
            ):
                break
            in_a, in_b = new_a, new_b
        assert trans is not None
        return trans, t, coef_a, coef_b

    residual_reduction = Computed[float](
        "Share of the residual of one affine motion of the whole sample that the two blocks' "
        "motions remove, 1 - S_2/S_1, in [0, 1]."
    )
    jump = Computed[NDArray[np.float64]](
        "(2,) displacement of block B relative to block A at :attr:`center`, m."
    )

    @property
    def jump_magnitude(self) -> float:
        """|:attr:`jump`|, m."""
        return float(np.hypot(*self.jump))

    @property
    def slip(self) -> float:
        """Component of :attr:`jump` along the band, (cos angle, sin angle), m."""
        return float(self.jump @ np.array([np.cos(self.angle), np.sin(self.angle)]))

    @property
    def opening(self) -> float:
        """Component of :attr:`jump` along :attr:`normal`, m (positive: the blocks part)."""
        return float(self.jump @ self.normal)

    relative_motion = Computed[NDArray[np.float64]](
        "(N,) each grain's share of the blocks' relative motion (0 with block A, 1 with block B), "
        "NaN for the grains not considered."
    )
    profile = Computed[tuple[NDArray[np.float64], NDArray[np.float64]]](
        "Distance from the band's centre line (m) and mean share of each bin."
    )
    profile_smooth = Computed[NDArray[np.float64]](
        "(B,) the smoothed share of each bin of :attr:`profile`, on which the edges are read "
        "(where it crosses 0.1 and 0.9)."
    )

    _displacement = Computed[NDArray[np.float64]]("(N, 2) the displacements read, m.")

    def summary(self) -> dict[str, Any]:
        """JSON-ready scalars (NaN and inf as None, angles in degrees, lengths in m)."""
        return {
            **self._slab_summary(),
            "n_particles": int(self.members.sum()),
            "residual_reduction": json_number(self.residual_reduction),
            "jump_m": json_number(self.jump_magnitude),
            "slip_m": json_number(self.slip),
            "opening_m": json_number(self.opening),
        }

    def plot(self, ax: Any = None, **kwargs: Any) -> Any:
        """Grain map coloured by displacement magnitude (Fig. 11) with the band
        outlined; returns the axes."""
        from grainlab import plot

        disp = self._displacement
        ax = plot.particle_map(
            self._positions, self._radii, np.hypot(disp[:, 0], disp[:, 1]), ax=ax,
            label="displacement magnitude (m)", **kwargs,
        )
        plot.outline_shear_band(ax, self)
        return ax


def _checked(
    positions: ArrayLike, displacement: ArrayLike, radii: ArrayLike, mask: ArrayLike | None
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.bool_], NDArray[np.bool_]]:
    """:meth:`DisplacementBand.compute`'s input as arrays, checked, with the grains
    considered and those of them with a finite position and displacement."""
    pos = np.asarray(positions, dtype=np.float64)
    disp = np.asarray(displacement, dtype=np.float64)
    rad = np.asarray(radii, dtype=np.float64)
    n = pos.shape[0] if pos.ndim == 2 else -1
    if pos.shape != (n, 2) or disp.shape != (n, 2) or rad.shape != (n,):
        raise ValueError(
            "positions, displacement, radii: expected shapes (N, 2), (N, 2), (N,), got "
            f"{pos.shape}, {disp.shape}, {rad.shape}"
        )
    considered = np.ones(n, bool) if mask is None else np.asarray(mask, bool)
    if considered.shape != (n,):
        raise ValueError(f"mask: expected shape ({n},), got {considered.shape}")
    valid = considered & np.isfinite(pos).all(axis=1) & np.isfinite(disp).all(axis=1)
    if valid.sum() < MIN_GRAINS:
        raise ValueError(
            f"displacement: need at least {MIN_GRAINS} grains with a finite displacement, "
            f"got {int(valid.sum())}"
        )
    return pos, disp, rad, considered, valid
