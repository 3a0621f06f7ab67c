"""Lambda against the force network, chains, local porosity and loops (postprocess/lambda_fabric.py)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from test_figures import write_run

from grainlab.analysis import (
    ContactLoops,
    ForceChains,
    ForceNetworks,
    LocalPorosity,
    StabilityIndex,
)
from grainlab.io.hdf5 import read_results
from grainlab.postprocess.lambda_fabric import (
    lambda_against_fabric,
    lambda_fabric_figure,
    main,
    run_lambda_fabric,
)
from grainlab.snapshot import Snapshot


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    folder = tmp_path_factory.mktemp("lambda_run")
    write_run(folder / "run.h5", nx=16, ny=30)
    return folder


def test_the_groups_are_the_measures_own(run_dir):
    snap = read_results(run_dir).snapshot("strain_0.0100")
    result = lambda_against_fabric(snap)
    lam = StabilityIndex().compute(snap)
    grains = snap.is_sample & (lam.n_contacts >= 2)
    values = lam.stability_index
    strong = ForceNetworks().compute(snap).in_strong_network
    chained = ForceChains().compute(snap).chain >= 0
    assert result.n_grains == grains.sum()
    assert result.mean_lambda == pytest.approx(values[grains].mean())
    assert result.strong.count + result.weak.count == result.n_grains
    assert result.strong.mean == pytest.approx(values[grains & strong].mean())
    assert result.in_chains.mean == pytest.approx(values[grains & chained].mean())
    assert result.in_chains.count == (grains & chained).sum()
    porosity = LocalPorosity().compute(snap).local_porosity
    assert sum(g.count for g in result.porosity) == (grains & np.isfinite(porosity)).sum()
    # quintiles: equally populated to within one grain
    counts = [g.count for g in result.porosity]
    assert max(counts) - min(counts) <= 1
    lowest = grains & (porosity <= result.porosity_edges[1])
    assert result.porosity[0].mean == pytest.approx(values[lowest].mean())
    loops = ContactLoops().compute(snap).grain_loop_size
    assert sum(g.count for g in result.loops) == result.n_grains
    assert result.loops[-1].count == (grains & ~np.isfinite(loops)).sum()
    assert -1.0 <= result.spearman_porosity <= 1.0


def test_the_peak_snapshot_the_figure_and_the_command(run_dir, tmp_path, capsys):
    result = run_lambda_fabric(run_dir)
    assert result.snapshot == "strain_0.0100"  # the synthetic run peaks at 1 %
    assert result.axial_strain == pytest.approx(0.01)
    written = lambda_fabric_figure(result, tmp_path / "lambda")
    assert [p.suffix for p in written] == [".png", ".svg"] and all(p.stat().st_size for p in written)
    assert main([str(run_dir), str(tmp_path / "again")]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert printed["n_grains"] == result.n_grains and printed["snapshot"] == "strain_0.0100"
    assert main([str(run_dir)]) == 2


def test_a_snapshot_without_forces_is_refused():
    snap = Snapshot.from_geometry(np.random.default_rng(0).uniform(0, 1, (30, 2)), np.full(30, 0.1))
    with pytest.raises(ValueError, match="normal_force"):
        lambda_against_fabric(snap)
