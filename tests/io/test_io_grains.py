"""Grains (rigid bodies) in the files read and written: a particles CSV keeps each
particle's grain, its centroid and angle to the bit; a LAMMPS dump's molecule ids
become grains when asked; files without them make every particle a grain of its own;
bad grain columns are refused naming the file and line."""

from __future__ import annotations

import numpy as np
import pytest

from grainlab.io import FileFormatError
from grainlab.io.csv import read_particles_csv, write_particles_csv
from grainlab.io.lammps_dump import read_lammps_dump
from grainlab.snapshot import GRAIN_ANGLE_FIELD, GRAIN_CENTROID_FIELD, GRAIN_FIELD, Snapshot


def _two_dimers_and_a_disk() -> Snapshot:
    """Grains 4 and 9 (two pebbles each) and grain 2 (one disk), values with all 17 digits."""
    rng = np.random.default_rng(3)
    positions = np.array([[0.0, 0.0], [1.5e-3, 0.0], [5e-3, 0.0], [5e-3, 1.5e-3], [9e-3, 9e-3]]) + rng.uniform(
        0, 1e-4, (5, 2)
    )
    rotations = rng.uniform(-3, 3, 5)
    grain = np.array([4, 4, 9, 9, 2])
    centroid = np.array([positions[:2].mean(axis=0)] * 2 + [positions[2:4].mean(axis=0)] * 2 + [positions[4]])
    angle = np.r_[rotations[0], rotations[0], rotations[2], rotations[2], rotations[4]]
    return Snapshot.from_geometry(
        positions,
        np.full(5, 0.8e-3),
        ids=[10, 11, 12, 13, 14],
        rotations=rotations,
        tolerance=1e-9,
        particle_fields={GRAIN_FIELD: grain, GRAIN_CENTROID_FIELD: centroid, GRAIN_ANGLE_FIELD: angle},
    )


def test_a_particles_csv_keeps_the_grains_to_the_bit(tmp_path):
    snap = _two_dimers_and_a_disk()
    path = write_particles_csv(tmp_path / "p.csv", snap)
    assert path.read_text().splitlines()[0] == "id,x,y,radius,rotation,kind,grain,grain_x,grain_y,grain_angle"
    back = read_particles_csv(path, tolerance=1e-9)
    np.testing.assert_array_equal(back.grains(), [4, 4, 9, 9, 2])
    assert back.grains().dtype == np.int64 and back.n_grains == 3
    for name in (GRAIN_CENTROID_FIELD, GRAIN_ANGLE_FIELD):
        assert np.asarray(back.particle_fields[name]).tobytes() == np.asarray(snap.particle_fields[name]).tobytes()
    assert "grain_x" not in back.particle_fields  # read as the centroid, not as columns of their own
    np.testing.assert_array_equal(back.grain_centroids()[4], snap.positions[4])


def test_a_csv_with_grain_labels_only_reads_them_and_knows_no_centroids(tmp_path):
    path = tmp_path / "p.csv"
    path.write_text("id,x,y,radius,kind,grain\n1,0,0,1,0,7\n2,1.5,0,1,0,7\n3,5,0,1,0,8\n")
    snap = read_particles_csv(path)
    np.testing.assert_array_equal(snap.grains(), [7, 7, 8])
    with pytest.raises(ValueError, match=r"grain centroids: the snapshot labels clumps .* without"):
        snap.grain_centroids()
    # no grain column: every particle a grain of its own, at its centre
    plain = tmp_path / "q.csv"
    plain.write_text("id,x,y,radius,kind\n1,0,0,1,0\n2,1.5,0,1,0\n3,5,0,1,0\n")
    disks = read_particles_csv(plain)
    np.testing.assert_array_equal(disks.grains(), [0, 1, 2])
    np.testing.assert_array_equal(disks.grain_centroids(), disks.positions)


@pytest.mark.parametrize(
    ("header", "rows", "message"),
    [
        ("grain", ["0", "-2"], r":3: column 'grain': -2 is not a grain label \(>= 0\)"),
        ("grain", ["0", "1.5"], r":3: column 'grain': 1.5 is not an integer id"),
        ("grain,grain_x", ["0,0", "0,0"], r"columns 'grain_x', 'grain_y': a grain's centroid needs both"),
        ("grain_angle", ["0", "0"], r"column 'grain_angle': a grain's value without a 'grain' column"),
        ("grain,grain_angle", ["3,0.5", "3,0.25"], r"particles 0 and 1 are of grain 3 but carry different values"),
    ],
)
def test_bad_grain_columns_are_refused(tmp_path, header, rows, message):
    path = tmp_path / "p.csv"
    path.write_text(f"id,x,y,radius,kind,{header}\n1,0,0,1,0,{rows[0]}\n2,1.5,0,1,0,{rows[1]}\n")
    with pytest.raises(ValueError, match=message):
        read_particles_csv(path)


DUMP = """ITEM: TIMESTEP
0
ITEM: NUMBER OF ATOMS
5
ITEM: BOX BOUNDS ff ff pp
-0.01 0.02
-0.01 0.02
-0.001 0.001
ITEM: ATOMS id mol type x y radius
1 3 1 0.0 0.0 0.001
2 3 1 0.0015 0.0 0.001
3 1 1 0.006 0.0 0.001
4 1 1 0.006 0.0015 0.001
5 2 1 0.012 0.0 0.001
"""


def test_a_lammps_dumps_molecule_ids_are_its_grains(tmp_path):
    path = tmp_path / "rigid.dump"
    path.write_text(DUMP)
    snap = read_lammps_dump(path, grain_column="mol")
    np.testing.assert_array_equal(snap.grains(), [3, 3, 1, 1, 2])
    assert snap.n_grains == 3
    # the molecule ids stay a field of their own; without grain_column they are not grains
    disks = read_lammps_dump(path)
    np.testing.assert_array_equal(disks.particle_fields["mol"], [3, 3, 1, 1, 2])
    np.testing.assert_array_equal(disks.grains(), np.arange(5))
    with pytest.raises(FileFormatError, match="no column 'body' for grain_column"):
        read_lammps_dump(path, grain_column="body")
    bad = tmp_path / "bad.dump"
    bad.write_text(DUMP.replace("\n5 2 1", "\n5 -1 1"))
    with pytest.raises(FileFormatError, match=r"bad.dump:14: column 'mol': -1 is not a grain label \(>= 0\)"):
        read_lammps_dump(bad, grain_column="mol")
