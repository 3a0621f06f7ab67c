"""Cemented samples (docs/cemented.md, "Cemented samples"): the pairs the ``cement.*``
keys bond, the refusals before any work, a cemented biaxial test: stronger than the
same sample without cement, and resumed after a kill in the middle of cracking to the
same bits; and the crack records of a cemented oedometer and simple-shear test."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from resume_check import assert_same_run, kill_at_measure, stop_and_resume

import grainlab
import grainlab.protocols.biaxial as biaxial
import grainlab.protocols.biaxial.records as records
import grainlab.protocols.registry  # noqa: F401  (every test registers its configuration)
from grainlab.cement import pairs_within_gap
from grainlab.io.hdf5 import read_checkpoint, read_results
from grainlab.protocols.biaxial.config import resolve
from grainlab.protocols.config import SCHEMAS, ConfigError
from grainlab.protocols.registry import PROTOCOLS, resolve_config
from grainlab.protocols.runner import run_protocol
from grainlab.protocols.specimen import cement_sample
from grainlab.report import write_report

CEMENT = ["cement.bonds=parallel", "cement.tensile_strength=500 kPa", "cement.cohesion=500 kPa",
          "cement.strength_scatter=0.2"]


def test_pairs_within_a_gap_on_a_row_across_a_period_and_within_a_body():
    x, r = [[0.0, 0.0], [2.0, 0.0], [4.5, 0.0], [9.5, 0.0]], [1.0, 1.0, 1.0, 1.0]
    assert [a.tolist() for a in pairs_within_gap(x, r, 0.0)] == [[0], [1]]  # touching counts
    assert [a.tolist() for a in pairs_within_gap(x, r, 0.5)] == [[0, 1], [1, 2]]  # 0.5 apart
    assert [a.tolist() for a in pairs_within_gap(x, r, 0.49)] == [[0], [1]]
    # in a period of 10.5 the last disk overlaps the first through the boundary
    assert [a.tolist() for a in pairs_within_gap(x, r, 0.0, period=(10.5, 20.0))] == [[0, 0], [1, 3]]
    # two pebbles of one body are no pair
    assert [a.tolist() for a in pairs_within_gap(x, r, 0.5, body=[0, 0, 1, 2])] == [[1], [2]]
    with pytest.raises(ValueError, match="gap"):
        pairs_within_gap(x, r, -1.0)


@pytest.mark.parametrize(
    ("overrides", "message"),
    [
        (["cement.gap=1 mm"], "cement.gap: given, but cement.bonds is 'none'"),
        (["cement.bonds=parallel"], "cement.tensile_strength: cemented grains need a strength > 0"),
        (["cement.bonds=parallel", "cement.tensile_strength=1 MPa"], "cement.cohesion: cemented grains need"),
        ([*CEMENT, "cement.radius_multiplier=0"], "cement.radius_multiplier: 0 is out of range"),
        ([*CEMENT, "cement.tensile_strength=-1 MPa"], "cement.tensile_strength: -1e\\+06 is out of range"),
        ([*CEMENT, "material.contact_law=hertz_mindlin"], "cement.normal_stiffness: 'auto' follows the linear"),
        (["cement.bonds=glue"], "cement.bonds"),
    ],
)
def test_bad_cement_keys_are_refused_in_one_line(overrides, message):
    for test in ("biaxial", "oedometer", "cyclic", "simple_shear"):
        with pytest.raises(ConfigError, match=message):
            SCHEMAS[test].resolve(overrides=overrides, quick=True)


def test_the_bonds_are_made_stress_free_with_the_contact_stiffness_and_seeded_strengths():
    # a row of three disks touching, a fourth 0.1 mm away: gap 0 bonds two pairs
    x = np.array([[0.0, 0.0], [2e-3, 0.0], [4e-3, 0.0], [6.1e-3, 0.0]])
    sim = grainlab.Simulation(x, np.full(4, 1e-3), 2650.0)
    config = resolve(overrides=CEMENT, quick=True)
    run = SimpleNamespace(n_grains=4, consolidation={})
    cement_sample(sim, run, config)  # type: ignore[arg-type]
    bonds = sim.cement_bonds()
    assert run.consolidation["cement_bonds"] == sim.n_cement_bonds == 2
    assert (bonds.i.tolist(), bonds.j.tolist()) == ([0, 1], [1, 2])
    np.testing.assert_allclose(bonds.area, 2e-3)  # lambda_b = 1: A = 2 R per m
    np.testing.assert_array_equal(bonds.normal_force, 0.0)
    # pulling the last bonded disk by 1 um: kn_bar A = the contact law's kn
    sim.positions = x + [[0, 0], [0, 0], [1e-6, 0], [0, 0]]
    sim.time_step = 1e-7 * sim.critical_time_step()  # one step that hardly moves them
    sim.run(1)
    force = sim.cement_bonds().normal_force[1]
    assert force == pytest.approx(-config.material.normal_stiffness * 1e-6, rel=1e-6)
    # the strengths scatter about their means, and the same seed draws the same ones
    again = grainlab.Simulation(x, np.full(4, 1e-3), 2650.0)
    cement_sample(again, SimpleNamespace(n_grains=4, consolidation={}), config)  # type: ignore[arg-type]
    np.testing.assert_array_equal(again.cement_bonds().tensile_strength, bonds.tensile_strength)
    assert len(set(bonds.tensile_strength.tolist())) == 2


def test_a_cracks_orientation_is_across_its_bonds_normal():
    from grainlab.cement import crack_orientations

    normals = np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [np.sqrt(0.5), np.sqrt(0.5)]])
    angles = crack_orientations(normals[:, 0], normals[:, 1])
    np.testing.assert_allclose(angles, [0.5 * np.pi, 0.0, 0.5 * np.pi, 0.75 * np.pi], atol=1e-15)


@pytest.mark.slow
def test_a_cemented_biaxial_test_is_stronger_and_resumes_through_cracking_to_the_same_bits(tmp_path, monkeypatch):
    shear = ["shear.final_strain=0.015", "shear.strain_rate=20%/min", "run.checkpoint_interval=1e-9"]
    plain = biaxial.run_biaxial(resolve(overrides=shear, quick=True), tmp_path / "plain", progress=False)
    config = resolve(overrides=[*shear, *CEMENT], quick=True)
    straight = biaxial.run_biaxial(config, tmp_path / "straight", progress=False)
    assert straight.summary["cement_bonds"] > straight.summary["n_particles"]
    assert straight.summary["peak_stress_ratio"] > 1.5 * plain.summary["peak_stress_ratio"]
    # the records count the broken bonds: from none, never down, some by the end; the plain run has no such column
    broken = read_results(straight.out_dir / "run.h5").timeseries["cement_bonds_broken"]
    assert broken[0] == 0 and np.all(np.diff(broken) >= 0) and 0 < broken[-1] < straight.summary["cement_bonds"]
    assert "cement_bonds_broken" not in read_results(plain.out_dir / "run.h5").timeseries
    # every break is in the crack records, at its time's axial strain, inside the sample
    cracks = read_results(straight.out_dir / "run.h5").cracks
    assert len(cracks["step"]) == broken[-1] and not read_results(plain.out_dir / "run.h5").cracks
    assert np.all(np.diff(cracks["step"]) >= 0) and np.all(np.diff(cracks["axial_strain"]) >= 0)
    assert 0 <= cracks["axial_strain"].min() and cracks["axial_strain"].max() <= 0.015
    assert set(np.unique(cracks["tension"])) <= {0, 1} and np.all(cracks["energy_j"] > 0)
    assert (straight.out_dir / "fig20_cracks.png").exists() and not (plain.out_dir / "fig20_cracks.png").exists()
    first = read_results(straight.out_dir / "run.h5").snapshot(0).positions
    for axis, column in enumerate(("x_m", "y_m")):
        assert first[:, axis].min() < cracks[column].min() and cracks[column].max() < first[:, axis].max()

    killed = tmp_path / "killed"
    kill_at_measure(monkeypatch, records, 20, lambda: biaxial.run_biaxial(config, killed, progress=False))
    # killed in the middle of cracking: the last checkpoint holds broken bonds and intact ones
    stopped = grainlab.Simulation.from_bytes(read_checkpoint(killed / "checkpoint.h5").engine_state)
    assert 0 < stopped.n_cement_bonds < straight.summary["cement_bonds"]
    resumed = biaxial.run_biaxial(config, killed, resume=True, progress=False)
    a, b = read_results(straight.out_dir / "run.h5"), read_results(resumed.out_dir / "run.h5")
    for name in a.timeseries:
        np.testing.assert_array_equal(a.timeseries[name], b.timeseries[name], err_msg=name)
    np.testing.assert_array_equal(a.snapshot(-1).positions, b.snapshot(-1).positions)
    assert a.cracks.keys() == b.cracks.keys()
    for name in a.cracks:
        np.testing.assert_array_equal(a.cracks[name], b.cracks[name], err_msg=name)


@pytest.mark.parametrize(("test", "strain", "loading"), [
    ("oedometer", "axial_strain", ["oedometer.vertical_stresses=[200 kPa, 400 kPa, 800 kPa, 400 kPa]"]),
    ("simple_shear", "shear_strain", ["simple_shear.final_strain=0.3", "simple_shear.record_interval=0.02",
                                      "simple_shear.inertial_number=0.01"]),
])
def test_a_cemented_oedometer_or_simple_shear_test_records_its_cracks_and_resumes_to_the_same_bits(
        tmp_path, monkeypatch, test, strain, loading):
    # weak bonds (100 kPa): the loading breaks most of them
    weak = ["cement.bonds=parallel", "cement.tensile_strength=100 kPa", "cement.cohesion=100 kPa",
            "cement.strength_scatter=0.2", *loading, "run.threads=1", "run.checkpoint_interval=1e-9"]
    protocol = PROTOCOLS[test](resolve_config(test, overrides=weak, quick=True))
    straight = tmp_path / "straight"
    run_protocol(protocol, straight)
    results = read_results(straight / "run.h5")
    broken, cracks = results.timeseries["cement_bonds_broken"], results.cracks
    # every break since the consolidation is a crack row, at the test's own strain, in the order they broke
    assert broken[0] == 0 and np.all(np.diff(broken) >= 0) and 0 < broken[-1] <= results.summary["cement_bonds"]
    assert len(cracks["step"]) == broken[-1] and strain in cracks
    assert ("axial_strain" in cracks) == (strain == "axial_strain")
    np.testing.assert_array_equal(np.bincount(np.searchsorted(results.timeseries["step"], cracks["step"]),
                                              minlength=len(broken)).cumsum(), broken)
    series = results.timeseries[strain]
    assert series[0] <= cracks[strain].min() and cracks[strain].max() <= series.max()
    assert np.all(np.diff(cracks["step"]) >= 0) and set(np.unique(cracks["tension"])) <= {0, 1}
    # the crack map, and the report's crack section that shows it
    assert (straight / "fig20_cracks.png").exists()
    assert 'id="cracks"' in write_report(straight).read_text() and "figure-fig20_cracks" in (straight / "report.html").read_text()
    # stopped at its third checkpoint, with bonds broken: resumed to the same records, snapshots and cracks
    stop_and_resume(PROTOCOLS[test](resolve_config(test, overrides=weak, quick=True)), tmp_path / "resumed", 3,
                    monkeypatch)
    assert_same_run(straight, tmp_path / "resumed")
    again = read_results(tmp_path / "resumed" / "run.h5").cracks
    assert again.keys() == cracks.keys()
    for name in cracks:
        np.testing.assert_array_equal(again[name], cracks[name], err_msg=name)
