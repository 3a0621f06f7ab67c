"""Results folders for the report tests (the fixtures are in conftest.py).

- :func:`write_synthetic_run`: a biaxial results folder written with ResultsWriter (no
  simulation, no figures): a lattice of grains inside membrane disks, a stress
  ratio peaking at 4 at 1 % axial strain (phi = asin(3/5)), a volumetric strain
  falling with slope -1/2 after the peak (psi = asin(1/5)) and snapshots with
  a band of simple shear inclined at 60 degrees.
- ``STUDY_OVERRIDES`` / ``STUDY_TARGETS``: the smallest useful packing study, a
  small box and 3 packings (about 3 s).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from grainlab.io.hdf5 import ResultsWriter, snapshot_name
from grainlab.protocols.biaxial.config import resolve
from grainlab.snapshot import Snapshot

D = 1.0e-3
PEAK_RATIO = 4.0
PEAK_STRAIN = 0.01
DILATION_SLOPE = -0.5
BAND_DEG = 60.0
SNAPSHOTS = (0.0, 0.01, 0.03)
PHASES = {"generate": 1.5, "consolidate": 2.5, "boundary": 0.5, "shear": 5.0}
THREADS = 2
SYNTHETIC_OVERRIDES = [
    "shear.final_strain=0.03",
    "shear.snapshot_strains=[0, 0.01, 0.03]",
    "sample.seed=7",
]

#: The small study: a box of about 250 grains, one irregular and two hexagonal packings.
STUDY_OVERRIDES = {"width": 0.02, "height": 0.04}
STUDY_TARGETS = {"irregular": (0.14,), "hexagonal": (0.08, 0.12)}


def _lattice(nx: int, ny: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    j, i = np.meshgrid(np.arange(ny), np.arange(nx), indexing="ij")
    grains = np.c_[((i + 0.5 * (j % 2)) * D).ravel(), (j * D * math.sqrt(3) / 2).ravel()]
    radii = 0.5 * D * rng.uniform(0.9, 1.0, len(grains))
    lo, hi = grains.min(axis=0) - 0.75 * D, grains.max(axis=0) + 0.75 * D
    ys = np.arange(lo[1], hi[1] + 1e-12, 0.5 * D)
    membrane = np.r_[np.c_[np.full_like(ys, lo[0]), ys], np.c_[np.full_like(ys, hi[0]), ys]]
    pos = np.vstack([grains, membrane])
    rad = np.r_[radii, np.full(len(membrane), 0.25 * D)]
    kind = np.r_[np.zeros(len(grains), np.int8), np.ones(len(membrane), np.int8)]
    return pos, rad, kind


def _deformed(pos: np.ndarray, strain: float) -> np.ndarray:
    """Axial shortening, lateral bulging and slip across a band 4 D thick at BAND_DEG."""
    centre = pos.mean(axis=0)
    p = pos - centre
    p = p * np.array([1.0 + 0.5 * strain, 1.0 - strain])
    beta = math.radians(BAND_DEG)
    t, n = np.array([math.cos(beta), math.sin(beta)]), np.array([-math.sin(beta), math.cos(beta)])
    width = 4.0 * D
    slip = 10.0 * strain * width
    s = p @ n
    p = p + np.outer(slip * np.clip(s / width, -0.5, 0.5), t)
    return p + centre


def timeseries() -> dict[str, np.ndarray]:
    eps = np.linspace(0.0, 0.03, 61)
    x = eps / PEAK_STRAIN
    q = 1.0 + (PEAK_RATIO - 1.0) * x * np.exp(1.0 - x)
    ev = np.where(eps < PEAK_STRAIN, 0.2 * eps, 0.2 * PEAK_STRAIN + DILATION_SLOPE * (eps - PEAK_STRAIN))
    shape = (q - 1.0) / (PEAK_RATIO - 1.0)
    return {
        "axial_strain": eps,
        "stress_ratio": q,
        "stress_ratio_mobilised": (q - 1.0) / (q + 1.0),
        "volumetric_strain": ev,
        "coordination_number": 4.0 - 0.6 * shape,
        "mechanical_coordination_number": 4.2 - 0.5 * shape,
        "anisotropy": 0.3 * shape,
        "force_anisotropy": 0.6 * shape,
        "mean_stability_index": 0.25 + 0.05 * shape,
    }


def write_synthetic_run(folder: Path, nx: int = 14, ny: int = 28) -> Path:
    """A finished biaxial results folder (run.h5 only) of a made-up test."""
    folder.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(11)
    pos0, rad, kind = _lattice(nx, ny, rng)
    config = resolve(overrides=SYNTHETIC_OVERRIDES, quick=True)
    ts = timeseries()
    n_grains = int((kind == 0).sum())
    with ResultsWriter(folder / "run.h5", kind="biaxial") as writer:
        writer.write_config(config.to_dict())
        writer.append_rows(ts)
        for e in SNAPSHOTS:
            snap = Snapshot.from_geometry(_deformed(pos0, e), rad, kind=kind, tolerance=0.12 * D, axial_strain=e)
            theta = snap.contact_angles()
            force = 5.0 * (1.0 + 20.0 * e * np.abs(np.sin(theta))) * rng.uniform(0.9, 1.1, theta.size)
            writer.write_snapshot(snapshot_name(e), snap.with_contacts(snap.contact_i, snap.contact_j,
                                                                     normal_force=force))
        writer.write_summary(
            {
                "n_particles": n_grains,
                "n_membrane_disks": int(len(kind) - n_grains),
                "porosity_generated": 0.12,
                "porosity_generated_overlap_corrected": 0.125,
                "porosity_after_consolidation": 0.15,
                "porosity_after_consolidation_overlap_corrected": 0.151,
                "porosity_initial": 0.145,
                "generation_stress_pa": 1.2e6,
                "coordination_number_initial": float(ts["coordination_number"][0]),
                "coordination_number_at_peak": float(ts["coordination_number"][20]),
                "peak_stress_ratio": PEAK_RATIO,
                "axial_strain_at_peak": PEAK_STRAIN,
                "strain_rate": 3.3e-3,
                "inertial_number": 1e-3,
                "inertial_number_mean_diameter": 2.6e-4,
                "density_scaling_factor": 3.7e-5,
                "time_step_s": 1.3e-4,
                "wall_time_s": sum(PHASES.values()) + 0.25,
                "wall_time_by_phase_s": PHASES,
                "threads": THREADS,
                "grainlab_version": "0.1.0",
            }
        )
        writer.write_phases(PHASES)
    return folder
