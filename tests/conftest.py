"""Shared pytest fixtures: seeded factories for small simulations."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "tests" / "data"
BENCH_PACKING = ROOT / "benchmarks" / "data" / "dense-4000-disks.xyr"


def read_xyr(path: Path) -> tuple[float, np.ndarray, np.ndarray]:
    """The common packing format: first line the cell side, then ``x y radius``."""
    with open(path) as f:
        side = float(f.readline())
    table = np.loadtxt(path, skiprows=1)
    return side, table[:, :2].copy(), table[:, 2].copy()


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(12345)


@pytest.fixture
def dense_periodic():
    """Factory: a dense overlapping packing of ``n_side**2`` disks in a periodic square cell."""
    import grainlab

    def make(n_side: int = 12, friction: float = 0.5, threads: int = 1, seed: int = 0) -> grainlab.Simulation:
        g = np.random.default_rng(seed)
        s = 1.0e-3
        a, b = np.meshgrid(np.arange(n_side), np.arange(n_side), indexing="ij")
        pos = np.column_stack([(a.ravel() + 0.5) * s, (b.ravel() + 0.5) * s]) + g.uniform(-0.03, 0.03, (n_side**2, 2)) * s
        rad = g.uniform(0.48, 0.56, n_side**2) * s
        sim = grainlab.Simulation(
            pos, rad, density=2.0e8, contact_model=grainlab.ContactModel(friction=friction), threads=threads
        )
        sim.set_periodic_cell((0.0, 0.0), (n_side * s, n_side * s))
        return sim

    return make


@pytest.fixture(scope="session")
def quick_biaxial_run(tmp_path_factory) -> Path:
    """One ``grainlab biaxial --quick`` run (results folder, with its report.html) shared by the
    whole session: the protocol tests and the report tests read it; a test that writes into a
    results folder copies it first."""
    from grainlab.cli import main

    out = tmp_path_factory.mktemp("biaxial") / "quick"
    # 20 %/min: ten times the default 2 %/min, so the test session stays fast
    assert main(["biaxial", "--quick", "--strain-rate", "20%/min", "--out", str(out), "--no-progress"]) == 0
    return out
