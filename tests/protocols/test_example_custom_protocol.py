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

import grainlab.protocols.runner as runner
from grainlab.io.hdf5 import read_results, write_checkpoint

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


class Stop(KeyboardInterrupt):
    pass


@pytest.mark.parametrize("checkpoints", [1, 3, 5])
def test_a_stopped_run_resumes_to_the_same_bits(straight, tmp_path, monkeypatch, checkpoints):
    example = _example()
    calls = {"n": 0}

    def stopping(*args, **kwargs):
        write_checkpoint(*args, **kwargs)
        calls["n"] += 1
        if calls["n"] == checkpoints:
            raise Stop

    out = tmp_path / "run"
    protocol = example.IsotropicCompression(example.CompressionConfig())
    with monkeypatch.context() as patch:
        patch.setattr(runner, "write_checkpoint", stopping)
        with pytest.raises(Stop):
            runner.run_protocol(protocol, out)
    with pytest.raises(ValueError, match="use --resume"):
        runner.run_protocol(protocol, out)
    runner.run_protocol(protocol, out, resume=True)
    a, b = read_results(straight / "run.h5"), read_results(out / "run.h5")
    assert b.kind == "isotropic_compression" and b.status == "complete"
    for name in a.timeseries:
        np.testing.assert_array_equal(a.timeseries[name], b.timeseries[name], err_msg=name)
    assert a.snapshot_names == b.snapshot_names
    np.testing.assert_array_equal(a.snapshot(-1).positions, b.snapshot(-1).positions)
    assert not (out / "checkpoint.h5").exists()
