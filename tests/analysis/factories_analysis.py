"""Seeded factories for the analysis tests: lattices, rings of contacts, packings."""

from __future__ import annotations

import numpy as np

from grainlab.snapshot import Snapshot

D = 1.0e-3  # particle diameter used by the lattices, m


def hex_lattice(nx: int = 8, ny: int = 8, d: float = D, rotation_deg: float = 0.0) -> Snapshot:
    """Periodic triangular lattice of touching disks (ny even), optionally rotated.

    Rotation keeps the box periodic only for 0; rotated lattices use explicit
    contacts found before the rotation.
    """
    assert ny % 2 == 0
    j, i = np.meshgrid(np.arange(ny), np.arange(nx), indexing="ij")
    x = (i + 0.5 * (j % 2)) * d
    y = j * d * np.sqrt(3.0) / 2.0
    pos = np.c_[x.ravel(), y.ravel()]
    box = np.array([[0.0, nx * d], [0.0, ny * d * np.sqrt(3.0) / 2.0]])
    snap = Snapshot.from_geometry(
        pos, np.full(len(pos), d / 2), box=box, periodic=(True, True), tolerance=1e-6 * d
    )
    return rotated(snap, rotation_deg)


def square_lattice(nx: int = 8, ny: int = 8, d: float = D, rotation_deg: float = 0.0) -> Snapshot:
    """Periodic square lattice of touching disks, optionally rotated (as hex_lattice)."""
    j, i = np.meshgrid(np.arange(ny), np.arange(nx), indexing="ij")
    pos = np.c_[i.ravel() * d, j.ravel() * d]
    box = np.array([[0.0, nx * d], [0.0, ny * d]])
    snap = Snapshot.from_geometry(
        pos, np.full(len(pos), d / 2), box=box, periodic=(True, True), tolerance=1e-6 * d
    )
    return rotated(snap, rotation_deg)


def rotated(snap: Snapshot, rotation_deg: float) -> Snapshot:
    """The snapshot turned by ``rotation_deg`` about the origin, with its contacts
    (explicit normals, no box: a rotated periodic cell is not a box)."""
    if not rotation_deg:
        return snap
    c, s = np.cos(np.radians(rotation_deg)), np.sin(np.radians(rotation_deg))
    rot = np.array([[c, -s], [s, c]])
    return Snapshot(
        snap.positions @ rot.T,
        snap.radii,
        contact_i=snap.contact_i,
        contact_j=snap.contact_j,
        contact_normal=snap.contact_normals() @ rot.T,
    )


def ring(angles_deg, r: float = 0.5e-3, other: float = 0.5e-3) -> Snapshot:
    """Particle 0 at the origin touched by one disk at each angle (contacts 0-k)."""
    a = np.radians(np.asarray(angles_deg, dtype=float))
    dist = r + other
    pos = np.vstack([[0.0, 0.0], dist * np.c_[np.cos(a), np.sin(a)]])
    rad = np.r_[r, np.full(a.size, other)]
    k = np.arange(1, a.size + 1)
    return Snapshot(pos, rad, contact_i=np.zeros(a.size, np.int64), contact_j=k)


def jittered_packing(nx: int, ny: int, seed: int, d: float = D) -> Snapshot:
    """A disordered dense packing: jittered triangular lattice (spacing d), radii 0.48-0.54 d.

    Neighbours overlap slightly, giving Z of about 4 as in the paper's sample.
    """
    rng = np.random.default_rng(seed)
    j, i = np.meshgrid(np.arange(ny), np.arange(nx), indexing="ij")
    x = (i + 0.5 * (j % 2)) * d
    y = j * d * np.sqrt(3.0) / 2.0
    pos = np.c_[x.ravel(), y.ravel()] + rng.normal(0.0, 0.04 * d, (nx * ny, 2))
    rad = rng.uniform(0.48, 0.54, nx * ny) * d
    return Snapshot.from_geometry(pos, rad)


def grain_on_membrane(
    n_disks: int = 7,
    forces=None,
    *,
    grain_radius: float = 1.5e-3,
    disk_radius: float = 0.25e-3,
    labelled: bool = True,
) -> Snapshot:
    """A grain (index 0) pressed into a membrane chain that wraps its left side.

    ``n_disks`` membrane disks (indices 2 ..) touch the grain at angles 180 deg
    + k * delta, k centred on 0, neighbours overlapping by half their diameter
    (as the biaxial membrane's disks do); a second grain (index 1) touches it
    at 0 deg. ``forces`` (n_disks,) are the normal forces of the membrane
    contacts (the grain-grain contact carries 1 N). With ``labelled`` the
    chain carries the body label 0.
    """
    dist = grain_radius + disk_radius
    delta = disk_radius / dist  # arc spacing of one disk radius: half-diameter overlap
    k = np.arange(n_disks) - 0.5 * (n_disks - 1)
    a = np.pi + k * delta
    disks = dist * np.c_[np.cos(a), np.sin(a)]
    pos = np.vstack([[0.0, 0.0], [2 * grain_radius, 0.0], disks])
    rad = np.r_[grain_radius, grain_radius, np.full(n_disks, disk_radius)]
    kind = np.r_[0, 0, np.full(n_disks, 1)]
    f = np.ones(n_disks) if forces is None else np.asarray(forces, dtype=float)
    fields = {"body": np.r_[-1, -1, np.zeros(n_disks, np.int64)]} if labelled else {}
    return Snapshot(
        pos,
        rad,
        kind=kind,
        contact_i=np.r_[0, np.zeros(n_disks, np.int64)],
        contact_j=np.r_[1, 2 + np.arange(n_disks)],
        normal_force=np.r_[1.0, f],
        particle_fields=fields,
    )
