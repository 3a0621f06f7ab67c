"""Fragments of crushable grains (docs/cemented.md, "Crushable grains"): the
connected components of the intact bond graph, each fragment's solid area and
equivalent-area diameter, and the fragments' grading (percent of the solid area
passing each size, the 2D reading of percent passing by mass). Pure: arrays in,
arrays out.

>>> import numpy as np
>>> labels = fragment_labels(4, [0, 2], [1, 3])
>>> labels.tolist()
[0, 0, 1, 1]
>>> area, size = fragment_sizes(np.ones(4), labels)
>>> np.round(size / 2, 6).tolist()  # two disks of radius 1: the equivalent disk's radius sqrt(2)
[1.414214, 1.414214]
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["fragment_grading", "fragment_labels", "fragment_sizes", "percent_passing"]


def fragment_labels(n: int, i: ArrayLike, j: ArrayLike) -> NDArray[np.int64]:
    """(n,) the fragment of each of ``n`` disks: two disks are of one fragment when a
    path of bonds ``(i, j)`` joins them (a disk without a bond is a fragment of its
    own); fragments are numbered by their first disk."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    a = np.asarray(i, dtype=np.int64).reshape(-1)
    b = np.asarray(j, dtype=np.int64).reshape(-1)
    if a.shape != b.shape:
        raise ValueError(f"j: {b.size} bond ends for {a.size} in i")
    if a.size and (min(a.min(), b.min()) < 0 or max(a.max(), b.max()) >= n):
        raise ValueError(f"i, j: a bond names a disk outside 0 .. {n - 1}")
    graph = coo_matrix((np.ones(a.size), (a, b)), shape=(n, n))
    _, labels = connected_components(graph, directed=False)
    return np.asarray(labels, dtype=np.int64)


def fragment_sizes(radii: ArrayLike, labels: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Each fragment's solid area (the sum of its disks' ``pi r^2``, m^2 per m of
    thickness) and equivalent-area diameter ``2 sqrt(area / pi)`` (m), by label."""
    r = np.asarray(radii, dtype=np.float64).reshape(-1)
    area = np.bincount(np.asarray(labels, dtype=np.int64).reshape(-1), weights=np.pi * r * r).astype(np.float64)
    return area, 2.0 * np.sqrt(area / np.pi)


def percent_passing(sizes: ArrayLike, areas: ArrayLike, sieves: ArrayLike) -> NDArray[np.float64]:
    """Percent of the fragments' solid area whose size is at most each of ``sieves``."""
    d = np.asarray(sizes, dtype=np.float64).reshape(-1)
    w = np.asarray(areas, dtype=np.float64).reshape(-1)
    order = np.argsort(d)
    cumulative = np.concatenate([[0.0], np.cumsum(w[order])])
    below = np.searchsorted(d[order], np.asarray(sieves, dtype=np.float64), side="right")
    return np.asarray(100.0 * cumulative[below] / cumulative[-1], dtype=np.float64)


def fragment_grading(radii: ArrayLike, labels: ArrayLike, sieves: ArrayLike) -> dict[str, Any]:
    """The fragments of ``labels``: their count, their solid area, the size d50 that half
    of it passes (interpolated in log size between the fragments' sizes) and the percent
    passing each of ``sieves``."""
    area, size = fragment_sizes(radii, labels)
    order = np.argsort(size)
    cumulative = 100.0 * np.cumsum(area[order]) / area.sum()
    d50 = float(np.exp(np.interp(50.0, cumulative, np.log(size[order]))))
    return {"fragments": len(area), "solid_area_m2": float(area.sum()), "d50_m": d50,
            "percent_passing": percent_passing(size, area, sieves).tolist()}
