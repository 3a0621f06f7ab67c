"""The reproduction's measures of a run of clumps are per body: lambda about each
body's centroid, a body's contact number counting every contact (CEGEO's Z_c),
the band found on the bodies' centroids; on a real quick run of trimers."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from grainlab.analysis import BodyStabilityIndex, CoordinationNumber, StabilityIndex, body_view
from grainlab.cli import main
from grainlab.io.hdf5 import read_results
from grainlab.postprocess.products import RunProducts
from grainlab.reproduction.measures import measure_biaxial


@pytest.fixture(scope="module")
def trimer_run(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("trimers") / "run"
    argv = ["biaxial", "--quick", "--strain-rate", "20%/min", "--out", str(out), "--no-progress", "--no-report",
            "--set", "sample.shape=trimer", "--set", "sample.shape_parameter=0.3",
            "--set", "shear.final_strain=0.01", "--set", "shear.snapshot_strains=[0, 0.005, 0.01]"]
    assert main(argv) == 0
    return out


def test_the_runs_products_per_body_are_its_bodies(trimer_run):
    results = read_results(trimer_run / "run.h5")
    products = RunProducts(results, per_body=True)
    assert products.per_body and not RunProducts(results).per_body
    last = results.snapshot_names[-1]
    view = body_view(results.snapshot(last))
    bodies = products.snapshot(last)
    assert bodies.n_particles == view.n_bodies < view.pebbles.n_particles
    field = products.stability_index(last)
    np.testing.assert_array_equal(field.stability_index, BodyStabilityIndex().compute(view).stability_index)
    assert products.band_labels(last).shape == (view.n_bodies,)
    # the pebbles' products, read as before, are per pebble
    assert RunProducts(results).band_labels(last).shape == (view.pebbles.n_particles,)


def test_the_claims_measures_read_each_trimer_as_one_grain(trimer_run):
    results = read_results(trimer_run / "run.h5")
    measured = measure_biaxial(trimer_run)
    for row in measured["snapshots"]:
        pebbles = results.snapshot(row["name"])
        view = body_view(pebbles)
        per_body = BodyStabilityIndex().compute(view)
        assert row["mean_lambda"] == pytest.approx(per_body.mean, rel=1e-12)
        assert row["coordination_number"] == pytest.approx(CoordinationNumber().compute(view.snapshot).coordination_number,
                                                           rel=1e-12)
        # what a reading per pebble would have given differs: the test can tell them apart
        assert row["mean_lambda"] != pytest.approx(StabilityIndex().compute(pebbles).mean, rel=1e-3)
        if row["band_members_known"]:
            grains = int(np.count_nonzero(np.asarray(view.snapshot.is_sample)))
            assert row["inside_n_grains"] + row["outside_n_grains"] == grains


def test_the_runs_fabric_numbers_and_figures_read_each_trimer_as_one_grain(trimer_run):
    """summary.json's states and bands (what report.html and the figures show) are per body."""
    from grainlab.postprocess.biaxial import analyse_run

    results = read_results(trimer_run / "run.h5")
    analysis = analyse_run(trimer_run)
    for role, state in analysis.states.items():
        view = body_view(results.snapshot(state.name))
        assert state.snap.n_particles == view.n_bodies, role
        expected = BodyStabilityIndex().compute(view)
        np.testing.assert_array_equal(state.stability.stability_index, expected.stability_index)
        numbers = analysis.numbers.states[role]
        assert numbers.mean_lambda == expected.mean
        assert numbers.mean_lambda != pytest.approx(StabilityIndex().compute(view.pebbles).mean, rel=1e-3)
        assert numbers.coordination_number == CoordinationNumber().compute(view.snapshot).coordination_number
    assert analysis.bands
    for band in analysis.bands.values():
        labels = RunProducts(results, per_body=True).band_labels(band.numbers.snapshot)
        assert labels.shape == (view.n_bodies,)
    # the maps draw the pebbles, each in its body's colour
    from grainlab.postprocess.figures import figure_tasks

    maps = next(t for t in figure_tasks(analysis) if t.name == "fig12_stability_index")
    for panel, role in zip(maps.args[0][:2], ("initial", "peak"), strict=True):
        state = analysis.states[role]
        assert len(panel.radii) == state.view.pebbles.n_particles > state.snap.n_particles
        np.testing.assert_array_equal(panel.values, state.stability.stability_index[state.view.body])
