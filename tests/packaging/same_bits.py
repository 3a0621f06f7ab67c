"""Prints the SHA-256 of a small run's whole state (``Simulation.to_bytes``): the same
bits whichever of the engine's paths ran it (tests/packaging/test_wheel.py runs it on
processors with and without AVX2). A dense periodic packing of 256 disks with friction
and no dashpots relaxes for 3,000 steps: on a processor with AVX2 its pairs run four at
a time and its free particles two at a time in AVX2 registers.

``--maps`` also prints the executable address ranges of the compiled engine
(``/proc/self/maps``), one ``MAP first-last`` line each: which of the instructions a
processor emulator ran were the engine's."""

import hashlib
import sys

import numpy as np

import grainlab

rng = np.random.default_rng(7)
n_side, spacing = 16, 1.0e-3
a, b = np.meshgrid(np.arange(n_side), np.arange(n_side), indexing="ij")
positions = np.column_stack([a.ravel() + 0.5, b.ravel() + 0.5]) * spacing
positions += rng.uniform(-0.03, 0.03, positions.shape) * spacing
radii = rng.uniform(0.48, 0.56, len(positions)) * spacing
sim = grainlab.Simulation(positions, radii, density=2.0e8, contact_model=grainlab.ContactModel(friction=0.5),
                          threads=1)
sim.set_periodic_cell((0.0, 0.0), (n_side * spacing, n_side * spacing))
sim.run(3000)
assert sim.neighbor_builds > 1 and sim.energy.friction_dissipated > 0.0  # rebuilds and sliding happened
print(hashlib.sha256(sim.to_bytes()).hexdigest(), sim.contact_count)
if "--maps" in sys.argv:
    with open("/proc/self/maps") as maps:
        for line in maps:
            fields = line.split()
            if fields[-1].endswith(".so") and "/grainlab/_core" in fields[-1] and "x" in fields[1]:
                print("MAP", fields[0])
