"""The average stress tensor of a set of particles from their contact forces
(Love-Weber), a check on boundary stresses.

For particles ``p`` in a region of area ``A`` (unit thickness), with contact
forces ``f_c`` acting on ``p`` at contact points ``x_c``::

    sigma_ij = -(1 / A) * sum_p sum_{c of p} (x_c - x_p)_i (f_c)_j

symmetrised, **compression positive** (hence the minus sign). Every contact of a
selected particle counts, including those with walls and with particles outside
the selection (the boundary forces), so in static equilibrium the result equals
the boundary stress.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray


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
