r"""Love-Weber stress from contact forces: of each grain, of a region, of a set of contacts.

Compression positive, Pa, unit thickness. Forms, contact points and branch vectors:
docs/fabric.md, "Stress: grains, regions and sets of contacts".
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from grainlab.analysis._compute import Compute, Computed
from grainlab.analysis._util import principal_stresses, sample_bounds
from grainlab.snapshot import Snapshot

__all__ = [
    "GrainStress",
    "LoveWeberStress",
    "branch_vectors",
    "contact_forces_on_i",
    "contact_points",
    "contact_stress",
    "grain_stress",
    "love_weber_stress",
]


def love_weber_stress(
    positions: ArrayLike,
    contact_i: ArrayLike,
    contact_j: ArrayLike,
    contact_point: ArrayLike,
    force_on_j: ArrayLike,
    area: float,
    selected: ArrayLike | None = None,
    *,
    wall_particle: ArrayLike | None = None,
    wall_point: ArrayLike | None = None,
    wall_force_on_particle: ArrayLike | None = None,
) -> NDArray[np.float64]:
    """The 2x2 average stress (Pa, compression positive) of the ``selected`` particles.

    Parameters
    ----------
    positions : (N, 2) particle centres, m
    contact_i, contact_j : (K,) particle indices of each contact
    contact_point : (K, 2) contact points, m
    force_on_j : (K, 2) contact force on ``j`` (its opposite acts on ``i``), N per m thickness
    area : area of the region (m^2 per m thickness)
    selected : (N,) bool mask of the particles whose contacts count (default all)
    wall_particle, wall_point, wall_force_on_particle : particle-wall contacts (optional)

    Examples
    --------
    Two disks pressed together along x by 1 N, in a region of 1 m^2:

    >>> s = love_weber_stress([[0, 0], [2, 0]], [0], [1], [[1, 0]], [[1.0, 0.0]], 1.0)
    >>> float(s[0, 0])  # compression along x: 1 m lever on each side times 1 N
    2.0
    """
    x = np.asarray(positions, dtype=float)
    ci = np.asarray(contact_i, dtype=np.int64)
    cj = np.asarray(contact_j, dtype=np.int64)
    point = np.asarray(contact_point, dtype=float).reshape(-1, 2)
    f = np.asarray(force_on_j, dtype=float).reshape(-1, 2)
    if not area > 0:
        raise ValueError(f"area: must be > 0, got {area}")
    mask = np.ones(len(x), dtype=bool) if selected is None else np.asarray(selected, dtype=bool)
    total = np.zeros((2, 2))
    # on j: +f at the contact point; on i: -f
    for side, sign in ((cj, 1.0), (ci, -1.0)):
        keep = mask[side]
        arm = point[keep] - x[side[keep]]
        total += sign * arm.T @ f[keep]
    if wall_particle is not None:
        wp = np.asarray(wall_particle, dtype=np.int64)
        keep = mask[wp]
        arm = np.asarray(wall_point, dtype=float).reshape(-1, 2)[keep] - x[wp[keep]]
        total += arm.T @ np.asarray(wall_force_on_particle, dtype=float).reshape(-1, 2)[keep]
    sym = 0.5 * (total + total.T)
    return -sym / area


# ------------------------------------------------------------------ on snapshots
def contact_forces_on_i(snapshot: Snapshot) -> NDArray[np.float64]:
    """(Nc, 2) force on particle ``contact_i`` of each contact, N (per m of
    thickness): ``-f_n n + f_s t`` with ``t = rot90(n) = (-n_y, n_x)``; the
    shear part is 0 when the snapshot has no shear forces.

    Raises ValueError when the snapshot has no normal forces.
    """
    if snapshot.normal_force is None:
        raise ValueError("normal_force: the snapshot has no contact forces (needed for stresses)")
    n = np.asarray(snapshot.contact_normals())
    fn = np.asarray(snapshot.normal_force)
    fs = np.zeros_like(fn) if snapshot.shear_force is None else np.asarray(snapshot.shear_force)
    t = np.column_stack([-n[:, 1], n[:, 0]])
    return np.asarray(-fn[:, None] * n + fs[:, None] * t, dtype=np.float64)


def branch_vectors(snapshot: Snapshot) -> NDArray[np.float64]:
    """(Nc, 2) branch vector of each contact, m: ``x_j - x_i`` (minimum image)
    for particle contacts, the contact point minus ``x_i`` for wall contacts.

    When the snapshot stores the contact normals and overlaps (an engine's
    snapshot does), a particle contact's branch is ``(r_i + r_j - delta) n``:
    the same vector for disks, and the only one at hand in a sheared periodic
    cell, whose images the snapshot's rectangular box cannot describe."""
    x = np.asarray(snapshot.positions)
    ci = np.asarray(snapshot.contact_i)
    cj = np.asarray(snapshot.contact_j)
    wall = cj < 0
    overlap = snapshot.contact_fields.get("overlap")
    if snapshot.contact_normal is not None and overlap is not None:
        r = np.asarray(snapshot.radii)
        n = np.asarray(snapshot.contact_normal)
        length = r[ci] + r[np.where(wall, ci, cj)] - np.asarray(overlap, dtype=np.float64)
        d = length[:, None] * n
    else:
        d = snapshot.minimum_image(x[np.where(wall, ci, cj)] - x[ci])
    if wall.any():
        d[wall] = contact_points(snapshot)[wall] - x[ci[wall]]
    return np.asarray(d, dtype=np.float64)


def contact_points(snapshot: Snapshot) -> NDArray[np.float64]:
    """(Nc, 2) contact points, m: the stored ones, else ``x_i + (r_i - delta/2) n``
    with the overlap ``delta = r_i + r_j - |x_j - x_i|`` (a wall contact:
    ``x_i + r_i n``), so that a point may lie outside a periodic box."""
    if snapshot.contact_point is not None:
        return np.asarray(snapshot.contact_point, dtype=np.float64)
    x = np.asarray(snapshot.positions)
    r = np.asarray(snapshot.radii)
    ci = np.asarray(snapshot.contact_i)
    cj = np.asarray(snapshot.contact_j)
    n = np.asarray(snapshot.contact_normals())
    wall = cj < 0
    cjs = np.where(wall, ci, cj)
    d = snapshot.minimum_image(x[cjs] - x[ci])
    overlap = np.where(wall, 0.0, r[ci] + r[cjs] - np.hypot(d[:, 0], d[:, 1]))
    return np.asarray(x[ci] + (r[ci] - 0.5 * overlap)[:, None] * n, dtype=np.float64)


def contact_stress(
    snapshot: Snapshot, used: ArrayLike | None = None, area: float | None = None
) -> NDArray[np.float64]:
    """(2, 2) stress of the contacts ``used`` ((Nc,) mask, default all), Pa,
    compression positive: ``(1/A) sum_c sym(l_c (x) (-f^i_c))``.

    ``area`` A (m^2 per m of thickness) defaults to the snapshot's region
    (its box, else the rectangle bounding the disks).
    """
    mask = np.ones(snapshot.n_contacts, bool) if used is None else np.asarray(used, dtype=bool)
    a = float(np.prod(np.diff(sample_bounds(snapshot), axis=1))) if area is None else float(area)
    if not a > 0:
        raise ValueError(f"area: must be > 0, got {area}")
    lever = branch_vectors(snapshot)[mask]
    force = -contact_forces_on_i(snapshot)[mask]
    total = lever.T @ force
    return np.asarray(0.5 * (total + total.T) / a, dtype=np.float64)


def grain_stress(snapshot: Snapshot, area: ArrayLike | None = None) -> NDArray[np.float64]:
    """(N, 2, 2) Love-Weber stress of every particle, Pa, compression positive:
    ``-(1/V_p) sum_{c of p} sym((x_c - x_p) (x) f^p_c)``.

    ``area`` (N,) the area V_p of each particle, m^2 per m of thickness
    (default its disk, pi r^2). Every contact of a particle counts (walls,
    membrane particles); a particle without contacts has zero stress.
    """
    x = np.asarray(snapshot.positions)
    n_p = snapshot.n_particles
    v = np.pi * np.asarray(snapshot.radii) ** 2 if area is None else np.asarray(area, float)
    if v.shape != (n_p,) or np.any(~(v > 0)):
        raise ValueError(f"area: expected ({n_p},) areas > 0")
    ci = np.asarray(snapshot.contact_i)
    cj = np.asarray(snapshot.contact_j)
    f_i = contact_forces_on_i(snapshot)
    arm_i = snapshot.minimum_image(contact_points(snapshot) - x[ci])
    pp = cj >= 0
    arm_j = arm_i[pp] - branch_vectors(snapshot)[pp]  # x_c - x_j
    owner = np.concatenate([ci, cj[pp]])
    arm = np.concatenate([arm_i, arm_j])
    force = np.concatenate([f_i, -f_i[pp]])
    out = np.zeros((n_p, 2, 2))
    for a in (0, 1):
        for b in (0, 1):
            out[:, a, b] = np.bincount(owner, weights=arm[:, a] * force[:, b], minlength=n_p)
    out = 0.5 * (out + np.swapaxes(out, 1, 2))
    return np.asarray(-out / v[:, None, None], dtype=np.float64)


class GrainStress(Compute):
    """The Love-Weber stress of each grain and its principal values, compression positive
    (Pa), spread over its disk by default: docs/fabric.md, "Stress: grains, regions and
    sets of contacts".

    Parameters
    ----------
    area : (N,) float, m^2, optional
        The area each grain's stress is spread over (default its disk).

    Example
    -------
    >>> from grainlab.snapshot import Snapshot
    >>> snap = Snapshot([[0, 0], [2, 0]], [1.0, 1.0], contact_i=[0], contact_j=[1],
    ...                 normal_force=[1.0])
    >>> round(float(GrainStress().compute(snap).major[0] * np.pi), 12)  # 1 N on a 1 m lever
    1.0
    """

    def __init__(self, area: ArrayLike | None = None) -> None:
        self.area = None if area is None else np.asarray(area, dtype=np.float64)

    def compute(self, snapshot: Snapshot) -> GrainStress:
        """Compute every grain's stress in ``snapshot``; returns ``self``."""
        stress = grain_stress(snapshot, self.area)
        major, minor, direction = principal_stresses(stress)
        self._store(
            _snapshot=snapshot, stress=stress, major=major, minor=minor, major_direction=direction
        )
        return self

    _snapshot = Computed[Snapshot]("The snapshot measured (drawn by plot).")
    stress = Computed[NDArray[np.float64]](
        "(N, 2, 2) stress of each grain, Pa, compression positive."
    )
    major = Computed[NDArray[np.float64]]("(N,) major principal stress sigma_1, Pa.")
    minor = Computed[NDArray[np.float64]]("(N,) minor principal stress sigma_2, Pa.")
    major_direction = Computed[NDArray[np.float64]](
        "(N,) direction of sigma_1, rad in [0, pi) from +x (0 where sigma_1 = sigma_2)."
    )

    def plot(self, ax: Any = None, **kwargs: Any) -> Any:
        """Particle map coloured by the major principal stress; returns the axes."""
        from grainlab import plot

        snap = self._snapshot
        values = np.where(snap.is_sample, self.major, np.nan)
        return plot.particle_map(
            snap.positions, snap.radii, values, ax=ax, cmap="magma_r",
            label=r"major principal stress $\sigma_1$ (Pa)", **kwargs,
        )

    def __repr__(self) -> str:
        return f"GrainStress(area={'disks' if self.area is None else 'given'})"


class LoveWeberStress(Compute):
    """The average (Love-Weber) stress of a region of a snapshot (:func:`love_weber_stress`),
    Pa, compression positive, every contact of the region's particles counted (those with
    walls and with particles outside it: its boundary forces); docs/fabric.md, "Stress:
    grains, regions and sets of contacts".

    Parameters
    ----------
    area : float, m^2, optional
        The region's area. Default: the snapshot's region (its box, else the
        rectangle bounding the disks) when the region is every particle, else
        the sum of the region's power cells
        (:class:`~grainlab.analysis.tessellation.LocalPorosity`).

    Example
    -------
    >>> from grainlab.snapshot import Snapshot
    >>> snap = Snapshot([[0, 0], [2, 0]], [1.0, 1.0], contact_i=[0], contact_j=[1],
    ...                 normal_force=[1.0], box=[[-1, 3], [-1, 1]])
    >>> float(LoveWeberStress().compute(snap).stress[0, 0])  # 2 m x 1 N over 8 m^2
    0.25
    """

    _parameters = ("area",)

    def __init__(self, area: float | None = None) -> None:
        if area is not None and not area > 0:
            raise ValueError(f"area: must be > 0, got {area}")
        self.area = area

    def compute(self, snapshot: Snapshot, region: ArrayLike | None = None) -> LoveWeberStress:
        """The stress of the particles where ``region`` ((N,) bool, default all) is
        true; returns ``self``."""
        n_p = snapshot.n_particles
        selected = np.ones(n_p, bool) if region is None else np.asarray(region, dtype=bool)
        if selected.shape != (n_p,):
            raise ValueError(f"region: expected shape ({n_p},), got {selected.shape}")
        area = self.area
        if area is None:
            if selected.all():
                area = float(np.prod(np.diff(sample_bounds(snapshot), axis=1)))
            else:
                from grainlab.analysis.tessellation import power_cell_areas

                area = float(power_cell_areas(snapshot)[selected].sum())
        # the particle sum, each particle's moment sum_c sym((x_c - x_p) (x) f^p_c)
        moments = grain_stress(snapshot, np.ones(n_p))
        stress = np.asarray(moments[selected].sum(axis=0) / area, dtype=np.float64)
        self._store(stress=stress, region_area=area, n_particles=int(selected.sum()))
        return self

    stress = Computed[NDArray[np.float64]]("(2, 2) stress of the region, Pa, compression positive.")

    region_area = Computed[float]("The region's area used, m^2.")
    n_particles = Computed[int]("Particles in the region.")

    @property
    def mean_stress(self) -> float:
        """p = (sigma_1 + sigma_2) / 2, Pa."""
        s = self.stress
        return float(0.5 * (s[0, 0] + s[1, 1]))

    @property
    def deviatoric_stress(self) -> float:
        """q = (sigma_1 - sigma_2) / 2, Pa."""
        s1, s2, _ = principal_stresses(self.stress)
        return float(0.5 * (s1 - s2))
