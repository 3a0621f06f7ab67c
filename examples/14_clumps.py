"""Rigid clumps: a pile of trimers settles in a box, and the outputs know its bodies.

Makes trimers of CEGEO's shape parameter eta (``grainlab.shapes``), drops them
into a box of three walls under gravity with local damping until they rest,
and prints what it measured: the walls carry the clumps' weight, no contact
joins two pebbles of one clump, the snapshot (and ParaView file) carries
every pebble's grain with its centroid and angle (docs/bodies.md), and the
coordination numbers and lambda per body beside those of the pebbles
(docs/fabric.md, "Measures per body").

Usage: ``python examples/14_clumps.py [n_clumps] [eta]`` (default 12 trimers,
eta 0.3); with ``--vtk DIR`` it writes the settled pile as ``DIR/pile.vtp`` (the
pebbles) and ``DIR/pile_clumps.vtp`` (one point per clump at its centroid, with its angle).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import grainlab
from grainlab.analysis import (
    BodyCoordination,
    BodyStabilityIndex,
    CoordinationNumber,
    StabilityIndex,
)
from grainlab.io.vtk import write_clumps_vtp, write_vtp
from grainlab.postprocess.vtk import snapshot_arrays
from grainlab.shapes import shape_template


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("n_clumps", nargs="?", type=int, default=12)
    parser.add_argument("eta", nargs="?", type=float, default=0.3)
    parser.add_argument("--vtk", type=Path, default=None, help="write the settled pile to DIR/pile.vtp, pile_clumps.vtp")
    args = parser.parse_args()

    radius = 1.5e-3  # circumscribed radius of each trimer (m)
    shape = shape_template("trimer", args.eta)
    sim = grainlab.Simulation(
        np.empty((0, 2)),
        np.empty(0),
        2650.0,
        contact_model=grainlab.ContactModel(1.0e6, 1.0e6, 0.5),
        time_step=1e-6,
        local_damping=0.7,
        gravity=(0.0, -9.81),
    )
    width = 4 * 2.2 * radius
    sim.add_line_wall((0.0, 0.0), (0.0, 1.0))
    sim.add_line_wall((0.0, 0.0), (1.0, 0.0))
    sim.add_line_wall((width, 0.0), (-1.0, 0.0))
    rng = np.random.default_rng(7)
    centres = [[(0.5 + k % 4) * 2.2 * radius, (0.5 + k // 4) * 2.2 * radius] for k in range(args.n_clumps)]
    sim.add_clumps(radius * shape.offsets, radius * shape.radii, positions=centres,
                   angles=rng.uniform(0.0, 2.0 * np.pi, args.n_clumps), density=2650.0)
    sim.time_step = sim.critical_time_step(0.5)
    steps = 0
    while steps < 400_000:
        sim.run(10_000)
        steps += 10_000
        if steps > 20_000 and np.abs(sim.clumps.velocity_m_per_s).max() < 1e-7:
            break

    weight = 9.81 * float(sim.clumps.mass_kg.sum())
    carried = -sum(sim.wall(k).force[1] for k in range(3))
    body = sim.body_of_particles
    contacts = sim.contacts()
    inner = int(np.sum(body[contacts.i] == body[contacts.j]))
    snap = sim.snapshot()
    print(f"{args.n_clumps} trimers (eta {args.eta:g}, {sim.n_particles} pebbles) at rest after {steps} steps")
    print(f"walls carry {carried:.6g} N of the {weight:.6g} N weight")
    print(f"{len(contacts)} contacts between clumps, {inner} inside one")
    print(f"the snapshot has {snap.n_grains} grains; grain of pebbles 0-5: {snap.grains()[:6].tolist()}")
    z = BodyCoordination(include_boundary=True).compute(snap)  # the walls hold the pile
    lam = BodyStabilityIndex().compute(snap)
    print(f"per body, walls counted: Z = {z.coordination_number:.3f} (touching pairs), "
          f"Z_c = {z.contact_coordination_number:.3f} (contacts), rattlers: {int(z.rattlers.sum())}, "
          f"mean lambda = {lam.mean:.3f}; read as pebbles: "
          f"Z = {CoordinationNumber(include_boundary=True).compute(snap).coordination_number:.3f}, "
          f"mean lambda = {StabilityIndex().compute(snap).mean:.3f}")
    if args.vtk is not None:
        args.vtk.mkdir(parents=True, exist_ok=True)
        path = write_vtp(args.vtk / "pile.vtp", np.c_[snap.positions, np.zeros(snap.n_particles)],
                         point_data=snapshot_arrays(snap))
        clumps = write_clumps_vtp(args.vtk / "pile_clumps.vtp", snap)
        print(f"wrote {path} (point data 'grain', 'grain_centroid', 'grain_angle') and {clumps} (one point per clump)")


if __name__ == "__main__":
    main()
