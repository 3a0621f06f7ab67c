"""examples/08_custom_protocol.py: a protocol written on the runner alone gets the
runner's checkpoints and resume (a run stopped after any checkpoint ends with the
uninterrupted run's bits) and the refusal of a folder holding a run; its physics
is sane (a denser packing and more contacts at each higher pressure)."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from resume_check import assert_same_run, stop_and_resume

from grainlab.io.hdf5 import read_results

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "08_custom_protocol.py"


def _example():
    spec = importlib.util.spec_from_file_location("custom_protocol", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def straight(tmp_path_factory):
    out = tmp_path_factory.mktemp("compression") / "run"
    printed = subprocess.run([sys.executable, str(EXAMPLE), str(out)], check=True, capture_output=True,
                             text=True).stdout
    assert printed.count("kPa: porosity") == 4 and "run.h5" in printed
    return out


def test_each_higher_pressure_packs_denser_with_more_contacts(straight):
    series = read_results(straight / "run.h5").timeseries
    assert list(series["pressure_pa"]) == [50e3, 100e3, 200e3, 400e3]
    assert np.all(np.diff(series["porosity"]) < 0)
    assert np.all(np.diff(series["coordination_number"]) > 0)


@pytest.mark.parametrize("checkpoints", [1, 3, 5])
def test_a_stopped_run_resumes_to_the_same_bits(straight, tmp_path, monkeypatch, checkpoints):
    example = _example()
    out = tmp_path / "run"
    stop_and_resume(example.IsotropicCompression(example.CompressionConfig()), out, checkpoints, monkeypatch)
    assert_same_run(straight, out, snapshots="last")
    assert read_results(out / "run.h5").kind == "isotropic_compression"
    assert not (out / "checkpoint.h5").exists()
