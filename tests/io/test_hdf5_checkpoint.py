"""checkpoint.h5: engine state round trip (bitwise continuation), checksums, atomic writes."""

from __future__ import annotations

import h5py
import numpy as np
import pytest

from grainlab.io.hdf5 import (
    CHECKPOINT_FORMAT_VERSION,
    CheckpointError,
    ResultsWriter,
    UnsupportedVersionError,
    read_checkpoint,
    write_checkpoint,
)

STATE = {
    "phase": "shearing",
    "step": 123456,
    "next_record_strain": 0.0055,
    "snapshots_done": ["strain_0.0000", "strain_0.0050"],
    "timeseries_rows": 11,
    "note": "σ₃ servo ✓",
    "nested": {"rng": [1, 2, 3], "flag": False, "none": None},
}


def bits(a: np.ndarray) -> bytes:
    return np.ascontiguousarray(a).tobytes()


def test_engine_continues_bitwise_from_a_checkpoint(tmp_path, dense_periodic):
    import grainlab

    sim = dense_periodic(n_side=18, friction=0.5, threads=1)  # 324 disks
    assert sim.n_particles == 324
    sim.local_damping = 0.3
    sim.set_velocity_gradient([[-0.5, 0.0], [0.0, 0.5]])
    sim.run(300)
    path = write_checkpoint(
        tmp_path / "checkpoint.h5",
        sim.to_bytes(),
        {**STATE, "step": sim.step_count},
        arrays={"positions": sim.positions, "radii": sim.radii},
    )
    positions_at_checkpoint = np.array(sim.positions)
    sim.run(400)
    expected = (np.array(sim.positions), np.array(sim.velocities), np.array(sim.rotations))

    cp = read_checkpoint(path)
    assert cp.protocol_state == {**STATE, "step": 300}
    assert bits(cp.arrays["positions"]) == bits(positions_at_checkpoint)
    resumed = grainlab.Simulation.from_bytes(cp.engine_state)
    assert resumed.step_count == 300 and resumed.n_particles == 324
    resumed.run(400)
    for got, want in zip(
        (resumed.positions, resumed.velocities, resumed.rotations), expected, strict=True
    ):
        assert bits(got) == bits(want)


def test_round_trip_of_state_and_arrays_is_exact(tmp_path):
    rng = np.random.default_rng(1)
    state = bytes(rng.integers(0, 256, 100_003, dtype=np.uint8))
    arrays = {
        "f64": rng.normal(size=(17, 2)),
        "f32": rng.normal(size=5).astype(np.float32),
        "i8": np.array([-1, 0, 1], np.int8),
        "u64": np.array([2**64 - 1], np.uint64),
        "flags": np.array([True, False]),
        "empty": np.zeros((0, 3)),
        "nan": np.array([np.nan, -np.inf]),
    }
    path = write_checkpoint(tmp_path, state, STATE, arrays=arrays)
    assert path == tmp_path / "checkpoint.h5"
    cp = read_checkpoint(tmp_path)
    assert cp.engine_state == state and cp.protocol_state == STATE
    assert list(cp.arrays) == list(arrays)
    for name, a in arrays.items():
        b = cp.arrays[name]
        assert (b.dtype, b.shape, bits(b)) == (a.dtype, a.shape, bits(a)), name
    assert cp.format_version == CHECKPOINT_FORMAT_VERSION == 2
    assert cp.grainlab_version and cp.created.endswith("+00:00")
    with h5py.File(path) as f:
        assert f.attrs["format"] == "grainlab-checkpoint"
        assert f["engine_state"].dtype == np.uint8
    # a new checkpoint replaces the old one whole
    write_checkpoint(tmp_path, b"second", {"phase": "done"})
    assert read_checkpoint(tmp_path).engine_state == b"second"
    assert read_checkpoint(tmp_path).arrays == {}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["checkpoint.h5"]


def flip_byte_in(path, dataset: str, offset: int) -> None:
    with h5py.File(path) as f:
        start = f[dataset].id.get_offset()
    assert start is not None
    with open(path, "r+b") as fh:
        fh.seek(start + offset)
        byte = fh.read(1)
        fh.seek(start + offset)
        fh.write(bytes([byte[0] ^ 0x01]))


@pytest.mark.parametrize(
    ("dataset", "offset"),
    [("engine_state", 0), ("engine_state", 4999), ("protocol_state", 10), ("arrays/x", 17)],
)
def test_a_flipped_byte_is_detected(tmp_path, dataset, offset):
    rng = np.random.default_rng(2)
    path = write_checkpoint(tmp_path, rng.bytes(5000), STATE, arrays={"x": rng.normal(size=50)})
    if dataset == "protocol_state":  # variable-length string: its bytes live in the heap
        raw = path.read_bytes()
        k = raw.index(b'"phase"')
        damaged = raw[: k + 2] + bytes([raw[k + 2] ^ 0x01]) + raw[k + 3 :]
        path.write_bytes(damaged)
    else:
        flip_byte_in(path, dataset, offset)
    with pytest.raises(
        CheckpointError, match=rf"checkpoint.h5: {dataset}: checksum mismatch .*corrupt"
    ):
        read_checkpoint(path)


def test_truncated_or_foreign_checkpoint_is_refused(tmp_path):
    path = write_checkpoint(tmp_path, bytes(200_000), STATE)
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])
    with pytest.raises(CheckpointError, match="cannot be read as HDF5: the file is truncated"):
        read_checkpoint(path)
    with pytest.raises(CheckpointError, match="file not found"):
        read_checkpoint(tmp_path / "nope.h5")
    ResultsWriter(tmp_path / "run.h5").finalize()
    with pytest.raises(CheckpointError, match=r"is a results file .*use read_results\(\)"):
        read_checkpoint(tmp_path / "run.h5")
    with h5py.File(path, "w") as f:
        f.attrs["format"] = "grainlab-checkpoint"
        f.attrs["format_version"] = 3
    with pytest.raises(UnsupportedVersionError, match="format_version 3 is newer than this"):
        read_checkpoint(path)
    with h5py.File(path, "w") as f:
        f.attrs["format"] = "grainlab-checkpoint"
        f.attrs["format_version"] = 2
    with pytest.raises(CheckpointError, match="missing dataset"):
        read_checkpoint(path)


def test_a_checkpoint_of_a_retired_layout_is_refused_by_name(tmp_path):
    # layout 1 is the layout 2 of this grainlab's writer under another number
    path = write_checkpoint(tmp_path, b"state", STATE, arrays={"results_partial": np.zeros(4, np.uint8)})
    with h5py.File(path, "r+") as f:
        f.attrs["format_version"] = np.int64(1)
    with pytest.raises(CheckpointError, match=r"format_version 1: written by an earlier grainlab, which this one no "
                                              r"longer resumes \(.*\); start the run again in a new folder"):
        read_checkpoint(path)


def test_bad_checkpoint_input_is_refused_before_writing(tmp_path):
    write_checkpoint(tmp_path, b"good", {"phase": "a"})
    with pytest.raises(TypeError, match="engine_state: expected bytes"):
        write_checkpoint(tmp_path, "text", {})  # type: ignore[arg-type]
    with pytest.raises(
        TypeError, match=r"protocol_state\['when'\]: cannot store a value of type object"
    ):
        write_checkpoint(tmp_path, b"x", {"when": object()})
    with pytest.raises(ValueError, match=r"arrays\['s'\]: cannot store dtype <U1"):
        write_checkpoint(tmp_path, b"x", {}, arrays={"s": np.array(["a"])})
    with pytest.raises(ValueError, match="arrays: 'a/b' is not a valid name"):
        write_checkpoint(tmp_path, b"x", {}, arrays={"a/b": np.zeros(1)})
    assert read_checkpoint(tmp_path).engine_state == b"good"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["checkpoint.h5"]
