"""When a candidate shear band is a band: the acceptance rules of every reading.

:class:`~grainlab.analysis.ShearBand`, :class:`~grainlab.analysis.DisplacementBand`
and :mod:`grainlab.postprocess.band` judge their candidates with these pure
functions; each rule returns what fails (empty: passes), in words that name the
numbers. The rules and thresholds: docs/fabric.md, "Shear band", and
docs/analysis.md, "Three readings of the shear band".
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "CROSSING", "FLANK_D", "MIN_EXCESS", "candidate_reason", "crossing_problems",
    "permutation_p_value", "profile_prominence", "reduction_problems", "significance_problems",
    "slab_eta2", "strain_band_problems", "transition_problems",
]

#: The band's centre line crosses at least this share of the sample's smaller side, and
#: its members cover at least this share of that chord.
CROSSING = 0.75
#: Excess strain (and fraction of the largest strain) below which there is no band at all.
MIN_EXCESS = 1.0e-9
#: Least width (mean diameters) of each flank of a strain band: left out of the
#: prominence's "elsewhere" and of the search for a second band.
FLANK_D = 2.0


def profile_prominence(
    excess: float,
    smooth: NDArray[np.float64],
    distance: NDArray[np.float64],
    crossing: NDArray[np.bool_],
    background: float,
    thickness: float,
    d_mean: float,
) -> tuple[float, float]:
    """``(prominence, elsewhere)`` of a strain band with ``excess`` strain over the
    ``background``: ``elsewhere`` is the largest excess of the smoothed profile
    ``smooth`` (B,) among the ``crossing`` bins beyond the band's flanks (``distance``
    from its centre line > half its ``thickness`` + max(thickness, :data:`FLANK_D`
    mean diameters), m); ``prominence = excess / elsewhere`` (0 without excess, inf
    when nothing else is above the background)."""
    flank = 0.5 * thickness + max(thickness, FLANK_D * d_mean)
    away = crossing & (np.abs(distance) > flank)
    elsewhere = float(smooth[away].max()) - background if away.any() else 0.0
    if excess <= 0.0:
        return 0.0, elsewhere
    if elsewhere <= 0.0:
        return math.inf, elsewhere
    return excess / elsewhere, elsewhere


def strain_band_problems(
    excess: float,
    prominence: float,
    elsewhere: float,
    thickness_diameters: float,
    min_thickness: float,
    min_prominence: float,
) -> list[str]:
    """A strain band's own tests: some excess strain, at least ``min_thickness`` mean
    diameters thick, a prominence at least ``min_prominence``."""
    if excess <= 0.0:
        return ["no part of the profile stands above the background strain"]
    problems = []
    if thickness_diameters < min_thickness:
        problems.append(
            f"thinner ({thickness_diameters:.2f} mean diameters) than "
            f"min_thickness = {min_thickness:g}"
        )
    if prominence < min_prominence:
        problems.append(
            f"does not stand out: prominence {prominence:.2f} < min_prominence = "
            f"{min_prominence:g} (another part of the profile is "
            f"{100 * elsewhere / excess:.0f} % as high above the background)"
        )
    return problems


def crossing_problems(
    pos: NDArray[np.float64],
    tangent: NDArray[np.float64],
    s: NDArray[np.float64],
    thickness: float,
    reach: float,
    d_mean: float,
    crossing: float = CROSSING,
) -> list[str]:
    """Whether a band crosses the sample of the grains at ``pos`` (M, 2) m: the chord
    of its centre line (direction ``tangent``) through the grains within ``reach`` of
    it is at least ``crossing`` of the sample's smaller side, and the band's grains
    cover ``crossing`` of the chord. ``s`` (M,) is each grain's distance from the
    line, in the unit of ``thickness`` and ``reach``; ``d_mean`` (m) the message's."""
    side = float(np.ptp(pos, axis=0).min())
    members = np.abs(s) <= 0.5 * thickness
    near = np.abs(s) <= max(0.5 * thickness, reach)
    chord = float(np.ptp(pos[near] @ tangent)) if near.sum() > 1 else 0.0
    span = float(np.ptp(pos[members] @ tangent)) if members.sum() > 1 else 0.0
    if chord < crossing * side or span < crossing * chord:
        return [
            f"does not cross the sample (its grains span {span / d_mean:.1f} mean diameters "
            f"of a {chord / d_mean:.1f}-diameter chord; the sample's smaller side is "
            f"{side / d_mean:.1f})"
        ]
    return []


def reduction_problems(reduction: float, min_reduction: float) -> list[str]:
    """A displacement band's two blocks must remove at least ``min_reduction`` of the
    residual of one affine motion of the whole sample (``reduction``, in [0, 1])."""
    if reduction < min_reduction:
        return [
            f"two blocks explain little more than one motion of the whole sample: they remove "
            f"{100 * reduction:.0f} % of its residual (min_reduction = {min_reduction:g})"
        ]
    return []


def transition_problems(reaches_both: bool, low: float, high: float) -> list[str]:
    """A displacement band's profile must reach block A's motion (share <= ``low``) on
    one side and block B's (share >= ``high``) on the other inside the sample."""
    if reaches_both:
        return []
    return [
        f"the transition does not reach block A's motion (share <= {low:g}) on one "
        f"side and block B's (share >= {high:g}) on the other inside the sample"
    ]


def slab_eta2(
    pos: NDArray[np.float64], values: NDArray[np.float64], normal: NDArray[np.float64], width: float
) -> float:
    """Adjusted correlation ratio of ``values`` (M,) with bins of ``width`` (m) across
    a slab of unit ``normal``, as :class:`~grainlab.analysis.ShearBand` scores an
    angle (every grain counts): ``1 - (1 - eta^2) (M - 1) / (M - B)``."""
    s = pos @ normal
    b = ((s - s.min()) / width).astype(np.int64)
    counts = np.bincount(b)
    sums = np.bincount(b, weights=values)
    occupied = counts > 0
    m = values.size
    mean = float(values.mean())
    total = float(((values - mean) ** 2).sum())
    if total <= 0.0:
        return 0.0
    between = float((sums[occupied] ** 2 / counts[occupied]).sum()) - m * mean**2
    n_bins = int(occupied.sum())
    return 1.0 - (1.0 - between / total) * (m - 1) / max(m - n_bins, 1)


def permutation_p_value(score: float, null: NDArray[np.float64]) -> float:
    """``(1 + #(null >= score)) / (K + 1)`` of a band's score against the scores of
    the bands found in K random rearrangements of its field (1/(K+1) at least)."""
    return float((1 + np.sum(null >= score)) / (null.size + 1))


def significance_problems(p_value: float, n_permutations: int, values: str) -> list[str]:
    """A band must be significant, ``p_value <= 0.05`` against ``n_permutations``
    random rearrangements of its field's ``values`` (words: "strain values")."""
    if p_value > 0.05:
        return [
            f"not significant (p = {p_value:.2f} against {n_permutations} random "
            f"rearrangements of the {values})"
        ]
    return []


def candidate_reason(angle_deg: float, thickness_diameters: float, problems: list[str]) -> str:
    """The reason a run gives for a candidate band that failed ``problems``."""
    return (
        f"best candidate at {angle_deg:.1f} deg, {thickness_diameters:.1f} "
        "mean diameters thick: " + "; ".join(problems)
    )
