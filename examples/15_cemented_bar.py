"""A direct tension test of a cemented bar: a row of touching disks, cemented with
parallel bonds of scattered strength, pulled apart at one end until it breaks.

Run: python examples/15_cemented_bar.py [columns]

The bar is `columns` x 3 disks (radius 1 mm) on a square lattice, every touching pair
cemented (grainlab.cement.pairs_within_gap) with sigma_c = c = 1 MPa, a seeded
normal scatter of 20 % (docs/cemented.md). The left column is held, the right one
pulled at 50 mm/s. The pulling force cannot exceed what the weakest cross-section's
three axial bonds carry together (sigma_c A each, their normal forces being all that
crosses it in tension); it peaks below that, as the section's bonds break one after
the other, and then the two halves part.
"""

from __future__ import annotations

import sys

import numpy as np

import grainlab
from grainlab.cement import draw_strengths, pairs_within_gap

R = 1e-3  # m
SIGMA_C = 1e6  # Pa, the bonds' mean tensile strength (and cohesion)
SPEED = 0.05  # m/s, the pulled end's speed (far below the bar's wave speed)


def main(columns: int = 12) -> None:
    col, row = np.meshgrid(np.arange(columns), np.arange(3), indexing="ij")
    positions = np.c_[col.ravel(), row.ravel()] * 2 * R
    sim = grainlab.Simulation(positions, np.full(len(positions), R), 2650.0)
    i, j = pairs_within_gap(positions, sim.radii, 1e-9)  # the lattice's touching pairs, round-off aside
    rng = np.random.default_rng(42)
    kn_bar = 8.45e7 / (2 * R)  # each bond's kn_bar A = 8.45e7 N/m (Table 1's kn)
    strength = draw_strengths(rng, SIGMA_C, 0.2 * SIGMA_C, len(i))
    sim.add_cement_bonds(i, j, normal_stiffness=kn_bar, shear_stiffness=kn_bar, tensile_strength=strength,
                         cohesion=draw_strengths(rng, SIGMA_C, 0.2 * SIGMA_C, len(i)))
    # the axial bonds cross the sections between columns c and c + 1: what each section can carry
    area = 2 * R  # A = 2 R_b per m of thickness, R_b = R
    axial = col.ravel()[j] != col.ravel()[i]
    section = np.zeros(columns - 1)
    np.add.at(section, np.minimum(col.ravel()[i], col.ravel()[j])[axial], strength[axial] * area)
    left, right = col.ravel() == 0, col.ravel() == columns - 1
    fixity = np.zeros(len(positions), np.uint8)
    fixity[left | right] = grainlab.FIX_X | grainlab.FIX_Y | grainlab.FIX_ROTATION
    sim.fixity = fixity
    velocities = np.zeros((len(positions), 2))
    velocities[right, 0] = SPEED
    sim.velocities = velocities
    sim.local_damping = 0.7
    print(f"{len(i)} bonds on {len(positions)} disks ({columns} x 3)")
    peak, broken, parted_at = 0.0, [], None
    for _ in range(400):
        sim.run(50)
        broken.append(sim.take_bond_breaks())
        pulling = -float(np.sum(sim.forces[right, 0]))  # the bonds' pull on the held end, N per m
        peak = max(peak, pulling)
        gap = positions[right, 0].mean() + SPEED * sim.time - 2 * R * (columns - 1)
        if parted_at is None and pulling <= 0.01 * peak and peak > 0:
            parted_at = gap
            break
    n = sum(len(b) for b in broken)
    tension = sum(int(np.sum(b.mode == "tension")) for b in broken)
    first = next(b for b in broken if len(b))
    axial = abs(first.normal[0, 0]) > 0.99
    weakest = int(np.argmin(section))
    print(f"peak pulling force {peak:.0f} N/m; the weakest section (between columns {weakest} and {weakest + 1}) "
          f"can carry {section[weakest]:.0f} N/m, the sum of its bonds' sigma_c A")
    print(f"{n} bonds broke, {tension} in tension; the first was {'axial' if axial else 'diagonal'}, in "
          f"{first.mode[0]}, at x = {1e3 * first.position[0, 0]:.2f} mm")
    print(f"the two halves parted after {1e6 * parted_at:.1f} um of stretch" if parted_at is not None
          else "the bar had not parted")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 12)
