r"""Fabric inside and outside a shear band, and how well lambda alone finds the band
(docs/analysis.md, "The band against the rest").

Example
-------
>>> import numpy as np
>>> roc_auc(np.array([3.0, 4.0, 1.0, 2.0]), np.array([True, True, False, False]))
1.0
>>> roc_auc(np.array([1.0, 1.0]), np.array([True, False]))
0.5
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial import cKDTree
from scipy.stats import mannwhitneyu

from grainlab.analysis._compute import Compute, Computed

__all__ = ["GROUP_MEASURES", "BandFabric", "coarse_grained", "roc_auc"]

#: The measures of each group (inside, outside), in order.
GROUP_MEASURES: tuple[str, ...] = (
    "n_grains",
    "mean_lambda",
    "mean_lambda_all",
    "coordination_number",
    "fraction_0",
    "fraction_1",
    "fraction_2",
    "fraction_3_or_more",
    "fraction_2_of_load_bearing",
    "fraction_3_or_more_of_load_bearing",
    "fraction_lambda_above_half",
    "mean_abs_rotation_rad",
)


def roc_auc(scores: ArrayLike, labels: ArrayLike) -> float:
    """Area under the ROC curve of ``scores`` for the boolean ``labels`` (ties
    count one half): the Mann-Whitney U of the positives over ``n_pos * n_neg``.
    Non-finite scores are left out; NaN when either class is empty."""
    s = np.asarray(scores, dtype=np.float64)
    y = np.asarray(labels, dtype=bool)
    if s.shape != y.shape:
        raise ValueError(f"scores and labels: shapes differ, {s.shape} and {y.shape}")
    ok = np.isfinite(s)
    pos, neg = s[ok & y], s[ok & ~y]
    if pos.size == 0 or neg.size == 0:
        return math.nan
    u = mannwhitneyu(pos, neg, alternative="two-sided", method="asymptotic").statistic
    return float(u) / float(pos.size * neg.size)


def coarse_grained(positions: ArrayLike, values: ArrayLike, radius: float) -> NDArray[np.float64]:
    """(N,) mean of the finite ``values`` over the particles whose centres lie
    within ``radius`` of each particle's centre (itself included); NaN where
    there are none."""
    pos = np.asarray(positions, dtype=np.float64)
    v = np.asarray(values, dtype=np.float64)
    if pos.ndim != 2 or pos.shape[1] != 2 or v.shape != (pos.shape[0],):
        raise ValueError(f"positions (N, 2) and values (N,) expected, got {pos.shape} and {v.shape}")
    if not (math.isfinite(radius) and radius > 0):
        raise ValueError(f"radius: expected a number > 0, got {radius!r}")
    n = pos.shape[0]
    if n == 0:
        return np.zeros(0)
    ok = np.isfinite(v)
    tree = cKDTree(pos)
    pairs = tree.query_pairs(radius, output_type="ndarray")
    i = np.concatenate([pairs[:, 0], pairs[:, 1], np.arange(n)])
    j = np.concatenate([pairs[:, 1], pairs[:, 0], np.arange(n)])
    use = ok[j]
    total = np.bincount(i[use], weights=v[j[use]], minlength=n)
    count = np.bincount(i[use], minlength=n)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(count > 0, total / np.maximum(count, 1), np.nan)


def _group(
    members: NDArray[np.bool_],
    lam: NDArray[np.float64],
    counts: NDArray[np.int64],
    grain_contacts: NDArray[np.int64],
    rotation: NDArray[np.float64] | None,
) -> dict[str, float]:
    n = int(members.sum())
    nan = math.nan
    if n == 0:
        return dict.fromkeys(GROUP_MEASURES, nan) | {"n_grains": 0}
    c = counts[members]
    lg = lam[members]
    bearing = c >= 2
    n_bearing = int(bearing.sum())
    rot = np.abs(rotation[members]) if rotation is not None else np.full(n, nan)
    rot = rot[np.isfinite(rot)]
    return {
        "n_grains": n,
        "mean_lambda": float(lg[bearing].mean()) if n_bearing else nan,
        "mean_lambda_all": float(lg.mean()),
        "coordination_number": float(grain_contacts[members].mean()),
        "fraction_0": float(np.mean(c == 0)),
        "fraction_1": float(np.mean(c == 1)),
        "fraction_2": float(np.mean(c == 2)),
        "fraction_3_or_more": float(np.mean(c >= 3)),
        "fraction_2_of_load_bearing": float(np.mean(c[bearing] == 2)) if n_bearing else nan,
        "fraction_3_or_more_of_load_bearing": float(np.mean(c[bearing] >= 3)) if n_bearing else nan,
        "fraction_lambda_above_half": float(np.mean(lg > 0.5)),
        "mean_abs_rotation_rad": float(rot.mean()) if rot.size else nan,
    }


class BandFabric(Compute):
    """Fabric of the grains inside and outside a band, and the AUC of lambda
    as a classifier of band membership (docs/analysis.md).

    Parameters
    ----------
    coarse_radius : float, default 2.0
        Radius of the disk that :func:`coarse_grained` averages lambda over,
        in mean grain diameters (the local strain's neighbourhood,
        docs/fabric.md).

    Example
    -------
    >>> import numpy as np
    >>> pos = np.c_[np.arange(6.0), np.zeros(6)]
    >>> lam = np.array([0.1, 0.1, 0.6, 0.7, 0.1, 0.2])
    >>> counts = np.array([3, 3, 2, 2, 4, 3])
    >>> band = np.array([False, False, True, True, False, False])
    >>> bf = BandFabric().compute(pos, np.ones(6), lam, counts, band)
    >>> bf.auc_lambda, bf.inside["fraction_2"], bf.outside["fraction_3_or_more"]
    (1.0, 1.0, 1.0)
    """

    _parameters = ("coarse_radius",)

    def __init__(self, coarse_radius: float = 2.0) -> None:
        if not (math.isfinite(coarse_radius) and coarse_radius > 0):
            raise ValueError(f"coarse_radius: expected a number > 0, got {coarse_radius!r}")
        self.coarse_radius = float(coarse_radius)

    def compute(
        self,
        positions: ArrayLike,
        diameters: ArrayLike,
        stability_index: ArrayLike,
        n_contacts: ArrayLike,
        members: ArrayLike,
        *,
        grain_contacts: ArrayLike | None = None,
        rotation: ArrayLike | None = None,
    ) -> BandFabric:
        """Measure the grains given (arrays of the same length, one entry per grain).

        ``n_contacts`` are the contacts lambda counts (boundary bodies
        included), ``grain_contacts`` the grain-grain contacts that the
        coordination number counts (default ``n_contacts``), ``rotation`` the
        rotation of each grain since a reference state (rad, NaN unknown).
        """
        pos = np.asarray(positions, dtype=np.float64)
        lam = np.asarray(stability_index, dtype=np.float64)
        counts = np.asarray(n_contacts, dtype=np.int64)
        band = np.asarray(members, dtype=bool)
        d = np.asarray(diameters, dtype=np.float64)
        grain = counts if grain_contacts is None else np.asarray(grain_contacts, dtype=np.int64)
        rot = None if rotation is None else np.asarray(rotation, dtype=np.float64)
        n = lam.shape[0]
        for name, a in (("positions", pos[:, 0] if pos.ndim == 2 else pos), ("diameters", d),
                        ("n_contacts", counts), ("members", band), ("grain_contacts", grain)):
            if a.shape != (n,):
                raise ValueError(f"{name}: expected {n} entries (one per grain), got shape {a.shape}")
        if rot is not None and rot.shape != (n,):
            raise ValueError(f"rotation: expected {n} entries (one per grain), got shape {rot.shape}")
        radius = self.coarse_radius * float(np.mean(d)) if n else 1.0
        field = coarse_grained(pos, lam, radius) if n else np.zeros(0)
        self._store(
            inside=_group(band, lam, counts, grain, rot),
            outside=_group(~band, lam, counts, grain, rot),
            auc_lambda=roc_auc(lam, band),
            auc_lambda_field=roc_auc(field, band),
            lambda_field=field,
        )
        return self

    inside = Computed[dict[str, float]](":data:`GROUP_MEASURES` of the band's grains.")
    outside = Computed[dict[str, float]](":data:`GROUP_MEASURES` of the grains outside the band.")
    auc_lambda = Computed[float]("ROC AUC of per-grain lambda for band membership.")
    auc_lambda_field = Computed[float](
        "ROC AUC of the coarse-grained lambda field for band membership."
    )
    lambda_field = Computed[NDArray[np.float64]](
        "(N,) lambda averaged over ``coarse_radius`` mean diameters around each grain."
    )

    def summary(self) -> dict[str, Any]:
        """Every number, JSON-ready: ``inside_*``, ``outside_*``, the AUCs."""
        out: dict[str, Any] = {}
        for side in ("inside", "outside"):
            for key, value in getattr(self, side).items():
                out[f"{side}_{key}"] = value
        out["auc_lambda"] = self.auc_lambda
        out["auc_lambda_field"] = self.auc_lambda_field
        return out
