"""Strain rates too fast for meaningful records are refused (before any work when
no time step of the sample could do, before the first record with the run's own
time step), and a run that fails is marked ``failed`` with its error in
run.h5.partial (docs/file-formats.md, root attributes)."""

from __future__ import annotations

import math

import pytest
from reliability_factories import TINY_TOML, tiny_config

import grainlab
import grainlab.protocols.biaxial as biaxial
import grainlab.protocols.biaxial.records as records
from grainlab.cli import main
from grainlab.io.hdf5 import read_results
from grainlab.protocols.biaxial.config import resolve


@pytest.mark.parametrize("rate", ["1000", "10"])
def test_a_hopeless_strain_rate_is_refused_before_any_work(tmp_path, capsys, rate):
    out = tmp_path / "never"
    assert main(["biaxial", "--strain-rate", rate, "--out", str(out), "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "shear.strain_rate" in err and "too fast" in err and "record interval" in err
    assert not out.exists()


def test_the_refusal_follows_the_record_interval_and_the_platen_travel():
    # one step of dt shears by rate * dt: 10 steps per 0.0005 record interval allow 0.5 1/s at dt = 1e-4 s
    # (a 10 mm sample, whose platens move slowly enough)
    assert biaxial.strain_rate_problem(0.49, 1e-4, 0.01, 0.25e-3, 0.0005) is None
    assert "spans 9.8 steps" in biaxial.strain_rate_problem(0.51, 1e-4, 0.01, 0.25e-3, 0.0005)
    # a platen travels rate * H / 2 * dt per step: 1 % of a 0.25 mm radius at 1e-4 s is 0.333 1/s for H = 0.15 m
    travel = biaxial.strain_rate_problem(0.34, 1e-4, 0.15, 0.25e-3, 0.0005)
    assert "2.55e-06 m in one time step" in travel and "1.0% of the smallest radius" in travel
    assert "at most 0.333 1/s" in travel
    # the estimate before any work: a tenth of the one-contact critical step of the smallest particle
    config = resolve(overrides=["shear.strain_rate=0.8"])
    radius = 0.25e-3
    dt = 0.1 * config["run.time_step_safety"] * math.sqrt(2.0e8 * math.pi * radius**2 / (2 * 8.45e7))
    assert biaxial.strain_rate_problem(0.8, dt, 0.150, radius, 0.0005) is None
    assert "at most 0.864 1/s" in biaxial.strain_rate_problem(1.0, dt, 0.150, radius, 0.0005)
    biaxial.check_strain_rate(config)  # passes here; the run's own, longer step refuses it later
    with pytest.raises(ValueError, match="shear.strain_rate: 1 1/s is too fast"):
        biaxial.check_strain_rate(resolve(overrides=["shear.strain_rate=1"]))


def test_snapshot_strains_with_one_name_are_refused_before_any_work():
    with pytest.raises(ValueError, match=r"0\.005 and 0\.00504 share the snapshot name 'strain_0\.0050'"):
        biaxial.check_strain_rate(resolve(overrides=["shear.snapshot_strains=[0, 0.005, 0.00504]"]))


def test_a_rate_too_fast_for_the_runs_own_time_step_stops_before_the_first_record(tmp_path, capsys):
    (tmp_path / "tiny.toml").write_text(TINY_TOML)
    out = tmp_path / "run"
    args = ["biaxial", "--config", str(tmp_path / "tiny.toml"), "--strain-rate", "1", "--out", str(out),
            "--no-progress"]
    assert main(args) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "run stopped: shear.strain_rate:" in err and "fewer than 10" in err, err
    partial = read_results(out, allow_incomplete=True)
    assert partial.status == "failed" and partial.attrs["error"].startswith("BiaxialError: shear.strain_rate")
    assert partial.timeseries == {} and partial.snapshot_names == []  # no meaningless record written


def test_a_run_that_blows_up_is_marked_failed_with_its_error(tmp_path, monkeypatch, capsys, fast_figures):
    (tmp_path / "tiny.toml").write_text(TINY_TOML)
    out = tmp_path / "run"
    measure, calls = records.measure, []

    def unstable(*args, **kwargs):
        calls.append(1)
        if len(calls) == 3:  # what the engine raises when particles overlap beyond the limit
            raise grainlab.SimulationUnstableError("particles 3 and 7 overlap by 60 % of the smaller radius")
        return measure(*args, **kwargs)

    monkeypatch.setattr(records, "measure", unstable)
    assert main(["biaxial", "--config", str(tmp_path / "tiny.toml"), "--out", str(out), "--no-progress"]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "run stopped: particles 3 and 7 overlap" in err
    partial = read_results(out, allow_incomplete=True)
    assert partial.status == "failed"
    assert partial.attrs["error"] == "SimulationUnstableError: particles 3 and 7 overlap by 60 % of the smaller radius"
    assert len(partial.timeseries["axial_strain"]) == 2  # the records before it are kept
    assert not (out / "run.h5").exists()


def test_the_tiny_run_records_at_its_strains(tiny_reference):
    """The records of an accepted rate lie at their target strains (1/20 of a record interval at most)."""
    strains = read_results(tiny_reference).timeseries["axial_strain"]
    config = tiny_config()
    targets = [k * config["shear.record_interval"] for k in range(len(strains))]
    assert max(abs(s - t) for s, t in zip(strains, targets, strict=True)) < 0.05 * config["shear.record_interval"]
