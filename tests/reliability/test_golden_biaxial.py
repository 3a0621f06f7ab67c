"""The golden biaxial run: a tiny run's records and snapshots, bit for bit, against a
digest taken from the code as it stood when the run was fixed. Any change to the
engine's arithmetic, the phases, their order, their save points or the records'
columns changes the digest; a change that keeps the physics bitwise keeps it.

Update :data:`GOLDEN_DIGEST` only for a change that is meant to change the bits,
and say so in CHANGELOG.md."""

from __future__ import annotations

import hashlib

import numpy as np
import pytest
from reliability_factories import tiny_config

import grainlab.protocols.biaxial as biaxial
from grainlab.io.hdf5 import read_results

#: blake2b-128 of the tiny run's time series and snapshots (see :func:`run_digest`).
GOLDEN_DIGEST = "bf41da1b0061ba32685619f8af59a9ab"


def run_digest(run_h5) -> str:
    """A digest of every time-series column and of each snapshot's positions,
    rotations, contact pairs and contact forces, names included."""
    results = read_results(run_h5)
    digest = hashlib.blake2b(digest_size=16)

    def feed(name: str, values) -> None:
        array = np.ascontiguousarray(values)
        digest.update(f"{name}:{array.dtype.str}:{array.shape}|".encode())
        digest.update(array.tobytes())

    for name, column in results.timeseries.items():
        feed(name, column)
    for name in results.snapshot_names:
        snap = results.snapshot(name)
        for field in ("positions", "rotations", "contact_i", "contact_j", "normal_force", "shear_force"):
            feed(f"{name}/{field}", getattr(snap, field))
    return digest.hexdigest()


@pytest.mark.parametrize("threads", [1, 2])
def test_the_tiny_biaxial_run_keeps_its_bits(tmp_path, fast_figures, threads):
    result = biaxial.run_biaxial(tiny_config(f"run.threads={threads}"), tmp_path / "run", progress=False)
    assert run_digest(tmp_path / "run" / "run.h5") == GOLDEN_DIGEST
    # the summary's peak is the records' largest stress ratio (the one rule, grainlab.analysis.peak)
    series = read_results(tmp_path / "run" / "run.h5").timeseries
    k = int(np.argmax(series["stress_ratio"]))
    assert result.summary["peak_stress_ratio"] == series["stress_ratio"][k]
    assert result.summary["axial_strain_at_peak"] == series["axial_strain"][k]
