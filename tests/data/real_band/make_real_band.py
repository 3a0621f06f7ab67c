"""Extract ``real_band.npz`` (the grains of a default biaxial run at 0, 1.5 and 10 %).

Usage: ``python tests/data/real_band/make_real_band.py RUN_DIR`` where RUN_DIR
holds the ``run.h5`` of ``grainlab biaxial --out RUN_DIR`` (default config).
See README.md in this folder.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from grainlab.io.hdf5 import read_results
from grainlab.postprocess.band import interior_grains

SNAPSHOTS = {"initial": "strain_0.0000", "peak": "strain_0.0150", "final": "strain_0.1000"}


def main(run_dir: str) -> Path:
    results = read_results(run_dir)
    snaps = {role: results.snapshot(name) for role, name in SNAPSHOTS.items()}
    first = snaps["initial"]
    g0 = first.is_sample
    ids = first.ids[g0]
    out: dict[str, np.ndarray] = {"ids": ids.astype(np.int32), "radii": first.radii[g0]}
    for role, snap in snaps.items():
        k = snap.index_of(ids)
        if (k < 0).any() or not snap.is_sample[k].all():
            raise ValueError(f"{SNAPSHOTS[role]}: the grains differ from the first snapshot's")
        out[f"positions_{role}"] = snap.positions[k]
        out[f"axial_strain_{role}"] = np.float64(snap.axial_strain)
        if role != "initial":
            # same rule as the biaxial figures: grains within one mean diameter of the
            # membrane disks or the platen contact points are left out of the search
            d_mean = float(np.mean(2.0 * snap.radii[snap.is_sample]))
            interior = interior_grains(snap, d_mean)  # indexed like snap's grains
            order = np.flatnonzero(snap.is_sample)
            where = np.empty(snap.n_particles, np.int64)
            where[order] = np.arange(order.size)
            out[f"interior_{role}"] = interior[where[k]]
    path = Path(__file__).with_name("real_band.npz")
    np.savez_compressed(path, **out)
    return path


if __name__ == "__main__":
    print(main(sys.argv[1]))
