"""The analysis products stored in run.h5 (grainlab.postprocess.products): stored once,
read back equal to the products made anew, made in worker processes as here, read
without a second search, made again under a new rule; files without them (layout
version 1, read-only folders) still read. And the figures drawn in workers are the
figures drawn here."""

from __future__ import annotations

import os
import re
import shutil
from dataclasses import asdict

import h5py
import numpy as np
import pytest
from test_figures import write_run

import grainlab.postprocess.products as products_module
from grainlab.analysis import ForceChains, LocalPorosity
from grainlab.analysis.shear_band import ShearBand
from grainlab.analysis.stability import StabilityIndex
from grainlab.io.hdf5 import ResultsFileError, read_results, write_analysis
from grainlab.plot.workers import FigurePool, worker_count
from grainlab.postprocess import band_labels, fabric_figures, find_band
from grainlab.postprocess.band import displacement_zone
from grainlab.postprocess.products import PRODUCTS, RunProducts, store_run_products


def svg_content(svg: bytes) -> bytes:
    """An SVG without its date and the random salt of matplotlib's element ids."""
    return re.sub(rb"(id=\"|#)[A-Za-z0-9_]*[0-9a-f]{8,}", rb"\1ID", re.sub(rb"<dc:date>[^<]*</dc:date>", b"", svg))


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    folder = tmp_path_factory.mktemp("band_run")
    write_run(folder / "run.h5")
    return folder


@pytest.fixture
def fresh_run(run_dir, tmp_path):
    """A copy of the run without stored products."""
    shutil.copyfile(run_dir / "run.h5", tmp_path / "run.h5")
    return tmp_path


@pytest.fixture
def counted(monkeypatch):
    """Counts the band fits made."""
    calls = []
    real = ShearBand.compute

    def compute(self, *args, **kwargs):
        calls.append(1)
        return real(self, *args, **kwargs)

    monkeypatch.setattr(ShearBand, "compute", compute)
    return calls


def assert_same_search(a, b):
    x, y = asdict(a.numbers), asdict(b.numbers)
    assert list(x) == list(y)
    for key in x:  # every number the same bits, of the same type (NaN equal to NaN)
        assert type(x[key]) is type(y[key]), key
        assert x[key] == y[key] or (x[key] != x[key] and y[key] != y[key]), key
    np.testing.assert_array_equal(a.displacement, b.displacement)
    for x, y in ((a.band, b.band), (a.second, b.second)):
        assert (x is None) == (y is None)
        assert x == y


def test_stored_products_are_the_products_made_anew(fresh_run, counted):
    stored = store_run_products(fresh_run)
    assert stored.analysis_versions == PRODUCTS
    assert stored.attrs["format_version"] == 3
    searched = len(counted)
    assert searched >= 20 * (len(stored.snapshot_names) - 1)  # every band and its permutation test
    products = RunProducts(fresh_run)
    assert products.missing() == {}
    ref = stored.snapshot("strain_0.0000")
    for name in stored.snapshot_names[1:]:
        cur = stored.snapshot(name)
        stability = StabilityIndex().compute(cur)
        made = find_band(ref, cur, stability, name=name, reference_name="strain_0.0000",
                         axial_strain=cur.axial_strain)
        assert_same_search(products.band_search(name), made)
        for reading in ("strain", "lambda", "displacement"):
            np.testing.assert_array_equal(products.band_labels(name, reading), band_labels(ref, cur, reading))
        zone, again = products.displacement_zone(name), displacement_zone(ref, cur)
        assert (zone.found, zone.reason, zone.residual_reduction, zone.zone) == (
            again.found, again.reason, again.residual_reduction, again.zone)
        np.testing.assert_array_equal(zone.members, again.members)
        np.testing.assert_array_equal(products.local_porosity(name), LocalPorosity().compute(cur).local_porosity)
        np.testing.assert_array_equal(products.force_chains(name), ForceChains().compute(cur).chain)
        field = products.stability_index(name)
        np.testing.assert_array_equal(field.stability_index, stability.stability_index)
        np.testing.assert_array_equal(field.n_contacts, stability.n_contacts)
    # the checks above made their own searches; the stored products were read without one
    counted.clear()
    products = RunProducts(fresh_run)
    for name in stored.snapshot_names[1:]:
        products.band_search(name)
        products.lambda_band(name)
    assert counted == []
    assert products.band_search("strain_0.0200").numbers.found  # the band of the test run


def test_a_file_that_holds_them_all_is_left_untouched(fresh_run):
    store_run_products(fresh_run)
    before = os.stat(fresh_run / "run.h5")
    store_run_products(fresh_run)
    after = os.stat(fresh_run / "run.h5")
    assert (before.st_ino, before.st_mtime_ns) == (after.st_ino, after.st_mtime_ns)


@pytest.mark.skipif(worker_count(2) < 2, reason="needs two cores for two worker processes")
def test_products_made_in_workers_are_the_products_made_here(run_dir, tmp_path):
    for where in ("here", "workers"):
        os.mkdir(tmp_path / where)
        shutil.copyfile(run_dir / "run.h5", tmp_path / where / "run.h5")
    store_run_products(tmp_path / "here")
    with FigurePool(tasks=4) as pool:
        assert pool.parallel
        store_run_products(tmp_path / "workers", pool)
    here, workers = RunProducts(tmp_path / "here"), RunProducts(tmp_path / "workers")
    for name in here.names_by_strain[1:]:
        assert_same_search(here.band_search(name), workers.band_search(name))
        assert_same_search(here.lambda_band(name), workers.lambda_band(name))


def test_a_file_without_products_is_read_and_its_products_made_anew(run_dir, tmp_path, counted):
    path = tmp_path / "run.h5"
    shutil.copyfile(run_dir / "run.h5", path)
    with h5py.File(path, "r+") as f:  # as grainlab wrote it before the analysis group
        f.attrs["format_version"] = np.int64(1)
    results = read_results(path)
    assert results.analysis_versions == {} and results.attrs["format_version"] == 1
    products = RunProducts(results)
    assert set(products.missing()) == set(results.snapshot_names)
    assert products.band_search("strain_0.0200").numbers.found
    assert len(counted) >= 20
    os.chmod(tmp_path, 0o555)  # a read-only folder: the products are made, not stored
    try:
        if not os.access(tmp_path, os.W_OK):  # (file modes do not stop root)
            with pytest.raises(OSError):
                store_run_products(path)
    finally:
        os.chmod(tmp_path, 0o755)
    assert read_results(path).attrs["format_version"] == 1  # untouched
    store_run_products(path)
    assert read_results(path).attrs["format_version"] == 3


def test_a_product_of_another_rule_version_is_made_again(fresh_run, counted, monkeypatch):
    store_run_products(fresh_run)
    results = read_results(fresh_run)
    ref, cur = results.snapshot("strain_0.0000"), results.snapshot("strain_0.0200")
    counted.clear()
    find_band(ref, cur, StabilityIndex().compute(cur))
    fits_per_search = len(counted)
    counted.clear()
    new_rule = PRODUCTS["band_strain"] + 1
    monkeypatch.setitem(products_module.PRODUCTS, "band_strain", new_rule)
    missing = RunProducts(fresh_run).missing()
    assert set(missing) == set(results.snapshot_names[1:])
    assert all(wanted == ["band_strain"] for wanted in missing.values())
    store_run_products(fresh_run)  # only the strain bands are searched again
    assert len(counted) == fits_per_search * len(missing)
    again = read_results(fresh_run)
    assert again.analysis_versions["band_strain"] == new_rule
    assert again.analysis_versions["band_lambda"] == 1
    assert RunProducts(again).missing() == {}


def test_products_are_stored_in_complete_runs_only(tmp_path):
    from grainlab.io.hdf5 import AnalysisItem, ResultsWriter

    path = tmp_path / "run.h5"
    writer = ResultsWriter(path, kind="biaxial")
    writer.append_rows({"axial_strain": np.zeros(2)})
    writer.finalize("failed")
    with pytest.raises(ResultsFileError, match="complete runs only"):
        write_analysis(path, {"band_strain": (1, {"a": AnalysisItem()})})
    with pytest.raises(ValueError, match="not a valid name"):
        write_analysis(path, {"band/strain": (1, {})})


@pytest.mark.skipif(worker_count(2) < 2, reason="needs two cores for two worker processes")
def test_fabric_figures_drawn_in_workers_are_the_figures_drawn_here(run_dir, tmp_path):
    here = fabric_figures(run_dir, tmp_path / "here", workers=0)
    workers = fabric_figures(run_dir, tmp_path / "workers", workers=2)
    assert list(workers) == list(here)
    assert workers.numbers.summary() == here.numbers.summary()
    for name, (png, svg) in here.items():
        assert workers[name][0].read_bytes() == png.read_bytes(), name
        assert svg_content(workers[name][1].read_bytes()) == svg_content(svg.read_bytes()), name
