"""Analyse a snapshot: coordination numbers, anisotropy, stability index, shear band.

Builds a small dense packing (a jittered triangular lattice of slightly
overlapping disks), gives every contact the linear-law normal force
kn * overlap, deforms a copy with a band of simple shear, writes both as
particles CSV files, reads them back and prints the fabric measures, as
``grainlab analyze cur.csv --reference ref.csv`` would.

    python examples/02_analyze_snapshot.py
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np

from grainlab.analysis import ContactAnisotropy, StabilityIndex, analyze_snapshot
from grainlab.io import read_snapshot, write_particles_csv
from grainlab.postprocess import write_analysis
from grainlab.snapshot import Snapshot

KN = 8.45e7  # N/m, contact normal stiffness (paper Table 1)


def packing(nx: int = 30, ny: int = 40, d: float = 1.0e-3, seed: int = 1) -> Snapshot:
    rng = np.random.default_rng(seed)
    row, col = np.meshgrid(np.arange(ny), np.arange(nx), indexing="ij")
    pos = np.c_[((col + 0.5 * (row % 2)) * d).ravel(), (row * d * np.sqrt(3) / 2).ravel()]
    pos += rng.normal(0.0, 0.04 * d, pos.shape)
    radii = rng.uniform(0.48, 0.54, len(pos)) * d
    return Snapshot.from_geometry(pos, radii)


def with_forces(snap: Snapshot) -> Snapshot:
    d = snap.positions[snap.contact_j] - snap.positions[snap.contact_i]
    overlap = snap.radii[snap.contact_i] + snap.radii[snap.contact_j] - np.hypot(d[:, 0], d[:, 1])
    return Snapshot(
        snap.positions,
        snap.radii,
        ids=snap.ids,
        contact_i=snap.contact_i,
        contact_j=snap.contact_j,
        normal_force=KN * overlap,
        contact_fields={"overlap": overlap},
    )


def sheared(ref: Snapshot, angle_deg: float = 35.0, width: float = 6e-3, gamma: float = 0.05):
    beta = np.radians(angle_deg)
    t = np.array([np.cos(beta), np.sin(beta)])
    n = np.array([-np.sin(beta), np.cos(beta)])
    s = (ref.positions - ref.positions.mean(axis=0)) @ n
    u = gamma * np.clip(s, -width / 2, width / 2)[:, None] * t
    return Snapshot(ref.positions + u, ref.radii, ids=ref.ids)


def main() -> dict:
    reference = with_forces(packing())
    current = sheared(reference)

    # the freud-style classes, one measure at a time
    fabric = ContactAnisotropy(bins=18).compute(reference)
    forces = ContactAnisotropy(bins=18, weight="normal_force").compute(reference)
    lam = StabilityIndex().compute(reference)
    print(f"reference: {reference.n_particles} particles, {reference.n_contacts} contacts")
    print(f"  a   = {fabric.anisotropy:.4f} (exact), {fabric.anisotropy_binned:.4f} (Eq. 7, 18 bins)")
    print(f"  a_n = {forces.anisotropy:.4f} (exact), {forces.anisotropy_binned:.4f} (Eq. 7, 18 bins)")
    print(f"  mean lambda = {lam.mean:.3f}")

    # everything at once, from files, as `grainlab analyze` does
    with tempfile.TemporaryDirectory() as tmp:
        write_particles_csv(Path(tmp) / "ref.csv", reference)
        write_particles_csv(Path(tmp) / "cur.csv", current)
        ref = read_snapshot(Path(tmp) / "ref.csv")
        cur = read_snapshot(Path(tmp) / "cur.csv")
        result = analyze_snapshot(cur, ref)
        write_analysis(result, Path(tmp) / "out", figures=False)
        summary = result.summary()
    print("current (sheared copy, contacts detected from geometry):")
    for key in ("Z", "mechanical_Z", "a", "theta_a_deg", "a_fourier", "mean_lambda"):
        print(f"  {key:<24} {summary[key]:.4f}")
    print(
        f"  shear band: {summary['band_angle_deg']:.1f} deg, "
        f"{summary['band_thickness_diameters']:.1f} mean diameters thick, "
        f"mean lambda {summary['mean_lambda_in_band']:.3f} inside / "
        f"{summary['mean_lambda_outside_band']:.3f} outside"
    )
    return summary


if __name__ == "__main__":
    main()
