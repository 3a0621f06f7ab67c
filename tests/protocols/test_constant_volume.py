"""The rigid side walls (boundary.kind = "walls") and the constant-volume test
(shear.volume = "constant"), the undrained test's analogue: the area held to
rounding at every record, the side walls' stress equal to the grains' own
Love-Weber stress, the dense sample's pore-pressure analogue rising then falling
(contraction turning to dilation), drained walls holding sigma_0, the cyclic test
at constant volume, resume to the same bits, and the configuration's one-line
errors."""

from __future__ import annotations

import json

import numpy as np
import pytest
from resume_check import assert_same_run, stop_and_resume

import grainlab.protocols.runner as runner
from grainlab.cli import main
from grainlab.io.hdf5 import read_results
from grainlab.protocols.biaxial import BiaxialProtocol
from grainlab.protocols.config import ConfigError
from grainlab.protocols.cyclic import CyclicProtocol
from grainlab.protocols.registry import resolve_config

SIGMA_0 = 100e3
# 2 % axial strain on the quick sample, a checkpoint at every record: a few seconds
SHORT = ["shear.final_strain=0.02", "shear.snapshot_strains=[0, 0.01, 0.02]", "run.threads=1",
         "run.checkpoint_interval=1e-6"]


@pytest.fixture(scope="module")
def undrained_config():
    return resolve_config("biaxial", overrides=[*SHORT, "shear.volume=constant"], quick=True)


@pytest.fixture(scope="module")
def undrained(tmp_path_factory, undrained_config):
    out = tmp_path_factory.mktemp("undrained") / "run"
    runner.run_protocol(BiaxialProtocol(undrained_config), out)
    return out


def test_constant_volume_takes_the_rigid_walls_and_refuses_a_membrane():
    config = resolve_config("biaxial", overrides=["shear.volume=constant"], quick=True)
    assert config["boundary.kind"] == "walls"
    with pytest.raises(ConfigError, match="not with boundary.kind = 'membrane'"):
        resolve_config("biaxial", overrides=["shear.volume=constant", "boundary.kind=membrane"])
    assert resolve_config("biaxial", quick=True)["boundary.kind"] == "membrane"  # drained: unchanged


def test_the_area_is_held_and_the_pore_pressure_analogue_is_the_walls_stress(undrained):
    results = read_results(undrained / "run.h5")
    ts = results.timeseries
    np.testing.assert_allclose(ts["volumetric_strain"], 0.0, atol=1e-12)
    sigma_3 = ts["confining_stress_felt_pa"]
    np.testing.assert_allclose(ts["stress_ratio"], ts["axial_stress_pa"] / sigma_3, rtol=1e-14)
    assert np.all(ts["confining_pressure_pa"] == SIGMA_0)
    # the side walls feel what the grains carry: their Love-Weber sigma_xx (walls included)
    np.testing.assert_allclose(sigma_3[1:], ts["love_weber_xx_pa"][1:], rtol=0.03)
    np.testing.assert_allclose(ts["axial_stress_pa"][1:], ts["love_weber_yy_pa"][1:], rtol=0.03)
    # a dense sample: contraction first (u > 0), then dilation (u < 0) as the grains ride over each other
    u = SIGMA_0 - sigma_3
    k = int(np.argmax(u))
    assert u[k] > 5e3 and 0 < ts["axial_strain"][k] < 0.01 and u[-1] < -0.5 * SIGMA_0
    summary = results.summary
    assert summary["shear_volume"] == "constant"
    assert summary["pore_pressure_max_pa"] == pytest.approx(u[k], rel=1e-12)
    assert summary["pore_pressure_final_pa"] == pytest.approx(u[-1], rel=1e-12)
    snap = results.snapshot(-1)
    assert snap.n_particles == summary["n_particles"]  # no membrane disks


@pytest.mark.parametrize("checkpoints", [4, 12])
def test_a_stopped_constant_volume_run_resumes_to_the_same_bits(undrained, undrained_config, tmp_path,
                                                                 monkeypatch, checkpoints):
    stop_and_resume(BiaxialProtocol(undrained_config), tmp_path / "run", checkpoints, monkeypatch)
    assert_same_run(undrained, tmp_path / "run")


def test_drained_rigid_walls_hold_the_confining_pressure(tmp_path):
    config = resolve_config("biaxial", overrides=[*SHORT, "boundary.kind=walls"], quick=True)
    runner.run_protocol(BiaxialProtocol(config), tmp_path / "run")
    ts = read_results(tmp_path / "run" / "run.h5").timeseries
    np.testing.assert_allclose(ts["confining_stress_felt_pa"], SIGMA_0, rtol=0.05)
    assert np.ptp(ts["volumetric_strain"]) > 1e-3  # the volume is free
    np.testing.assert_allclose(ts["stress_ratio"], ts["axial_stress_pa"] / SIGMA_0, rtol=1e-14)


def test_the_cyclic_test_at_constant_volume(tmp_path):
    config = resolve_config("cyclic", overrides=["shear.volume=constant", "cyclic.cycles=2",
                                                 "cyclic.strain_amplitude=0.002", "run.threads=1"], quick=True)
    runner.run_protocol(CyclicProtocol(config), tmp_path / "run")
    results = read_results(tmp_path / "run" / "run.h5")
    ts = results.timeseries
    np.testing.assert_allclose(ts["volumetric_strain"], 0.0, atol=1e-12)
    for row in results.summary["cycles"]:
        end = int(np.argmin(np.abs(ts["cycle"] - row["cycle"])))
        s1, s3 = ts["axial_stress_pa"][end], ts["confining_stress_felt_pa"][end]
        assert row["pore_pressure_pa"] == pytest.approx(SIGMA_0 - s3, rel=1e-12)
        assert row["mean_effective_stress_pa"] == pytest.approx(0.5 * (s1 + s3), rel=1e-12)


def test_the_command_line_writes_the_stress_path(tmp_path, capsys):
    out = tmp_path / "undrained"
    assert main(["biaxial", "--quick", "--out", str(out), "--no-progress", "--set", "shear.volume=constant",
                 "--set", "shear.final_strain=0.01", "--set", "shear.snapshot_strains=[0, 0.01]"]) == 0
    printed = capsys.readouterr().out
    assert "constant volume: u up to" in printed
    assert (out / "fig19_stress_path.png").exists()
    page = (out / "report.html").read_text()
    assert "Stress path at constant volume" in page
    assert json.loads((out / "summary.json").read_text())["shear_volume"] == "constant"


def test_a_membrane_at_constant_volume_is_one_line_and_no_folder(tmp_path, capsys):
    out = tmp_path / "never"
    assert main(["biaxial", "--quick", "--out", str(out), "--set", "shear.volume=constant",
                 "--set", "boundary.kind=membrane"]) != 0
    err = capsys.readouterr().err
    assert "shear.volume: 'constant' holds the sample's area" in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_the_docs_quote_the_default_constant_volume_run():
    """docs/protocols.md's default constant-volume run is tests/data/constant_volume's summary."""
    from pathlib import Path

    root = Path(__file__).resolve().parents[2]
    s = json.loads((root / "tests" / "data" / "constant_volume" / "default_summary.json").read_text())
    line = next(x for x in (root / "docs" / "protocols.md").read_text().splitlines()
                if x.startswith("grainlab biaxial: 3518") and "constant volume" in x)
    assert line.split("; ")[:-2] == [
        f"grainlab biaxial: {s['n_particles']} grains, porosity {s['porosity_initial']:.3f}, "
        f"Z0 {s['coordination_number_initial']:.2f}",
        f"peak sigma1/sigma3 {s['peak_stress_ratio']:.2f} at {100 * s['axial_strain_at_peak']:.2f} % axial strain",
        f"constant volume: u up to {s['pore_pressure_max_pa'] / 1e3:.1f} kPa at "
        f"{100 * s['axial_strain_at_pore_pressure_max']:.2f} %, {s['pore_pressure_final_pa'] / 1e3:.1f} kPa at the end"]
    assert s["shear_volume"] == "constant" and s["final_stress_ratio"] == pytest.approx(1.745, abs=5e-4)
