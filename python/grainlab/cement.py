"""Cement: breakable bonds between disks, and their seeded strengths.

The engine's cement bonds (docs/cemented.md) act in parallel with the contact
law and break, inside a run, at the step where a bond's stress reaches its
strength. This module holds what the Python side adds: strengths drawn with a
seeded NumPy generator (:func:`draw_strengths`), the checks and broadcasting of
:meth:`grainlab.Simulation.add_cement_bonds`, and the typed records of the
breaks (:class:`BondBreaks`) and of the intact bonds (:class:`CementBonds`).

Example
-------
>>> import numpy as np
>>> from grainlab import Simulation
>>> from grainlab.cement import draw_strengths
>>> sim = Simulation(positions=[[0.0, 0.0], [2e-3, 0.0]], radii=[1e-3, 1e-3], density=2650.0)
>>> rng = np.random.default_rng(7)
>>> sim.add_cement_bonds(
...     [0], [1], normal_stiffness=2e10, shear_stiffness=2e10,
...     tensile_strength=draw_strengths(rng, 1e4, 2e3, 1), cohesion=2e4, friction_angle=30.0,
... )
>>> sim.n_cement_bonds
1
>>> sim.velocities = [[-0.05, 0.0], [0.05, 0.0]]
>>> sim.run(2_000)
>>> breaks = sim.take_bond_breaks()
>>> len(breaks), str(breaks.mode[0]), sim.n_cement_bonds
(1, 'tension', 0)
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

#: The kinds of cement bond: ``"parallel"`` (stiffnesses per area in Pa/m,
#: strengths in Pa, a moment) and ``"contact"`` (stiffnesses in N/m, strengths in
#: N, no moment).
CementKindName = Literal["parallel", "contact"]

_DISTRIBUTIONS = ("normal", "weibull")


def draw_strengths(
    rng: np.random.Generator,
    mean: float,
    scatter: float,
    size: int,
    distribution: Literal["normal", "weibull"] = "normal",
) -> NDArray[np.float64]:
    """``size`` strengths of mean ``mean`` and standard deviation ``scatter``
    (same unit as ``mean``), drawn from ``rng`` (a seeded ``numpy.random.Generator``).

    ``"normal"``: a normal law truncated at 0 (a negative draw is drawn again,
    so with a scatter above about a third of the mean the mean is slightly
    raised). ``"weibull"``: a two-parameter Weibull law whose shape ``m`` gives
    the coefficient of variation ``scatter / mean``
    (``Gamma(1 + 2/m) / Gamma(1 + 1/m)^2 - 1 = (scatter / mean)^2``, solved by
    bisection) and whose scale is ``mean / Gamma(1 + 1/m)``. A zero scatter
    gives ``mean`` for every bond. The same generator state gives the same
    strengths.

    >>> import numpy as np
    >>> s = draw_strengths(np.random.default_rng(1), 1e6, 2e5, 20_000, "weibull")
    >>> round(float(s.mean()) / 1e6, 2), round(float(s.std()) / 2e5, 1)
    (1.0, 1.0)
    """
    if not (math.isfinite(mean) and mean > 0):
        raise ValueError(f"mean: a strength is finite and > 0, got {mean}")
    if not (math.isfinite(scatter) and scatter >= 0):
        raise ValueError(f"scatter: a standard deviation is finite and >= 0, got {scatter}")
    if distribution not in _DISTRIBUTIONS:
        raise ValueError(f"distribution: expected one of {', '.join(_DISTRIBUTIONS)}, got {distribution!r}")
    if int(size) < 0:
        raise ValueError(f"size: expected >= 0, got {size}")
    n = int(size)
    if scatter == 0:
        return np.full(n, float(mean))
    if distribution == "weibull":
        m = _weibull_shape(scatter / mean)
        return mean / math.gamma(1 + 1 / m) * rng.weibull(m, n)
    out = rng.normal(mean, scatter, n)
    bad = out < 0
    while bad.any():
        out[bad] = rng.normal(mean, scatter, int(bad.sum()))
        bad = out < 0
    return out


def pairs_within_gap(
    positions: ArrayLike,
    radii: ArrayLike,
    gap: float,
    *,
    body: ArrayLike | None = None,
    period: tuple[float, float] | None = None,
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """The pairs ``(i, j)``, ``i < j``, whose surfaces are at most ``gap`` apart
    (touching and overlapping pairs included), sorted; two pebbles of one ``body``
    are no pair. ``period`` ``(Lx, Ly)``: positions in a periodic rectangle whose
    corner is the origin (the nearest image of each pair).

    >>> i, j = pairs_within_gap([[0, 0], [2.0, 0], [4.5, 0]], [1.0, 1.0, 1.0], 0.5)
    >>> i.tolist(), j.tolist()
    ([0, 1], [1, 2])
    """
    from scipy.spatial import cKDTree

    x = np.asarray(positions, dtype=np.float64).reshape(-1, 2)
    r = np.asarray(radii, dtype=np.float64).reshape(-1)
    if not (math.isfinite(gap) and gap >= 0):
        raise ValueError(f"gap: a distance is finite and >= 0, got {gap}")
    if len(r) != len(x):
        raise ValueError(f"radii: {len(r)} for {len(x)} positions")
    if len(x) < 2:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    box = None if period is None else np.asarray(period, dtype=np.float64)
    tree = cKDTree(x if box is None else np.mod(x, box), boxsize=box)
    pairs = tree.query_pairs(2.0 * float(r.max()) + gap, output_type="ndarray").astype(np.int64)
    pairs.sort(axis=1)
    d = x[pairs[:, 1]] - x[pairs[:, 0]]
    if box is not None:
        d -= box * np.round(d / box)
    keep = np.hypot(d[:, 0], d[:, 1]) <= r[pairs[:, 0]] + r[pairs[:, 1]] + gap
    if body is not None:
        b = np.asarray(body).reshape(-1)
        keep &= b[pairs[:, 0]] != b[pairs[:, 1]]
    pairs = pairs[keep]
    pairs = pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))]
    return pairs[:, 0], pairs[:, 1]


def crack_orientations(normal_x: ArrayLike, normal_y: ArrayLike) -> NDArray[np.float64]:
    """Each crack's orientation in [0, pi): the line of the broken bond's section,
    perpendicular to its normal (a crack opened by vertical tension runs horizontally).

    >>> crack_orientations([1.0, 0.0], [0.0, 1.0]).round(4).tolist()
    [1.5708, 0.0]
    """
    nx, ny = np.asarray(normal_x, dtype=np.float64), np.asarray(normal_y, dtype=np.float64)
    return np.mod(np.arctan2(ny, nx) + 0.5 * np.pi, np.pi)


def _weibull_shape(cv: float) -> float:
    """The Weibull shape whose coefficient of variation is ``cv`` (bisection on log m)."""

    def cv_of(m: float) -> float:
        g1, g2 = math.gamma(1 + 1 / m), math.gamma(1 + 2 / m)
        return math.sqrt(max(g2 / (g1 * g1) - 1, 0.0))

    lo, hi = 0.05, 500.0
    if not cv_of(hi) <= cv <= cv_of(lo):
        raise ValueError(f"scatter: a Weibull law has a coefficient of variation in [{cv_of(hi):.3g}, {cv_of(lo):.3g}], got {cv:.3g}")
    for _ in range(200):
        mid = math.sqrt(lo * hi)
        if cv_of(mid) > cv:
            lo = mid
        else:
            hi = mid
    return math.sqrt(lo * hi)


def cement_arguments(
    n_particles: int,
    i: ArrayLike,
    j: ArrayLike,
    kind: str,
    values: dict[str, ArrayLike],
) -> tuple[Any, ...]:
    """The engine's arguments of :meth:`grainlab.Simulation.add_cement_bonds`:
    ``i``, ``j`` as int64 arrays of one length, ``kind``, then each of
    ``values`` (radius_multiplier, normal_stiffness, shear_stiffness,
    tensile_strength, cohesion, friction_angle, in that order) broadcast to one
    float per pair. Refuses, in one line naming the field, what NumPy cannot
    read or broadcast, a non-integer index and an index out of range; the
    engine checks the values and the pairs (itself, twice, already bonded)."""
    if kind not in ("parallel", "contact"):
        raise ValueError(f"kind: expected 'parallel' or 'contact', got {kind!r}")
    pairs = []
    for name, a in (("i", i), ("j", j)):
        arr = np.atleast_1d(np.asarray(a))
        if arr.ndim != 1 or (arr.size and arr.dtype.kind not in "iu"):
            raise ValueError(f"{name}: expected a 1-D array of particle indices, got {arr.dtype} {arr.shape}")
        bad = np.flatnonzero((arr < 0) | (arr >= n_particles))
        if bad.size:
            k = int(bad[0])
            raise ValueError(f"{name}[{k}]: particle index {int(arr[k])} out of range 0..{n_particles}")
        pairs.append(arr.astype(np.int64))
    if pairs[0].shape != pairs[1].shape:
        raise ValueError(f"j: has {pairs[1].size} entries for {pairs[0].size} values of i")
    n = pairs[0].size
    columns = []
    for name, v in values.items():
        try:
            col = np.broadcast_to(np.asarray(v, dtype=np.float64), (n,))
        except (ValueError, TypeError) as e:
            raise ValueError(f"{name}: expected one number or one per pair ({n}): {e}") from None
        columns.append(np.ascontiguousarray(col))
    return (pairs[0], pairs[1], kind, *columns)


def _arrays(d: dict[str, Any], text: str) -> dict[str, NDArray[Any]]:
    """The engine's dict as arrays, its ``text`` entry (a list of names) as a 1-D str array."""
    out = {k: np.asarray(v) for k, v in d.items()}
    out[text] = np.asarray(d[text], dtype=np.str_).reshape(-1)
    return out


@dataclass(frozen=True)
class BondBreaks:
    """Breaks of cement bonds, one entry per break in the order they happened
    (:meth:`grainlab.Simulation.take_bond_breaks`).

    Signs: normal force compression positive (a break in tension has a
    negative one), ``normal`` the unit vector from ``i`` to ``j``; ``position``
    the bond's centre, mid-gap on the line of centres (m), ``energy`` the
    strain energy the bond held (J per m of thickness: normal, shear and
    bending springs)."""

    step: NDArray[np.uint64]
    """(K,) step count of the evaluation that broke the bond."""
    time: NDArray[np.float64]
    """(K,) simulated time of that state, s."""
    i: NDArray[np.uint32]
    """(K,) first particle (user index)."""
    j: NDArray[np.uint32]
    """(K,) second particle (user index)."""
    position: NDArray[np.float64]
    """(K, 2) bond centre, m."""
    normal: NDArray[np.float64]
    """(K, 2) unit normal from i to j."""
    mode: NDArray[np.str_]
    """(K,) ``"tension"`` or ``"shear"``."""
    energy: NDArray[np.float64]
    """(K,) strain energy released, J/m."""
    normal_force: NDArray[np.float64]
    """(K,) normal force at the break, N (compression positive)."""
    shear_force: NDArray[np.float64]
    """(K,) shear force at the break, N."""
    moment: NDArray[np.float64]
    """(K,) moment at the break, N m (0 for a contact bond)."""

    def __len__(self) -> int:
        return int(self.step.size)

    @classmethod
    def _from_engine(cls, d: dict[str, Any]) -> BondBreaks:
        return cls(**_arrays(d, "mode"))


@dataclass(frozen=True)
class CementBonds:
    """The intact cement bonds (:meth:`grainlab.Simulation.cement_bonds`), in the
    engine's order: forces at the current state (normal force compression
    positive, N; shear force on ``j`` along the normal turned +90 degrees, N;
    moment on ``j``, N m), section (``area`` m^2 per m, 1 for a contact bond;
    ``bond_radius`` m, 0 for a contact bond) and strengths (Pa, N for a contact bond)."""

    i: NDArray[np.uint32]
    j: NDArray[np.uint32]
    kind: NDArray[np.str_]
    normal_force: NDArray[np.float64]
    shear_force: NDArray[np.float64]
    moment: NDArray[np.float64]
    area: NDArray[np.float64]
    bond_radius: NDArray[np.float64]
    tensile_strength: NDArray[np.float64]
    cohesion: NDArray[np.float64]

    def __len__(self) -> int:
        return int(self.i.size)

    @classmethod
    def _from_engine(cls, d: dict[str, Any]) -> CementBonds:
        return cls(**_arrays(d, "kind"))
