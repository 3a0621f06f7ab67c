"""The periodic cell as a test's boundary: the cell's stress, from the contacts
(a clump's branch vectors from its centroid) and the grains' motion about the
imposed flow, and its stress control, proportional and integral in the stress
gap at the affine stiffness estimate, the periodic counterpart of the
servo-controlled walls (docs/boundary.md, "A stress-controlled cell")."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from grainlab.simulation import Contacts, Simulation

__all__ = ["CONTROL_STEPS", "INTEGRAL_SHARE", "RELAXATION", "CellStress", "cell_stress", "servo_rate",
           "side_stresses"]

#: Steps between two settings of the cell's rate.
CONTROL_STEPS = 100
#: Fraction of the stress gap the proportional part closes per control interval at the estimated stiffness.
RELAXATION = 0.5
#: The integral part's gain over the proportional part's, per interval.
INTEGRAL_SHARE = 0.5


@dataclass(frozen=True)
class CellStress:
    """The cell's stress (Pa, compression positive, symmetric 2 x 2): the
    contacts' part and the kinetic part; the affine stiffness of each side
    (Pa per unit strain) and the cell's area (m^2)."""

    contact: NDArray[np.float64]
    kinetic: NDArray[np.float64]
    stiffness_pa: tuple[float, float]
    area_m2: float

    @property
    def total(self) -> NDArray[np.float64]:
        return np.asarray(self.contact + self.kinetic, dtype=np.float64)


def _stiffness_sum(normal_stiffness: NDArray[np.float64], a: NDArray[np.float64], b: NDArray[np.float64]) -> float:
    """``sum_c k_c a_c b_c`` over the contacts; a stiffness the same for every
    contact (the linear law's ``kn``) is factored out of the sum."""
    if normal_stiffness.size and bool(np.all(normal_stiffness == normal_stiffness[0])):
        return float(normal_stiffness[0]) * float(a @ b)
    return float((normal_stiffness * a) @ b)


@dataclass(frozen=True)
class _CellContacts:
    """What the cell's stress reads: its area, the contacts, each contact's branch
    vector from ``i``'s grain to ``j``'s (``(r_i + r_j - delta) n`` between disks,
    from centroid to centroid for clumps, ``length`` its disks' part) and each
    grain's mass and velocity (the clumps', not their pebbles')."""

    area: float
    contacts: Contacts
    length: NDArray[np.float64]
    branch: NDArray[np.float64]
    clumps: bool
    masses: NDArray[np.float64]
    velocities: NDArray[np.float64]


def _cell_contacts(sim: Simulation, caller: str) -> _CellContacts:
    cell = sim.cell
    if cell is None:
        raise ValueError(f"{caller}: the simulation has no periodic cell")
    c = sim.contacts()
    radii = sim.radii
    length = radii[c.i] + radii[c.j] - c.overlap
    branch = length[:, None] * c.normal
    if not len(sim.clumps):
        return _CellContacts(float(cell.area), c, length, branch, False, sim.masses, sim.velocities)
    clumps = sim.clumps
    body = sim.body_of_particles
    pebble = body < len(clumps)
    # each pebble's arm from its clump's centroid, at its nearest image in the cell
    arm = np.zeros((sim.n_particles, 2))
    arm[pebble] = sim.positions[pebble] - clumps.centroid_m[body[pebble]]
    lattice = np.array([cell.a, cell.b]).T
    fractions = np.linalg.solve(lattice, arm.T)
    arm = np.asarray((lattice @ (fractions - np.round(fractions))).T, dtype=np.float64)
    branch = branch + arm[c.i] - arm[c.j]
    masses = np.concatenate([sim.masses[~pebble], clumps.mass_kg])
    velocities = np.concatenate([sim.velocities[~pebble], clumps.velocity_m_per_s])
    return _CellContacts(float(cell.area), c, length, branch, True, masses, velocities)


def cell_stress(sim: Simulation) -> CellStress:
    """The stress of the periodic cell of ``sim`` (:class:`CellStress`); with clumps,
    branch vectors between their centroids and their own kinetic part."""
    g = _cell_contacts(sim, "cell_stress")
    c, area = g.contacts, g.area
    on_j = -c.force_on_i
    contact = g.branch.T @ on_j / area
    contact = 0.5 * (contact + contact.T)
    v = g.velocities
    kinetic = (g.masses[:, None] * v).T @ v / area
    n4 = c.normal**4
    if g.clumps:
        stiffness = np.array([float((c.normal_stiffness * g.branch[:, k] ** 2) @ (c.normal[:, k] ** 2))
                              for k in (0, 1)]) / area
    else:
        stiffness = c.normal_stiffness * (g.length**2) @ n4 / area
    return CellStress(contact, kinetic, (float(stiffness[0]), float(stiffness[1])), area)


def side_stresses(sim: Simulation, sides: Sequence[int]) -> list[tuple[float, float]]:
    """``(sigma_kk, E_kk)`` of each side ``k`` of ``sides`` (0: x, 1: y) alone, as
    :func:`cell_stress` gives them (to rounding) at a fraction of its cost, from one
    read of the contacts: what the control reads every 100 steps."""
    g = _cell_contacts(sim, "side_stresses")
    c, area = g.contacts, g.area
    out = []
    for side in sides:
        n_k = c.normal[:, side]
        # the force on j along k: normal_force n_k - shear_force (on i) t_k, t = (-n_y, n_x)
        tangent_k = -c.normal[:, 1] if side == 0 else c.normal[:, 0]
        on_j = c.normal_force * n_k - c.shear_force * tangent_k
        lever = g.branch[:, side] if g.clumps else g.length * n_k
        v = g.velocities[:, side]
        stress = (float(lever @ on_j) + float(g.masses @ (v * v))) / area
        stiffness = _stiffness_sum(c.normal_stiffness, lever * lever, n_k * n_k) / area
        out.append((stress, stiffness))
    return out


def servo_rate(stress_pa: float, target_pa: float, stiffness_pa: float, interval_s: float, max_rate: float,
               integral: float) -> tuple[float, float]:
    """``(L_kk, J)``: the rate (1/s; positive stretches the cell) of the cell's
    control for the gap ``stress - target`` at ``stiffness_pa`` over
    ``interval_s``, and the integral part ``J`` updated from ``integral``, both
    within ``+- max_rate``. A cell without stiffness yet (no contacts) keeps
    ``J`` and shrinks at ``max_rate`` when below its target, else stays."""
    if stiffness_pa <= 0.0:
        return (0.0 if stress_pa >= target_pa else -max_rate), integral
    gain = RELAXATION / (stiffness_pa * interval_s)
    gap = stress_pa - target_pa
    integral = float(np.clip(integral + INTEGRAL_SHARE * gain * gap, -max_rate, max_rate))
    return float(np.clip(gain * gap + integral, -max_rate, max_rate)), integral
