"""The check every protocol's tests make: a run stopped after its Nth checkpoint and
resumed has the uninterrupted run's records and snapshots, bit for bit."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

import grainlab.protocols.runner as runner
from grainlab.io.hdf5 import read_results, write_checkpoint


class Stop(KeyboardInterrupt):
    """Raised in place of a kill, right after a checkpoint was written."""


def stop_and_resume(protocol: Any, out: Path, checkpoints: int, monkeypatch: Any) -> None:
    """Runs ``protocol`` into ``out``, stops it right after its ``checkpoints``-th
    checkpoint, checks that a plain rerun is refused, and resumes it to the end."""
    calls = {"n": 0}

    def stopping(*args: Any, **kwargs: Any) -> None:
        write_checkpoint(*args, **kwargs)
        calls["n"] += 1
        if calls["n"] == checkpoints:
            raise Stop

    with monkeypatch.context() as patch:
        patch.setattr(runner, "write_checkpoint", stopping)
        with pytest.raises(Stop):
            runner.run_protocol(protocol, out)
    with pytest.raises(ValueError, match="use --resume"):
        runner.run_protocol(protocol, out)
    runner.run_protocol(protocol, out, resume=True)


def kill_at_measure(monkeypatch: Any, module: Any, n: int, run: Any) -> None:
    """Runs ``run()`` with ``module.measure`` raising ``KeyboardInterrupt`` at its
    ``n``-th call (a kill while a record is measured), then puts it back."""
    real_measure = module.measure
    calls = {"n": 0}

    def dying_measure(*args: Any, **kwargs: Any) -> Any:
        calls["n"] += 1
        if calls["n"] == n:
            raise KeyboardInterrupt("simulated kill during shearing")
        return real_measure(*args, **kwargs)

    monkeypatch.setattr(module, "measure", dying_measure)
    try:
        with pytest.raises(KeyboardInterrupt):
            run()
    finally:
        monkeypatch.setattr(module, "measure", real_measure)


def assert_same_run(a_dir: Path, b_dir: Path, *, snapshots: str = "all") -> None:
    """The two runs' records and snapshot names are equal, and the positions of every
    snapshot (or of the last one, ``snapshots="last"``), bit for bit."""
    a, b = read_results(a_dir / "run.h5"), read_results(b_dir / "run.h5")
    assert b.status == "complete"
    for name in a.timeseries:
        np.testing.assert_array_equal(a.timeseries[name], b.timeseries[name], err_msg=name)
    assert a.snapshot_names == b.snapshot_names
    names = a.snapshot_names if snapshots == "all" else a.snapshot_names[-1:]
    for name in names:
        np.testing.assert_array_equal(a.snapshot(name).positions, b.snapshot(name).positions, err_msg=name)
