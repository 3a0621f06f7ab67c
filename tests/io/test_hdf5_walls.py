"""Walls stored with the snapshots of run.h5 and the engine step stored as an integer."""

from __future__ import annotations

import h5py
import numpy as np
import pytest

import grainlab
from grainlab.io.hdf5 import ResultsWriter, read_results
from grainlab.io.walls import WALL_LINE, WALL_SEGMENT, WallGeometry
from grainlab.snapshot import Snapshot


def _sim_with_walls() -> grainlab.Simulation:
    sim = grainlab.Simulation([[0.005, 0.002], [0.007, 0.002]], [1e-3, 1e-3], density=2.0e8)
    sim.add_segment_wall((0.0, 0.0), (0.02, 0.0))  # bottom platen, particles above
    sim.add_segment_wall((0.02, 0.01), (0.0, 0.01))  # top platen
    side = sim.add_line_wall((0.0, 0.0), (1.0, 0.0))  # left, infinite
    side.active = False
    return sim


def test_wall_geometry_of_a_simulation():
    sim = _sim_with_walls()
    walls = WallGeometry.from_simulation(sim, names={0: "bottom", 1: "top"})
    assert walls.names == ("bottom", "top", "wall_2")
    assert walls.kind.tolist() == [WALL_SEGMENT, WALL_SEGMENT, WALL_LINE]
    np.testing.assert_array_equal(walls.b[1], [0.0, 0.01])
    np.testing.assert_array_equal(walls.inward_normal[0], [0.0, 1.0])  # left of a -> b: up
    np.testing.assert_array_equal(walls.inward_normal[1], [0.0, -1.0])
    assert walls.active.tolist() == [True, True, False]
    assert walls.segments().shape == (2, 2, 2)  # the inactive line is not drawn


def test_a_line_is_clipped_to_the_bounds():
    walls = WallGeometry(("floor",), [WALL_LINE], [[0.0, 0.0]], [[0.0, 0.0]], [[0.0, 1.0]], [True])
    (seg,) = walls.segments(np.array([[0.0, 0.0], [3.0, 4.0]]))
    assert seg[:, 1].tolist() == [0.0, 0.0]  # stays on y = 0
    assert seg[:, 0].min() < 0.0 and seg[:, 0].max() > 3.0  # spans the bounds


def test_walls_and_integer_step_round_trip(tmp_path):
    sim = _sim_with_walls()
    snap = Snapshot.from_geometry(sim.positions, sim.radii)
    walls = WallGeometry.from_simulation(sim, names={0: "bottom", 1: "top"})
    with ResultsWriter(tmp_path / "run.h5", kind="biaxial") as out:
        out.append_rows({"step": [0, 1000, 2000], "axial_strain": [0.0, 0.001, 0.002]})
        out.write_snapshot("strain_0.0000", snap, step=0, walls=walls)
        out.write_snapshot("strain_0.0020", snap, step=2000)
    res = read_results(tmp_path / "run.h5")
    assert res.timeseries["step"].dtype == np.int64
    assert res.timeseries["step"].tolist() == [0, 1000, 2000]
    back = res.walls("strain_0.0000")
    assert back.names == walls.names
    np.testing.assert_array_equal(back.a, walls.a)
    np.testing.assert_array_equal(back.b, walls.b)
    np.testing.assert_array_equal(back.inward_normal, walls.inward_normal)
    assert back.active.tolist() == [True, True, False]
    assert res.walls(-1) is None  # written without walls
    with h5py.File(tmp_path / "run.h5") as f:  # what h5py users see
        assert f["timeseries/step"].dtype == np.int64
        assert f["snapshots/strain_0.0000/walls/a"].attrs["units"] == "m"
        assert f["snapshots/strain_0.0000/walls/name"].asstr()[()].tolist() == ["bottom", "top", "wall_2"]


def test_a_fractional_step_is_refused(tmp_path):
    with ResultsWriter(tmp_path / "run.h5") as out:
        with pytest.raises(ValueError, match=r"timeseries\['step'\]: the engine step must be a whole number"):
            out.append_rows({"step": [1.5], "t": [0.0]})


def test_bad_wall_arrays_are_refused():
    with pytest.raises(ValueError, match=r"walls.a: expected shape \(1, 2\)"):
        WallGeometry(("w",), [0], [0.0, 0.0], [[1.0, 0.0]], [[0.0, 1.0]], [True])
    with pytest.raises(ValueError, match="walls.kind: unknown code 5"):
        WallGeometry(("w",), [5], [[0.0, 0.0]], [[1.0, 0.0]], [[0.0, 1.0]], [True])
