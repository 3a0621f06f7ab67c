"""The unconfined compression test (UCS) of a cemented sample: its physics (the
stress rises from the release to a peak q_u, E the slope of the records below it,
the sample widening with nu between 0 and 1, the bonds breaking into the crack
records), its resume to the same bits, its command line and report, and its
refusal of an uncemented sample or a bad key."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from resume_check import assert_same_run, stop_and_resume

import grainlab.protocols.runner as runner
from grainlab.cli import main
from grainlab.columns import UCS
from grainlab.io.hdf5 import read_results
from grainlab.protocols.config import ConfigError
from grainlab.protocols.registry import PROTOCOLS, resolve_config
from grainlab.protocols.ucs import UcsProtocol
from grainlab.report import detect_kind

CEMENT = ["cement.bonds=parallel", "cement.tensile_strength=500 kPa", "cement.cohesion=500 kPa"]
# the default strain rate (1 %/min), to 1 % strain in 100 records: about 10 s on the quick sample
QUICK = [*CEMENT, "ucs.final_strain=0.01", "ucs.records=100", "run.threads=1"]


@pytest.fixture(scope="module")
def config():
    return resolve_config("ucs", overrides=QUICK, quick=True)


@pytest.fixture(scope="module")
def straight(tmp_path_factory, config):
    out = tmp_path_factory.mktemp("ucs") / "run"
    runner.run_protocol(UcsProtocol(config), out)
    return out


def test_the_records_are_the_schemas_columns_one_every_record_strain(straight, config):
    results = read_results(straight / "run.h5")
    ts = results.timeseries
    assert list(ts) == [str(c) for c in UCS] and dict(results.timeseries_units) == UCS.units()
    assert results.snapshot_names == ["start", "end"]
    # the start (after the release), then one record every final_strain / records of strain
    strain = ts["axial_strain"]
    assert strain[0] == 0.0 and len(strain) > 10
    np.testing.assert_allclose(np.diff(strain), 0.01 / 100, rtol=1e-3)
    # the top platen at the strain rate: the strain is the rate times the time since the start
    np.testing.assert_allclose(strain, config.ucs.strain_rate * (ts["time_s"] - ts["time_s"][0]), rtol=1e-3,
                               atol=1e-9)


def test_the_stress_rises_to_a_peak_and_the_run_stops_at_the_residual_drop_or_the_final_strain(straight):
    results = read_results(straight / "run.h5")
    s, ts = results.summary, results.timeseries
    stress, strain = ts["axial_stress_pa"], ts["axial_strain"]
    peak = int(np.argmax(stress))
    assert s["unconfined_strength_pa"] == stress.max() and s["axial_strain_at_peak"] == strain[peak]
    assert 0 < peak < len(stress) - 1 and stress.max() > 2 * stress[0] > 0
    after = stress[peak + 1:]
    if s["ended_by"] == "residual":  # the first record below half the peak ends it
        assert after[-1] < 0.5 * stress.max() and np.all(after[:-1] >= 0.5 * stress.max())
    else:
        assert s["ended_by"] == "final_strain" and strain[-1] == pytest.approx(0.01, rel=1e-3)
        assert np.all(after >= 0.5 * stress.max())


def test_e_is_the_initial_slope_and_nu_is_between_zero_and_one(straight):
    results = read_results(straight / "run.h5")
    s, ts = results.summary, results.timeseries
    stress, strain = ts["axial_stress_pa"], ts["axial_strain"]
    # the secant between the first record above 10 % of q_u and the last one below 50 % before the peak
    first, last = s["elastic_fit_strains"]
    a, b = int(np.searchsorted(strain, first)), int(np.searchsorted(strain, last))
    secant = (stress[b] - stress[a]) / (strain[b] - strain[a])
    assert 0.1 * stress.max() <= stress[a] and stress[b] <= 0.5 * stress.max() and b > a
    assert s["youngs_modulus_pa"] > 0 and 0.8 < s["youngs_modulus_pa"] / secant < 1.25
    assert s["elastic_fit_records"] >= 5
    assert 0 < s["poisson_ratio"] < 1
    # the sample widens: the lateral strain grows as the axial strain does
    assert ts["lateral_strain"][0] == 0.0 and ts["lateral_strain"][-1] > 0
    assert ts["width_m"][-1] > ts["width_m"][0] and s["width0_m"] == ts["width_m"][0]


def test_the_compression_starts_from_the_seating_stress(straight, config):
    results = read_results(straight / "run.h5")
    s, stress = results.summary, results.timeseries["axial_stress_pa"]
    # the platen servo-controlled to ucs.seating_stress (1 kPa) held it within a tenth in equilibrium
    assert config.ucs.seating_stress == 1e3 and s["seating_steps"] > 0
    assert abs(stress[0] - 1e3) <= 100 and stress.max() > 100 * stress[0]


def test_each_broken_bond_is_a_crack_record(straight):
    results = read_results(straight / "run.h5")
    s, ts, cracks = results.summary, results.timeseries, results.cracks
    broken = ts["cement_bonds_broken"]
    assert s["cement_bonds"] > 0 and np.all(np.diff(broken) >= 0)
    assert len(cracks["step"]) == broken[-1] == s["cracks_final"] > s["cracks_at_peak"] > 0
    assert s["cracks_at_peak"] == broken[int(np.argmax(ts["axial_stress_pa"]))]
    assert np.all(cracks["step"] <= ts["step"][-1]) and np.all(np.diff(cracks["step"]) >= 0)
    # each crack's step is before the record that counted it
    counted = np.searchsorted(ts["step"], cracks["step"])
    np.testing.assert_array_equal(np.bincount(counted, minlength=len(broken)).cumsum(), broken)
    assert (straight / "fig01_stress_strain.png").exists() and (straight / "fig20_cracks.png").exists()


@pytest.mark.parametrize("at", ["ninth record", "last record"])
def test_a_stopped_run_resumes_to_the_same_bits(straight, tmp_path, monkeypatch, at):
    config = resolve_config("ucs", overrides=[*QUICK, "run.checkpoint_interval=1e-6"], quick=True)
    # a checkpoint at the start, after the consolidation, the release and the seating, then at each record but the first
    records = len(read_results(straight / "run.h5").timeseries["step"])
    stop_and_resume(UcsProtocol(config), tmp_path / "run", 13 if at == "ninth record" else records + 3, monkeypatch)
    assert_same_run(straight, tmp_path / "run")
    a, b = read_results(straight / "run.h5"), read_results(tmp_path / "run" / "run.h5")
    for name in a.cracks:
        np.testing.assert_array_equal(a.cracks[name], b.cracks[name], err_msg=name)


def test_the_command_line_runs_it_with_its_report_as_cemented_md_prints(tmp_path, capsys):
    out = tmp_path / "ucs"
    assert main(["run", "ucs", "--quick", "--out", str(out), "--no-progress",
                 *(arg for key in [*CEMENT, "ucs.final_strain=0.01"] for arg in ("--set", key))]) == 0
    printed = capsys.readouterr().out.splitlines()[0]
    quoted = " ".join((Path(__file__).resolve().parents[2] / "docs" / "cemented.md").read_text().split())
    assert "; ".join(printed.split("; ")[:-1]) in quoted, printed  # all but the wall time and folder
    summary = json.loads((out / "summary.json").read_text())
    assert printed.startswith(f"grainlab ucs: {summary['n_particles']} grains, {summary['cement_bonds']} cement")
    assert f"q_u {summary['unconfined_strength_pa'] / 1e3:.0f} kPa" in printed
    assert detect_kind(out) == (out, "ucs")
    page = (out / "report.html").read_text()
    assert "unconfined strength q_u" in page and "Poisson" in page and "data:image/png;base64," in page
    assert "figure-fig20_cracks" in page and "figure-fig01_stress_strain" in page
    header = (out / "timeseries.csv").read_text().splitlines()[0].split(",")
    assert [name.split(" ")[0] for name in header] == [str(c) for c in UCS]


@pytest.mark.parametrize(("override", "message"), [
    ([], "ucs: an uncemented sample has no unconfined strength; give cement.bonds=parallel and its strengths"),
    ([*CEMENT, "ucs.residual_fraction=1.5"], "ucs.residual_fraction: 1.5 is out of range"),
    ([*CEMENT, "ucs.records=0"], "ucs.records"),
    (["cement.bonds=parallel"], "cement.tensile_strength: cemented grains need a strength > 0"),
])
def test_bad_input_gets_one_line_and_no_folder(tmp_path, capsys, override, message):
    out = tmp_path / "never"
    assert main(["run", "ucs", "--quick", "--out", str(out), *(arg for key in override for arg in ("--set", key))]) != 0
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_the_registry_knows_it_and_refuses_an_uncemented_sample_before_any_work():
    assert "ucs" in PROTOCOLS
    with pytest.raises(ConfigError, match="^ucs: an uncemented sample"):
        resolve_config("ucs", quick=True)
