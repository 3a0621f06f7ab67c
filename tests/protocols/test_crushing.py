"""The crushing test of single agglomerates: its records (one agglomerate after the
other, the platen at a constant speed, sigma = F / (d t) on the recorded force), the
failure rule and the modes, the crack records of each agglomerate, the Weibull fit of
the strengths, a run resumed between two agglomerates to the same bits, the command line
and its report, and bad input refused in one line."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from resume_check import assert_same_run, stop_and_resume

import grainlab.protocols.runner as runner
from grainlab.analysis.weibull import weibull_fit
from grainlab.cli import main
from grainlab.columns import CRUSHING
from grainlab.io.hdf5 import read_results
from grainlab.protocols.crushing import CrushingProtocol
from grainlab.protocols.registry import PROTOCOLS, resolve_config
from grainlab.report import detect_kind

# four small agglomerates (about 25 disks each): a few seconds
SMALL = ["crushing.agglomerates=4", "crushing.d_min=1.2 mm", "crushing.d_max=1.4 mm", "run.threads=1"]


@pytest.fixture(scope="module")
def config():
    return resolve_config("crushing", overrides=SMALL)


@pytest.fixture(scope="module")
def straight(tmp_path_factory, config):
    out = tmp_path_factory.mktemp("crushing") / "run"
    runner.run_protocol(CrushingProtocol(config), out)
    return out


def _rows(ts, k):
    return np.flatnonzero(ts["agglomerate"] == k)


def test_each_agglomerate_is_recorded_from_its_start_at_a_constant_platen_speed(straight, config):
    results = read_results(straight / "run.h5")
    ts, s = results.timeseries, results.summary
    assert list(ts) == [str(c) for c in CRUSHING] and dict(results.timeseries_units) == CRUSHING.units()
    assert np.all(np.diff(ts["agglomerate"]) >= 0) and set(ts["agglomerate"]) == set(range(4))
    rate = config.crushing.strain_rate
    for k in range(4):
        rows = _rows(ts, k)
        d = ts["diameter_m"][rows]
        assert ts["step"][rows[0]] == 0 and ts["platen_displacement_m"][rows[0]] == 0.0
        assert np.all(d == d[0]) and 1.2e-3 <= d[0] <= 1.4e-3 and s["agglomerates"][k]["diameter_m"] == d[0]
        np.testing.assert_allclose(ts["axial_strain"][rows], rate * ts["time_s"][rows], rtol=1e-6, atol=1e-12)
        np.testing.assert_allclose(ts["platen_displacement_m"][rows], d * ts["axial_strain"][rows], rtol=1e-12)
    # sigma = F / (d t), t = 1 m, on every record, and sigma_f on the largest recorded force
    np.testing.assert_allclose(ts["characteristic_stress_pa"], ts["platen_force_n"] / ts["diameter_m"], rtol=1e-12)
    for k, a in enumerate(s["agglomerates"]):
        rows = _rows(ts, k)
        assert a["peak_force_n"] == ts["platen_force_n"][rows].max()
        assert a["strength_pa"] == pytest.approx(ts["platen_force_n"][rows].max() / (a["diameter_m"] * 1.0),
                                                 rel=1e-12)
    assert results.snapshot_names == [f"agglomerate_{k:03d}_{w}" for k in range(4) for w in ("start", "end")]


def test_an_agglomerate_fails_at_the_first_record_where_it_has_split_and_its_force_has_dropped(straight, config):
    results = read_results(straight / "run.h5")
    ts, s = results.timeseries, results.summary
    assert s["n_failed"] >= 3
    for k, a in enumerate(s["agglomerates"]):
        rows = _rows(ts, k)
        force, major = ts["platen_force_n"][rows], ts["major_fragments"][rows]
        failed = (major >= 2) & (force < config.crushing.residual_fraction * np.maximum.accumulate(force))
        if a["ended_by"] == "failure":
            assert failed[-1] and not failed[:-1].any()
            assert a["mode"] == ("split" if a["major_fragments"] == 2 else "fragmented")
        else:
            assert a["mode"] == "unfailed" and ts["axial_strain"][rows[-1]] == pytest.approx(0.2, rel=1e-3)
        assert a["fragments"] == ts["fragments"][rows[-1]] and a["major_fragments"] == major[-1]
        end = results.snapshot(f"agglomerate_{k:03d}_end")
        assert len(set(end.particle_fields["fragment"].tolist())) == a["fragments"] and end.n_particles == a["disks"]
        assert set(results.snapshot(f"agglomerate_{k:03d}_start").particle_fields["fragment"].tolist()) == {0}
    assert sum(s["modes"].values()) == 4


def test_each_broken_bond_is_a_crack_of_its_agglomerate(straight, config):
    results = read_results(straight / "run.h5")
    ts, cracks = results.timeseries, results.cracks
    for k in range(4):
        mine = cracks["agglomerate"] == k
        assert np.count_nonzero(mine) == ts["cement_bonds_broken"][_rows(ts, k)[-1]] > 0
        np.testing.assert_allclose(cracks["axial_strain"][mine], config.crushing.strain_rate * cracks["time_s"][mine])
    assert np.all(np.diff(cracks["agglomerate"]) >= 0)


def test_the_weibull_fit_is_that_of_the_failed_agglomerates_strengths(straight):
    s = json.loads((straight / "summary.json").read_text())
    failed = [a["strength_pa"] for a in s["agglomerates"] if a["ended_by"] == "failure"]
    fit = weibull_fit(failed)
    assert s["weibull"]["modulus"] == fit.modulus and s["weibull"]["scale"] == fit.scale
    assert s["weibull"]["n"] == s["n_failed"] == len(failed)
    assert (straight / "fig01_force_displacement.png").exists() and (straight / "fig02_weibull.png").exists()


def test_unbreakable_bonds_leave_every_agglomerate_whole_and_no_fit(tmp_path):
    config = resolve_config("crushing", overrides=[*SMALL[:-1], "crushing.agglomerates=3", "cement.tensile_strength=1 GPa",
                                                   "cement.cohesion=1 GPa", "crushing.final_strain=0.02"])
    result = runner.run_protocol(CrushingProtocol(config), tmp_path / "run")
    s = result.summary
    assert s["n_failed"] == 0 and s["weibull"] is None and s["modes"]["unfailed"] == 3
    assert all(a["fragments"] == 1 and a["largest_fragment_fraction"] == 1.0 for a in s["agglomerates"])
    assert "no Weibull fit" in result.one_line()


@pytest.mark.parametrize("after", [1, 3])
def test_a_run_stopped_between_two_agglomerates_resumes_to_the_same_bits(straight, tmp_path, monkeypatch, after):
    config = resolve_config("crushing", overrides=[*SMALL, "run.checkpoint_interval=1e-6"])
    # a checkpoint at the start, then after each agglomerate but the last
    stop_and_resume(CrushingProtocol(config), tmp_path / "run", 1 + after, monkeypatch)
    assert_same_run(straight, tmp_path / "run")
    a, b = read_results(straight / "run.h5"), read_results(tmp_path / "run" / "run.h5")
    for name in a.cracks:
        np.testing.assert_array_equal(a.cracks[name], b.cracks[name], err_msg=name)
    assert a.summary["agglomerates"] == b.summary["agglomerates"] and a.summary["weibull"] == b.summary["weibull"]


def test_the_command_line_runs_it_with_its_report_as_cemented_md_prints(tmp_path, capsys):
    out = tmp_path / "crushing"
    assert main(["run", "crushing", "--quick", "--out", str(out), "--no-progress"]) == 0
    printed = capsys.readouterr().out.splitlines()[0]
    quoted = " ".join((Path(__file__).resolve().parents[2] / "docs" / "cemented.md").read_text().split())
    assert "; ".join(printed.split("; ")[:-1]) in quoted, printed  # all but the wall time and folder
    summary = json.loads((out / "summary.json").read_text())
    assert printed.startswith(f"grainlab crushing: {summary['n_agglomerates']} agglomerates")
    assert summary["n_agglomerates"] == 10
    assert detect_kind(out) == (out, "crushing")
    page = (out / "report.html").read_text()
    assert "Weibull modulus m" in page and "figure-fig02_weibull" in page and "figure-fig01_force_displacement" in page
    header = (out / "timeseries.csv").read_text().splitlines()[0].split(",")
    assert [name.split(" ")[0] for name in header] == [str(c) for c in CRUSHING]


@pytest.mark.parametrize(("override", "message"), [
    (["crushing.d_min=3 mm"], "crushing.d_min: 0.003 m exceeds crushing.d_max 0.002 m"),
    (["agglomerate.disk_diameter=1 mm"], "agglomerate.disk_diameter: an agglomerate is at least 3 disks across"),
    (["crushing.agglomerates=2"], "crushing.agglomerates"),
    (["cement.tensile_strength=0"], "cement.tensile_strength: cemented grains need a strength > 0"),
    (["agglomerate.vacancies=0.7"], "agglomerate.vacancies: 0.7 is out of range"),
    (["cement.gap=1 mm"], "unknown configuration key 'cement.gap'"),
])
def test_bad_input_gets_one_line_and_no_folder(tmp_path, capsys, override, message):
    out = tmp_path / "never"
    assert main(["run", "crushing", "--out", str(out), *(arg for key in override for arg in ("--set", key))]) != 0
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_the_registry_knows_it():
    assert "crushing" in PROTOCOLS
