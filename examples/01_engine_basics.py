"""Engine basics: build a simulation from arrays, add walls, run, read the state.

Drops a few hundred disks (Table 1 properties) into a box under gravity, lets
them settle with local damping, and prints what the engine measures.
Run it: ``python examples/01_engine_basics.py [n_side]``.
"""

import sys

import numpy as np

import grainlab

n_side = int(sys.argv[1]) if len(sys.argv) > 1 else 15
rng = np.random.default_rng(0)

# disks on a loose grid: 2 mm spacing, diameters 0.8-1.6 mm
spacing = 2.0e-3
a, b = np.meshgrid(np.arange(n_side), np.arange(2 * n_side), indexing="ij")
positions = np.column_stack([a.ravel() + 0.5, b.ravel() + 0.5]) * spacing
positions[:, 0] += rng.uniform(-0.15, 0.15, len(positions)) * spacing  # break the columns
radii = rng.uniform(0.4e-3, 0.8e-3, len(positions))

sim = grainlab.Simulation(
    positions,
    radii,
    density=2650.0,  # a real sand density this time
    contact_model=grainlab.ContactModel(normal_stiffness=1e6, shear_stiffness=1e6, friction=0.5),
    local_damping=0.7,
    gravity=(0.0, -9.81),
)
width = n_side * spacing
# walls are oriented: the particles lie on the left of a -> b (counter-clockwise around them)
floor = sim.add_segment_wall((0.0, 0.0), (width, 0.0))
sim.add_segment_wall((0.0, 4 * width), (0.0, 0.0))  # left side wall
sim.add_segment_wall((width, 0.0), (width, 4 * width))  # right side wall
print(sim)

for _ in range(10):
    sim.run(8_000)
    print(
        f"t = {sim.time:6.3f} s  KE = {sim.energy.kinetic:.3e} J  "
        f"Z = {sim.coordination_number:.2f}  unbalanced = {sim.unbalanced_force_ratio:.2e}"
    )

weight = sim.masses.sum() * 9.81
carried = -sum(wall.force[1] for wall in sim.walls)  # walls push up on the grains
print(f"walls carry {carried:.4g} N of the {weight:.4g} N weight (per m thickness), the floor {-floor.force[1]:.4g} N")
contacts = sim.contacts()
print(f"{len(contacts)} contacts, {contacts.sliding.sum()} sliding, max overlap {contacts.overlap.max():.2e} m")
