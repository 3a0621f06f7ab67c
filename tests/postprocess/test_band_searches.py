"""The band searches find_band keeps: the same snapshots searched again (read again from
run.h5) give the same band without a second search; other snapshots are searched; searches
made ahead in worker processes are the ones made here. And the figures drawn in workers are
the figures drawn here."""

from __future__ import annotations

import math
import re
from dataclasses import asdict

import numpy as np
import pytest
from test_figures import write_run

import grainlab.postprocess.band as band_module
from grainlab.analysis.shear_band import ShearBand
from grainlab.analysis.stability import StabilityIndex
from grainlab.io.hdf5 import read_results
from grainlab.plot.workers import FigurePool, worker_count
from grainlab.postprocess import band_labels, fabric_figures, find_band
from grainlab.postprocess.band import keep_searches, search_ahead


def svg_content(svg: bytes) -> bytes:
    """An SVG without its date and the random salt of matplotlib's element ids."""
    return re.sub(rb"(id=\"|#)[A-Za-z0-9_]*[0-9a-f]{8,}", rb"\1ID", re.sub(rb"<dc:date>[^<]*</dc:date>", b"", svg))


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    folder = tmp_path_factory.mktemp("band_run")
    write_run(folder / "run.h5")
    return folder


@pytest.fixture
def counted(monkeypatch):
    """Forgets the kept searches and counts the band fits made."""
    monkeypatch.setattr(band_module, "_searches", type(band_module._searches)())
    calls = []
    real = ShearBand.compute

    def compute(self, *args, **kwargs):
        calls.append(1)
        return real(self, *args, **kwargs)

    monkeypatch.setattr(ShearBand, "compute", compute)
    return calls


def test_the_same_snapshots_are_searched_once(run_dir, counted):
    first, again = read_results(run_dir), read_results(run_dir)  # two reads: equal data, other objects
    ref, cur = first.snapshot("strain_0.0000"), first.snapshot("strain_0.0200")
    found = find_band(ref, cur, StabilityIndex().compute(cur), name="strain_0.0200", reference_name="strain_0.0000",
                      axial_strain=0.02)
    fits = len(counted)
    assert fits >= 20 and found.numbers.found  # the band and its permutation test
    ref2, cur2 = again.snapshot("strain_0.0000"), again.snapshot("strain_0.0200")
    kept = find_band(ref2, cur2, StabilityIndex().compute(cur2))
    assert len(counted) == fits  # no second search
    # labelled anew, every number the same
    assert (kept.numbers.snapshot, kept.numbers.reference, math.isnan(kept.numbers.axial_strain)) == ("", "", True)
    same = {k: v for k, v in asdict(found.numbers).items() if k not in ("snapshot", "reference", "axial_strain")}
    assert same == {k: v for k, v in asdict(kept.numbers).items() if k not in ("snapshot", "reference", "axial_strain")}
    np.testing.assert_array_equal(kept.displacement, found.displacement)
    assert kept.displacement is not found.displacement
    # band_labels (the claims' search) of the same pair: kept too
    labels = band_labels(ref2, cur2)
    assert len(counted) == fits and labels.max() >= 1


def test_other_snapshots_are_searched_anew(run_dir, counted):
    results = read_results(run_dir)
    ref, cur = results.snapshot("strain_0.0000"), results.snapshot("strain_0.0200")
    band_labels(ref, cur)
    fits = len(counted)
    band_labels(ref, results.snapshot("strain_0.0100"))  # another state
    assert len(counted) >= 2 * fits
    band_labels(cur, cur)  # the same snapshots the other way round
    assert len(counted) >= 3 * fits


def test_searches_made_ahead_in_workers_are_the_searches_made_here(run_dir, counted):
    results = read_results(run_dir)
    pairs = [("strain_0.0000", name) for name in results.snapshot_names[1:]]
    here = {name: band_labels(results.snapshot(ref), results.snapshot(name)) for ref, name in pairs}
    band_module._searches.clear()
    with FigurePool(tasks=len(pairs)) as pool:
        started = search_ahead(results, pairs, pool)
        assert len(started) == len(pairs)
        keep_searches(started)
    fits = len(counted)
    again = read_results(run_dir)
    for ref, name in pairs:
        np.testing.assert_array_equal(band_labels(again.snapshot(ref), again.snapshot(name)), here[name])
    assert len(counted) == fits  # every search was found done
    with FigurePool(tasks=len(pairs)) as pool:
        assert search_ahead(again, pairs, pool) == []  # nothing left to search


@pytest.mark.skipif(worker_count(2) < 2, reason="needs two cores for two worker processes")
def test_fabric_figures_drawn_in_workers_are_the_figures_drawn_here(run_dir, tmp_path):
    here = fabric_figures(run_dir, tmp_path / "here", workers=0)
    workers = fabric_figures(run_dir, tmp_path / "workers", workers=2)
    assert list(workers) == list(here)
    assert workers.numbers.summary() == here.numbers.summary()
    for name, (png, svg) in here.items():
        assert workers[name][0].read_bytes() == png.read_bytes(), name
        assert svg_content(workers[name][1].read_bytes()) == svg_content(svg.read_bytes()), name
