"""Short reprs and small HTML tables for notebooks: Results, Snapshot, measures."""

from __future__ import annotations

import numpy as np

from grainlab.analysis import ContactAnisotropy, StabilityIndex
from grainlab.io.hdf5 import ResultsWriter, read_results
from grainlab.snapshot import Snapshot


def _lattice(n: int = 20) -> Snapshot:
    a, b = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    pos = np.c_[a.ravel(), b.ravel()] * 1e-3
    return Snapshot.from_geometry(pos, np.full(n * n, 0.5e-3), tolerance=1e-9)


def test_results_show_counts_not_arrays(tmp_path):
    snap = _lattice()
    with ResultsWriter(tmp_path / "run.h5", kind="biaxial") as out:
        out.append_rows({"step": np.arange(5000), "axial_strain": np.linspace(0, 0.1, 5000)})
        out.write_snapshot("strain_0.0000", snap, step=0)
        out.write_summary({"peak_stress_ratio": 2.5, "note": "x" * 200})
    res = read_results(tmp_path / "run.h5")
    text = repr(res)
    assert text == (f"Results({str(tmp_path / 'run.h5')!r}, kind='biaxial', status='complete', "
                    "5000 rows x 2 columns, 1 snapshots)")
    page = res._repr_html_()
    assert len(page) < 3000
    assert "strain_0.0000" in page and "N = 400, Nc = 760" in page and "peak_stress_ratio" in page
    assert "xxxxxxxxxx..." in page  # long values cut


def test_snapshot_table():
    snap = _lattice()
    page = snap._repr_html_()
    assert "400 soil" in page and "<td style='text-align:left;padding:1px 10px 1px 0'>760</td>" in page
    assert "Snapshot(n_particles=400, n_contacts=760" in page


def test_measure_tables_before_and_after_compute():
    measure = StabilityIndex()
    assert "not computed" in measure._repr_html_()
    measure.compute(_lattice())
    page = measure._repr_html_()
    # a square lattice: interior grains have 4 contacts at 90 degrees (lambda 0), edges 3, corners 2
    assert "stability_index" in page and "array (400,) float64" in page
    assert "StabilityIndex(include_boundary=True" in page
    assert len(page) < 5000
    fabric = ContactAnisotropy().compute(_lattice())
    assert "anisotropy" in fabric._repr_html_()
