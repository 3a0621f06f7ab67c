"""The oedometer of crushable grains (sample.grains = agglomerate): each grain of the
radius expansion an agglomerate of bonded disks, loaded to high stress; the fragments at
each load step conserve the solid area and stay within their agglomerates, their count
grows as the stress does, unbreakable bonds leave one fragment per agglomerate, the yield
stress follows its rule, the outputs and the refusals."""

from __future__ import annotations

import numpy as np
import pytest
from resume_check import assert_same_run, stop_and_resume

import grainlab.protocols.runner as runner
from grainlab.analysis.fragments import fragment_sizes
from grainlab.cli import main
from grainlab.io.hdf5 import read_results
from grainlab.protocols.oedometer import OedometerProtocol
from grainlab.protocols.oedometer.outputs import yield_stress
from grainlab.protocols.registry import resolve_config

# about 130 agglomerates of 10 disks in a 12 mm box, loaded to 2 MPa: about 15 s
SAMPLE = ["sample.width=12 mm", "sample.height=12 mm", "sample.d_min=1 mm", "sample.d_max=1.2 mm",
          "sample.grading=uniform_by_number", "run.threads=1", "sample.grains=agglomerate",
          "agglomerate.disk_diameter=0.25 mm", "cement.bonds=parallel", "cement.cohesion=1 MPa",
          "cement.strength_scatter=0.2"]
CRUSHABLE = [*SAMPLE, "cement.tensile_strength=1 MPa", "oedometer.vertical_stresses=[250 kPa, 500 kPa, 1 MPa, 2 MPa]"]


@pytest.fixture(scope="module")
def crushed(tmp_path_factory):
    out = tmp_path_factory.mktemp("agglomerates") / "run"
    runner.run_protocol(OedometerProtocol(resolve_config("oedometer", overrides=CRUSHABLE)), out)
    return out


def _fragments_of(snapshot):
    return np.asarray(snapshot.particle_fields["fragment"]), np.asarray(snapshot.particle_fields["agglomerate"])


def test_each_load_step_s_fragments_conserve_the_solid_area_and_stay_in_their_agglomerate(crushed):
    results = read_results(crushed / "run.h5")
    s = results.summary
    grading = s["fragment_grading"]
    names = [n for n in results.snapshot_names if n.startswith("load_")]
    assert len(grading) == len(names) == 5 and s["agglomerates"] > 100
    for g, name in zip(grading, names, strict=True):
        snap = results.snapshot(name)
        fragment, agglomerate = _fragments_of(snap)
        assert len(agglomerate) == s["n_particles"] and agglomerate.max() == s["agglomerates"] - 1
        area, _ = fragment_sizes(snap.radii, fragment)
        solid = np.pi * np.sum(snap.radii**2)
        assert area.sum() == pytest.approx(solid, rel=1e-12) and g["solid_area_m2"] == pytest.approx(solid, rel=1e-12)
        assert g["fragments"] == len(area) >= s["agglomerates"]
        # a fragment never spans two agglomerates
        pairs = np.unique(np.column_stack([fragment, agglomerate]), axis=0)
        assert len(pairs) == len(area)
        # (all of the solid passes the largest sieve, to the rounding of the areas' sum)
        assert g["percent_passing"][-1] == pytest.approx(100.0, abs=1e-9)
        assert np.all(np.diff(g["percent_passing"]) >= 0)
    counts = [g["fragments"] for g in grading]
    assert counts == sorted(counts) and counts[-1] > 2 * counts[0]  # the grains crush as the stress rises
    assert grading[-1]["d50_m"] < grading[0]["d50_m"]


def test_the_yield_stress_is_the_two_tangents_crossing_and_the_files_are_written(crushed):
    results = read_results(crushed / "run.h5")
    ts, s = results.timeseries, results.summary
    x, e = np.log(ts["vertical_stress_pa"]), ts["void_ratio"]
    # the first two records' line against the steepest later pair's
    k = 1 + min(range(len(x) - 2), key=lambda m: (e[m + 2] - e[m + 1]) / (x[m + 2] - x[m + 1]))
    a, b = np.polyfit(x[:2], e[:2], 1), np.polyfit(x[k:k + 2], e[k:k + 2], 1)
    assert s["yield_stress_pa"] == pytest.approx(np.exp((b[1] - a[1]) / (a[0] - b[0])), rel=1e-9)
    assert ts["vertical_stress_pa"][0] < s["yield_stress_pa"] < ts["vertical_stress_pa"][-1]
    rows = (crushed / "fragments.csv").read_text().splitlines()
    assert rows[0] == "load_step,vertical_stress_pa,fragments,d50_m,sieve_m,percent_passing" and len(rows) == 1 + 5 * 25
    assert (crushed / "fig03_fragment_grading.png").exists()
    assert "agglomerates of" in OedometerProtocol.result_type(crushed, s).one_line()


def test_the_yield_rule_on_a_bilinear_curve():
    sigma = np.array([100e3, 200e3, 400e3, 800e3, 1600e3])
    e = np.where(sigma < 300e3, 0.5 - 0.01 * np.log(sigma / 100e3), 0.5 - 0.01 * np.log(3.0) - 0.2 * np.log(sigma / 300e3))
    assert yield_stress({"vertical_stress_pa": sigma, "void_ratio": e}) == pytest.approx(300e3, rel=1e-9)
    assert yield_stress({"vertical_stress_pa": sigma[:3], "void_ratio": e[:3]}) is None


def test_the_yield_rule_finds_the_knee_of_a_curve_that_flattens_again():
    # stiff to 400 kPa, crushing to 1.6 MPa, then flatter again (the grains ground to single
    # disks): the first rule (the line through the last two records) met the first line
    # below the knee; the steepest stretch finds it
    sigma = 100e3 * 2.0 ** np.arange(7)
    x = np.log(sigma / 100e3)
    knee, ground = np.log(4.0), np.log(16.0)
    e = 0.5 - 0.01 * np.minimum(x, knee) - 0.3 * np.clip(x - knee, 0.0, ground - knee) - 0.02 * np.maximum(x - ground, 0.0)
    assert yield_stress({"vertical_stress_pa": sigma, "void_ratio": e}) == pytest.approx(400e3, rel=1e-9)
    # a curve that only flattens has no yield
    assert yield_stress({"vertical_stress_pa": sigma, "void_ratio": 0.5 - 0.1 * x + 0.005 * x**2}) is None


def test_unbreakable_bonds_leave_one_fragment_per_agglomerate(tmp_path):
    config = resolve_config("oedometer", overrides=[*SAMPLE, "cement.tensile_strength=1 GPa", "cement.cohesion=1 GPa",
                                                    "oedometer.vertical_stresses=[400 kPa]"])
    result = runner.run_protocol(OedometerProtocol(config), tmp_path / "run")
    assert [g["fragments"] for g in result.summary["fragment_grading"]] == [result.summary["agglomerates"]] * 2
    last = read_results(tmp_path / "run" / "run.h5").snapshot(-1)
    fragment, agglomerate = _fragments_of(last)
    np.testing.assert_array_equal(fragment, agglomerate)
    assert result.summary["yield_stress_pa"] is None  # fewer than four first-loading records


def test_a_run_of_agglomerates_resumes_to_the_same_bits(crushed, tmp_path, monkeypatch):
    config = resolve_config("oedometer", overrides=[*CRUSHABLE, "run.checkpoint_interval=1e-6"])
    # the start, the consolidation, the confinement, then each load step: stopped after the second load step
    stop_and_resume(OedometerProtocol(config), tmp_path / "run", 5, monkeypatch)
    assert_same_run(crushed, tmp_path / "run")
    assert read_results(tmp_path / "run" / "run.h5").summary["fragment_grading"] == \
        read_results(crushed / "run.h5").summary["fragment_grading"]


@pytest.mark.parametrize(("override", "message"), [
    (["agglomerate.vacancies=0.1"], "agglomerate.vacancies: given, but sample.grains is 'disk'"),
    (["sample.grains=agglomerate"], "sample.grains: agglomerates are bonded disks; give cement.bonds=parallel"),
    ([*SAMPLE, "cement.tensile_strength=1 MPa", "agglomerate.disk_diameter=0.5 mm"],
     "agglomerate.disk_diameter: an agglomerate is at least 3 disks across"),
])
def test_bad_input_gets_one_line_and_no_folder(tmp_path, capsys, override, message):
    out = tmp_path / "never"
    assert main(["run", "oedometer", "--out", str(out), *(arg for key in override for arg in ("--set", key))]) != 0
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_the_free_radii_take_the_overlaps_off_so_no_two_circles_overlap():
    from grainlab.protocols.agglomerates import free_radii

    rng = np.random.default_rng(3)
    positions, radii = rng.uniform(1.0, 9.0, (20, 2)), rng.uniform(0.5, 1.0, 20)
    free = free_radii(positions, radii, (0.0, 0.0, 10.0, 10.0))
    centres = np.hypot(*(positions[:, None] - positions[None]).transpose(2, 0, 1))
    gaps = centres - free[:, None] - free[None]
    np.fill_diagonal(gaps, np.inf)
    assert gaps.min() >= -1e-12 and np.all(free <= radii)
    assert np.all(free <= np.minimum(positions, 10.0 - positions).min(axis=1) + 1e-12)
    before = centres - radii[:, None] - radii[None]
    np.fill_diagonal(before, np.inf)
    untouched = before.min(axis=1) > 0
    assert untouched.any() and (~untouched).any()
    np.testing.assert_array_equal(free[untouched], radii[untouched])  # a disk that overlapped nothing keeps its radius


def test_every_break_after_the_consolidation_is_a_crack_record(crushed):
    results = read_results(crushed / "run.h5")
    broken, cracks = results.timeseries["cement_bonds_broken"], results.cracks
    # counted from the agglomerates' bonds as made (some break in the consolidation), never down
    assert results.summary["cement_bonds"] == results.summary["agglomerate_bonds"]
    assert broken[0] < broken[-1] and np.all(np.diff(broken) >= 0)
    assert len(cracks["step"]) == broken[-1] <= results.summary["cement_bonds"]
    np.testing.assert_array_equal(np.bincount(np.searchsorted(results.timeseries["step"], cracks["step"]),
                                              minlength=len(broken)).cumsum(), broken)
    assert (crushed / "fig20_cracks.png").exists()
