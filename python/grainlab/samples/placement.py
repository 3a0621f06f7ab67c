"""Random sequential placement of non-overlapping disks in a box, largest
first, in rounds of array work (docs/samples.md, "Random placement").

Example
-------
>>> import numpy as np
>>> from grainlab.samples import random_placement
>>> rng = np.random.default_rng(1)
>>> d = np.full(50, 1e-3)
>>> xy, r = random_placement((0.0, 0.0, 0.02, 0.02), d, rng)
>>> float(r[0])  # scale 0.5: placed at half their final radius
0.00025
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial import cKDTree

from grainlab.samples._checks import in_range, positive_lengths
from grainlab.samples.porosity import check_box

__all__ = ["PlacementError", "random_placement"]


class PlacementError(ValueError):
    """Random placement could not fit every disk (the box is too full)."""


def random_placement(
    box: ArrayLike,
    diameters: ArrayLike,
    rng: np.random.Generator,
    scale: float = 0.5,
    *,
    batch: int = 256,
    tries: int = 16,
    max_rounds_without_progress: int = 100,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Places disks of radius ``scale * d / 2`` at random, without overlap, inside ``box``.

    Parameters
    ----------
    box : ``(xmin, ymin, xmax, ymax)``, m
    diameters : (N,) final diameters, m
    rng : the random generator (the result is a function of its state)
    scale : placed radius over final radius, in (0, 1] (the paper halves them: 0.5)
    batch : disks attempted per round
    tries : candidate centres per disk per round
    max_rounds_without_progress : rounds in a row that place nothing before giving up

    Returns
    -------
    positions : (N, 2) centres, m, in the order of ``diameters``
    radii : (N,) placed radii ``scale * d / 2``, m

    Raises
    ------
    PlacementError
        (a ``ValueError``) when the disks cannot all be placed: says how many were
        placed and the solid fraction they covered.
    """
    x0, y0, x1, y1 = check_box(box)
    d, scale = _checked(diameters, scale, batch, tries)
    n = len(d)
    radii = 0.5 * scale * d
    positions = np.zeros((n, 2))
    if n == 0:
        return positions, radii
    if 2.0 * radii.max() > min(x1 - x0, y1 - y0):
        k = int(np.argmax(radii))
        raise PlacementError(
            f"diameters[{k}]: a placed disk of diameter {2 * radii[k]:.4g} m does not fit in the box "
            f"({x1 - x0:.4g} x {y1 - y0:.4g} m)"
        )
    area = (x1 - x0) * (y1 - y0)
    order = np.argsort(-radii, kind="stable")
    placed = np.zeros(0, dtype=np.intp)  # indices into the original arrays
    queue = order
    stalled = 0
    tree: cKDTree | None = None
    while len(queue):
        todo = queue[:batch]
        m = len(todo)
        existing = (tree, positions[placed], radii[placed]) if len(placed) else None
        chosen, cpos = _one_round(radii[todo], (x0, y0, x1, y1), rng, tries, existing)
        accepted = todo[chosen]
        positions[accepted] = cpos
        if len(accepted):
            placed = np.concatenate([placed, accepted])
            tree = cKDTree(positions[placed])
            stalled = 0
        else:
            stalled += 1
            if stalled >= max_rounds_without_progress:
                covered = math.pi * np.sum(radii[placed] ** 2) / area
                wanted = math.pi * np.sum(radii**2) / area
                raise PlacementError(
                    f"random placement: placed {len(placed)} of {n} disks (solid fraction {covered:.3f} of "
                    f"the {wanted:.3f} needed at scale {scale:g}); the box is too full for random placement, "
                    "lower scale or the number of disks"
                )
        done = np.zeros(m, dtype=bool)
        done[chosen] = True
        queue = np.concatenate([todo[~done], queue[batch:]])
    return positions, radii


def _checked(diameters: ArrayLike, scale: float, batch: int, tries: int) -> tuple[NDArray[np.float64], float]:
    """The diameters and the scale, checked (bad input names its field)."""
    d = positive_lengths("diameters", diameters, "diameter")
    scale = in_range("scale", scale, "(0, 1]")
    if int(batch) < 1 or int(tries) < 1:
        raise ValueError(f"batch and tries: must be >= 1, got batch={batch}, tries={tries}")
    return d, scale


def _one_round(
    r: NDArray[np.float64],
    box: tuple[float, float, float, float],
    rng: np.random.Generator,
    tries: int,
    existing: tuple[cKDTree, NDArray[np.float64], NDArray[np.float64]] | None,
) -> tuple[NDArray[np.intp], NDArray[np.float64]]:
    """One round of placement for disks of radii ``r``: ``tries`` random centres
    each, the first one clear of the ``existing`` disks (their tree, centres and
    radii) kept, then of a clashing pair of this round the later disk left to
    wait. Returns which disks were placed (indices into ``r``) and where."""
    x0, y0, x1, y1 = box
    m = len(r)
    u = rng.random((m, tries, 2))
    cx = x0 + r[:, None] + u[..., 0] * ((x1 - x0) - 2.0 * r[:, None])
    cy = y0 + r[:, None] + u[..., 1] * ((y1 - y0) - 2.0 * r[:, None])
    cand = np.stack([cx, cy], axis=-1).reshape(-1, 2)
    rc = r[np.repeat(np.arange(m), tries)]
    ok = np.ones(len(cand), dtype=bool) if existing is None else _clear_of(cand, rc, *existing)
    # per disk, the first candidate clear of the placed set
    ok2 = ok.reshape(m, tries)
    first = np.argmax(ok2, axis=1)
    chosen = np.flatnonzero(ok2.any(axis=1))
    cpos = cand.reshape(m, tries, 2)[chosen, first[chosen]]
    crad = r[chosen]
    # conflicts inside the round: the later (smaller) disk of a clashing pair waits
    if len(chosen) > 1:
        pairs = cKDTree(cpos).query_pairs(2.0 * float(crad.max()), output_type="ndarray")
        if len(pairs):
            a, b = pairs.min(axis=1), pairs.max(axis=1)
            clash = np.hypot(*(cpos[a] - cpos[b]).T) < crad[a] + crad[b]
            keep = np.ones(len(chosen), dtype=bool)
            keep[b[clash]] = False
            chosen, cpos = chosen[keep], cpos[keep]
    return chosen, cpos


def _clear_of(
    cand: NDArray[np.float64],
    rc: NDArray[np.float64],
    tree: cKDTree,
    placed_pos: NDArray[np.float64],
    placed_rad: NDArray[np.float64],
) -> NDArray[np.bool_]:
    """Whether each candidate disk overlaps no placed disk."""
    reach = float(rc.max() + placed_rad.max())
    ctree = cKDTree(cand)
    hits = ctree.sparse_distance_matrix(tree, reach, output_type="ndarray")
    ok = np.ones(len(cand), dtype=bool)
    if len(hits):
        ci, pj, dist = hits["i"], hits["j"], hits["v"]
        bad = dist < rc[ci] + placed_rad[pj]
        ok[ci[bad]] = False
    return ok
