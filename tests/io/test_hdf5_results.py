"""run.h5: a file written by the current version reads back exactly; layout versions; selection."""

from __future__ import annotations

import json

import h5py
import numpy as np
import pytest

from grainlab.io import FileFormatError, read_snapshot
from grainlab.io.hdf5 import (
    FORMAT_VERSION,
    ResultsFileError,
    ResultsWriter,
    UnsupportedVersionError,
    read_hdf5_snapshot,
    read_results,
    snapshot_name,
    write_checkpoint,
)
from grainlab.io.hdf5.reader import _READERS_BY_VERSION
from grainlab.snapshot import ParticleKind, Snapshot

CONFIG = {
    "sample": {
        "width_m": 0.075,
        "height_m": 0.15,
        "porosity": 0.12,
        "grading": {"d_min_m": 5e-4, "d_max_m": 3e-3, "curve": [[0.5, 0.0], [3.0, 100.0]]},
        "seed": 2**40 + 3,
    },
    "contact": {"normal_stiffness": 8.45e7, "friction": 0.5, "bonded": False},
    "label": "biaxial test — σ₃ = 100 kPa, ü",
    "snapshot_strains": [0.0, 0.005, 0.007, 0.009, 0.015, 0.1],
    "empty_list": [],
    "empty_dict": {},
    "nothing": None,
    "tiny": 5e-324,
    "third": 1.0 / 3.0,
    "not_a_number": float("nan"),
    "infinite": float("-inf"),
    "mixed": [1, "two", 3.0, True, None, {"deep": [[]]}],
}


def same_config(a, b) -> bool:
    """Equality that also holds for NaN, and tells 1 from 1.0 and True from 1."""
    return json.dumps(a, sort_keys=True) == json.dumps(b, sort_keys=True) and _types(a) == _types(b)


def _types(x):
    if isinstance(x, dict):
        return {k: _types(v) for k, v in x.items()}
    if isinstance(x, list):
        return [_types(v) for v in x]
    return type(x).__name__


def rich_snapshot(seed: int = 3, n: int = 60) -> Snapshot:
    """Every Snapshot field set, wall contacts included."""
    rng = np.random.default_rng(seed)
    base = Snapshot.from_geometry(
        rng.uniform(1e-3, 19e-3, (n, 2)), rng.uniform(0.6e-3, 1.4e-3, n), tolerance=0.0
    )
    k = base.n_contacts
    walls = 3
    wall_i = np.array([0, 5, 7])
    ci = np.concatenate([base.contact_i, wall_i])
    cj = np.concatenate([base.contact_j, -1 - np.array([0, 2, 3])])
    normals = np.concatenate([base.contact_normals(), [[0.0, -1.0], [1.0, 0.0], [-0.6, 0.8]]])
    points = rng.uniform(0, 0.02, (k + walls, 2))
    kind = np.full(n, ParticleKind.SOIL, dtype=np.int8)
    kind[:4] = ParticleKind.MEMBRANE
    kind[10:12] = ParticleKind.BOUNDARY
    return Snapshot(
        base.positions,
        base.radii,
        ids=rng.permutation(10 * n)[:n] + 7,
        rotations=rng.normal(size=n),
        kind=kind,
        contact_i=ci,
        contact_j=cj,
        normal_force=rng.uniform(0, 50, k + walls),
        shear_force=rng.normal(size=k + walls),
        contact_normal=normals,
        contact_point=points,
        contact_fields={
            "overlap": rng.uniform(0, 1e-5, k + walls),
            "sliding": rng.uniform(size=k + walls) < 0.3,
            "bonded": np.zeros(k + walls, bool),
            "chain_id": rng.integers(0, 5, k + walls).astype(np.int32),
        },
        particle_fields={
            "velocity": rng.normal(size=(n, 2)),
            "force": rng.normal(size=(n, 2)).astype(np.float32),
            "n_cycles": rng.integers(0, 100, n).astype(np.uint16),
        },
        box=[[0.0, 0.02], [0.0, 0.02]],
        periodic=(True, False),
        time=1.25e-3,
        axial_strain=0.0150000001,
        metadata={"source": "test ✓", "step": 1200, "nested": {"a": [1, 2.5, None]}},
    )


def assert_same_array(a, b, name):
    a, b = np.asarray(a), np.asarray(b)
    assert a.dtype == b.dtype, (name, a.dtype, b.dtype)
    assert a.shape == b.shape, (name, a.shape, b.shape)
    assert a.tobytes() == b.tobytes(), name  # bitwise


def assert_same_snapshot(a: Snapshot, b: Snapshot) -> None:
    for name in (
        "positions",
        "radii",
        "ids",
        "rotations",
        "kind",
        "contact_i",
        "contact_j",
        "normal_force",
        "shear_force",
        "contact_normal",
        "contact_point",
        "box",
    ):
        va, vb = getattr(a, name), getattr(b, name)
        assert (va is None) == (vb is None), name
        if va is not None:
            assert_same_array(va, vb, name)
    for owner in ("contact_fields", "particle_fields"):
        fa, fb = getattr(a, owner), getattr(b, owner)
        assert list(fa) == list(fb), owner
        for key in fa:
            assert_same_array(fa[key], fb[key], f"{owner}[{key}]")
    assert a.periodic == b.periodic
    assert a.time == b.time and a.axial_strain == b.axial_strain
    assert dict(a.metadata) == dict(b.metadata)


# ------------------------------------------------------------------------- round trip
def test_round_trip_is_exact(tmp_path):
    snap = rich_snapshot()
    geometry_only = Snapshot.from_geometry([[0.0, 0.0], [2e-3, 0.0]], [1e-3, 1e-3], tolerance=1e-9)
    empty = Snapshot(np.zeros((0, 2)), np.zeros(0))
    rng = np.random.default_rng(0)
    batches = [
        {"axial_strain": rng.uniform(size=m), "stress_ratio": rng.normal(size=m)}
        for m in (1, 7, 0, 2500, 3)
    ]
    with ResultsWriter(tmp_path / "run.h5", kind="biaxial") as out:
        out.write_config(CONFIG)
        out.define_timeseries({"axial_strain": "", "stress_ratio": ""})
        for batch in batches:
            out.append_rows(batch)
        out.append_timeseries({"axial_strain": 0.1, "stress_ratio": np.float32(2.5)})
        out.write_snapshot("strain_0.0150", snap)
        out.write_snapshot("initial", geometry_only)
        out.write_snapshot("empty", empty)
        out.write_summary({"peak_stress_ratio": 3.25, "axial_strain_at_peak": 0.015, "note": "ok"})
        out.write_phases({"generation": 12.5, "consolidation": 3.0, "shearing": 40.25})
    res = read_results(tmp_path / "run.h5")

    assert res.format_version == FORMAT_VERSION == 3
    assert res.kind == "biaxial" and res.status == "complete"
    assert res.grainlab_version and res.created.endswith("+00:00")
    assert same_config(res.config, CONFIG)
    assert res.summary == {"peak_stress_ratio": 3.25, "axial_strain_at_peak": 0.015, "note": "ok"}
    assert res.phases == {"generation": 12.5, "consolidation": 3.0, "shearing": 40.25}
    assert list(res.phases) == ["generation", "consolidation", "shearing"]
    for column in ("axial_strain", "stress_ratio"):
        expected = np.concatenate(
            [b[column] for b in batches] + [[{"axial_strain": 0.1, "stress_ratio": 2.5}[column]]]
        )
        assert_same_array(res.timeseries[column], expected, column)
    assert res.snapshot_names == ["strain_0.0150", "initial", "empty"]
    info = res.snapshots[0]
    assert (info.time, info.axial_strain, info.step) == (1.25e-3, 0.0150000001, 1200)
    assert (info.n_particles, info.n_contacts) == (snap.n_particles, snap.n_contacts)
    assert_same_snapshot(res.snapshot("strain_0.0150"), snap)
    assert_same_snapshot(res.snapshot("initial"), geometry_only)
    assert_same_snapshot(res.snapshot(), empty)
    assert res.snapshot(-1).n_particles == 0


def test_engine_snapshot_with_wall_contacts_round_trips(tmp_path):
    import grainlab

    rng = np.random.default_rng(0)
    a, b = np.meshgrid(np.arange(8), np.arange(8))
    pos = np.column_stack([(a.ravel() + 0.5) * 2e-3, (b.ravel() + 0.5) * 2e-3])
    sim = grainlab.Simulation(
        pos,
        rng.uniform(0.4e-3, 0.8e-3, len(pos)),
        density=2650.0,
        contact_model=grainlab.ContactModel(
            normal_stiffness=1e6, shear_stiffness=1e6, friction=0.5
        ),
        local_damping=0.7,
        gravity=(0.0, -9.81),
        threads=1,
    )
    width = 16e-3
    sim.add_segment_wall((width, 0.0), (0.0, 0.0))
    sim.add_segment_wall((0.0, 0.0), (0.0, 4 * width))
    sim.add_segment_wall((width, 4 * width), (width, 0.0))
    sim.run(4000)
    snap = sim.snapshot(step=sim.step_count, axial_strain=0.0)
    assert snap.is_wall_contact.any() and (~snap.is_wall_contact).any()
    assert set(snap.contact_fields) == {"overlap", "sliding", "bonded"}
    with ResultsWriter(tmp_path, kind="demo") as out:
        out.write_snapshot(snapshot_name(0.0), snap)
    back = read_results(tmp_path).snapshot("strain_0.0000")
    assert_same_snapshot(back, snap)
    np.testing.assert_array_equal(back.wall_ids, snap.wall_ids)
    assert read_snapshot(tmp_path / "run.h5", timestep=4000).n_contacts == snap.n_contacts


def test_config_and_summary_have_a_readable_attribute_view(tmp_path):
    with ResultsWriter(tmp_path / "run.h5") as out:
        out.write_config(CONFIG)
        out.write_config({"a": {"b": 1}})  # replaces, attributes too
        out.write_summary({"n_particles": 3000, "porosity_initial": 0.12, "ok": True})
    with h5py.File(tmp_path / "run.h5") as f:
        assert dict(f["config"].attrs) == {"a.b": 1}
        s = f["summary"].attrs
        assert (s["n_particles"], s["porosity_initial"], bool(s["ok"])) == (3000, 0.12, True)
        assert json.loads(f["config/json"].asstr()[()]) == {"a": {"b": 1}}
    with ResultsWriter(tmp_path / "run.h5", overwrite=True) as out:
        out.write_config(CONFIG)
    with h5py.File(tmp_path / "run.h5") as f:
        a = f["config"].attrs
        assert a["sample.porosity"] == 0.12
        assert a["sample.seed"] == 2**40 + 3
        assert a["label"] == CONFIG["label"]
        np.testing.assert_array_equal(a["snapshot_strains"], CONFIG["snapshot_strains"])
        assert "mixed" not in a and "nothing" not in a  # JSON only


def test_snapshot_names_are_stable():
    assert snapshot_name(0.015) == "strain_0.0150"
    assert snapshot_name(0.0150000001) == "strain_0.0150"
    assert snapshot_name(0.1) == "strain_0.1000"
    assert snapshot_name(0.0) == snapshot_name(-0.0) == snapshot_name(-1e-12) == "strain_0.0000"
    assert snapshot_name(0.0125, digits=5, prefix="eps") == "eps_0.01250"
    with pytest.raises(ValueError, match="axial_strain: must be finite"):
        snapshot_name(float("nan"))


# ---------------------------------------------------------------------- selection
@pytest.fixture
def three_snapshots(tmp_path):
    snaps = [rich_snapshot(seed=s, n=20 + s) for s in range(3)]
    with ResultsWriter(tmp_path / "run.h5", kind="biaxial") as out:
        for k, (strain, snap) in enumerate(zip((0.0, 0.005, 0.015), snaps, strict=True)):
            out.write_snapshot(snapshot_name(strain), snap, step=1000 * k)
    return tmp_path / "run.h5", snaps


def test_read_snapshot_selects_by_name_index_step_and_defaults_to_last(three_snapshots):
    path, snaps = three_snapshots
    assert_same_snapshot(read_snapshot(path), snaps[2])
    assert_same_snapshot(read_snapshot(path, snapshot="strain_0.0050"), snaps[1])
    assert_same_snapshot(read_snapshot(str(path), snapshot=0), snaps[0])
    assert_same_snapshot(read_snapshot(path, snapshot=-2), snaps[1])
    assert_same_snapshot(read_snapshot(path, timestep=2000), snaps[2])
    assert_same_snapshot(read_snapshot(path.parent, format="grainlab-hdf5"), snaps[2])


def test_read_snapshot_selection_errors_are_clear(three_snapshots, tmp_path):
    path, _ = three_snapshots
    with pytest.raises(ValueError, match=r"no snapshot 'strain_0.0070'.*strain_0.0050"):
        read_snapshot(path, snapshot="strain_0.0070")
    with pytest.raises(ValueError, match="index 3 out of range for 3 snapshots"):
        read_snapshot(path, snapshot=3)
    with pytest.raises(ValueError, match=r"no snapshot at step 5 .*\[0, 1000, 2000\]"):
        read_snapshot(path, timestep=5)
    with pytest.raises(ValueError, match="give one or the other"):
        read_snapshot(path, snapshot=0, timestep=0)
    with pytest.raises(ValueError, match="contacts: a grainlab results file carries"):
        read_snapshot(path, contacts=path)
    with pytest.raises(ValueError, match="tolerance"):
        read_snapshot(path, tolerance=1e-6)
    with pytest.raises(ValueError, match="boundary types"):
        read_snapshot(path, boundary_types=(2,))
    csv = tmp_path / "p.csv"
    csv.write_text("id,x,y,radius\n1,0,0,1\n")
    with pytest.raises(ValueError, match="snapshot: only applies to grainlab HDF5"):
        read_snapshot(csv, snapshot="strain_0.0050")
    with ResultsWriter(tmp_path / "none.h5") as out:
        pass
    with pytest.raises(ResultsFileError, match="holds no snapshots"):
        read_snapshot(tmp_path / "none.h5")
    unstepped = tmp_path / "unstepped.h5"
    with ResultsWriter(unstepped) as out:
        out.write_snapshot("a", Snapshot(np.zeros((1, 2)), np.ones(1)))
    with pytest.raises(ValueError, match=r"records its engine step; select by name.*\['a'\]"):
        read_snapshot(unstepped, timestep=0)


def test_grainlab_analyze_reads_run_h5(three_snapshots, tmp_path, capsys):
    from grainlab.cli import main

    path, snaps = three_snapshots
    out = tmp_path / "analysis"
    code = main(["analyze", str(path), "--timestep", "1000", "--no-figures", "--out", str(out)])
    assert code == 0
    n_sample = int(snaps[1].is_sample.sum())  # membrane disks are not part of the sample
    assert f"analyze: {n_sample} particles" in capsys.readouterr().out
    assert (out / "fabric.json").exists()


# -------------------------------------------------------------------- writer checks
def test_writer_refuses_bad_input_with_clear_messages(tmp_path):
    with ResultsWriter(tmp_path / "run.h5") as out:
        with pytest.raises(
            TypeError, match=r"config\['a'\]\[1\]: cannot store a value of type set"
        ):
            out.write_config({"a": [1, {2, 3}]})
        with pytest.raises(TypeError, match=r"config\['a'\]: key 1 is not a string"):
            out.write_config({"a": {1: 2}})
        out.append_timeseries({"t": 0.0, "q": 1.0})
        with pytest.raises(ValueError, match=r"missing \['q'\], unexpected \['p'\]"):
            out.append_timeseries({"t": 1.0, "p": 1.0})
        with pytest.raises(ValueError, match="different lengths"):
            out.append_rows({"t": [1.0, 2.0], "q": [1.0]})
        with pytest.raises(ValueError, match=r"timeseries\['q'\]: expected 1D"):
            out.append_rows({"t": [1.0], "q": [[1.0]]})
        with pytest.raises(ValueError, match="cannot add columns"):
            out.define_timeseries({"new": "Pa"})
        with pytest.raises(ValueError, match="snapshot name: 'a/b' is not a valid name"):
            out.write_snapshot("a/b", rich_snapshot())
        out.write_snapshot("s", rich_snapshot())
        with pytest.raises(ValueError, match="'s' already written"):
            out.write_snapshot("s", rich_snapshot())
        out.write_snapshot("s", rich_snapshot(seed=9), overwrite=True)
        bad = Snapshot(np.zeros((1, 2)), np.ones(1), metadata={"when": object()})
        with pytest.raises(
            TypeError, match=r"snapshot.metadata\['when'\]: cannot store a value of type object"
        ):
            out.write_snapshot("bad", bad)
        with pytest.raises(ValueError, match="finalize\\(\\) marks a run 'complete'"):
            out.set_status("complete")  # type: ignore[arg-type]
        with pytest.raises(ValueError, match="phases: wall times must be finite"):
            out.write_phases({"a": -1.0})
        assert out.columns == ["t", "q"] and out.n_rows == 1
        assert out.snapshot_names == ["s"]
    res = read_results(tmp_path / "run.h5")
    assert res.snapshot_names == ["s"]  # the refused 'bad' snapshot left nothing behind
    assert_same_snapshot(res.snapshot("s"), rich_snapshot(seed=9))
    assert {k: v.tolist() for k, v in res.timeseries.items()} == {"t": [0.0], "q": [1.0]}
    with pytest.raises(FileExistsError, match="overwrite=True"):
        ResultsWriter(tmp_path / "run.h5")
    with pytest.raises(ValueError, match="writer is closed"):
        out.append_timeseries({"t": 0.0, "q": 1.0})


# --------------------------------------------------------------------- layout versions
def write_v1_by_hand(path) -> None:
    """A version-1 file written from docs/file-formats.md alone, without ResultsWriter."""
    s = h5py.string_dtype()
    with h5py.File(path, "w") as f:
        f.attrs.update(
            format="grainlab-results",
            format_version=1,
            grainlab_version="0.1.0",
            created="2025-01-01T00:00:00+00:00",
            kind="biaxial",
            status="complete",
        )
        f.create_group("config").create_dataset("json", data='{"seed": 7}', dtype=s)
        ts = f.create_group("timeseries")
        ts.attrs["columns"] = np.array(["axial_strain", "q"], dtype=s)
        ts.attrs["n_rows"] = 2
        ts.create_dataset("axial_strain", data=[0.0, 0.001], maxshape=(None,))
        ts.create_dataset("q", data=[0.0, 1.5e5]).attrs["units"] = "Pa"
        g = f.create_group("snapshots").create_group("strain_0.0010")
        g.attrs.update(index=0, time=0.5, axial_strain=0.001, periodic=[0, 0])
        g.create_dataset("positions", data=[[0.0, 0.0], [2e-3, 0.0]])
        g.create_dataset("radii", data=[1e-3, 1e-3])
        g.create_dataset("contact_i", data=[0, 1])
        g.create_dataset("contact_j", data=[1, -1])
        g.create_dataset("contact_point", data=[[1e-3, 0.0], [3e-3, 0.0]])
        g.create_dataset("normal_force", data=[1.0, 2.0])
        g.create_group("contact_fields").create_dataset("sliding", data=[False, True])
        f.create_group("summary").create_dataset("json", data='{"peak": 2.0}', dtype=s)
        ph = f.create_group("phases")
        ph.create_dataset("name", data=np.array(["shearing"], dtype=s))
        ph.create_dataset("wall_time", data=[1.5])


def test_a_version_1_file_written_from_the_docs_is_read(tmp_path):
    path = tmp_path / "run.h5"
    write_v1_by_hand(path)
    res = read_results(path)
    assert res.config == {"seed": 7} and res.summary == {"peak": 2.0}
    assert res.timeseries["q"].tolist() == [0.0, 1.5e5]
    assert res.timeseries_units == {"axial_strain": "", "q": "Pa"}
    assert res.phases == {"shearing": 1.5}
    snap = read_snapshot(path)
    assert snap.n_contacts == 2 and snap.wall_ids.tolist() == [-1, 0]
    assert snap.contact_fields["sliding"].tolist() == [False, True]
    assert snap.axial_strain == 0.001 and snap.ids.tolist() == [0, 1]
    np.testing.assert_allclose(snap.contact_normals(), [[1.0, 0.0], [1.0, 0.0]])


def test_a_version_2_file_reads_with_every_particle_a_grain_of_its_own(tmp_path):
    """Files written before grains (layout 2, the same snapshot groups as layout 1)."""
    path = tmp_path / "run.h5"
    write_v1_by_hand(path)
    with h5py.File(path, "r+") as f:
        f.attrs["format_version"] = 2
        f["snapshots/strain_0.0010"].create_dataset("rotations", data=[0.25, -1.5])
    snap = read_results(path).snapshot("strain_0.0010")
    assert snap.grains().tolist() == [0, 1] and snap.n_grains == 2
    assert snap.grain_centroids().tolist() == [[0.0, 0.0], [2e-3, 0.0]]
    assert snap.grain_angles().tolist() == [0.25, -1.5]
    assert "grain" not in snap.particle_fields


def test_future_version_is_refused_naming_the_version(tmp_path):
    path = tmp_path / "run.h5"
    write_v1_by_hand(path)
    with h5py.File(path, "r+") as f:
        f.attrs["format_version"] = 7
    with pytest.raises(UnsupportedVersionError, match="format_version 7 is newer than this"):
        read_results(path)
    with pytest.raises(UnsupportedVersionError, match="format_version 7"):
        read_snapshot(path)
    with h5py.File(path, "r+") as f:
        f.attrs["format_version"] = 0
    with pytest.raises(
        ResultsFileError, match=r"format_version 0 is unknown \(known versions: 1, 2, 3\)"
    ):
        read_results(path)


def test_readers_dispatch_on_version_so_old_layouts_stay_readable(tmp_path, monkeypatch):
    """A later layout adds a reader; version-1 files still go to the version-1 reader."""
    path = tmp_path / "run.h5"
    write_v1_by_hand(path)
    v1 = _READERS_BY_VERSION[1]
    seen = []

    def v2_reader(f, p, allow):
        seen.append("v2")
        return v1.read_results(f, p, allow)

    monkeypatch.setitem(
        _READERS_BY_VERSION, 2, type(v1)(v2_reader, v1.list_snapshots, v1.read_snapshot)
    )
    assert read_results(path).config == {"seed": 7} and seen == []
    with h5py.File(path, "r+") as f:
        f.attrs["format_version"] = 2
    assert read_results(path).format_version == 2 and seen == ["v2"]


def test_other_hdf5_files_are_refused_clearly(tmp_path):
    plain = tmp_path / "plain.h5"
    with h5py.File(plain, "w") as f:
        f["x"] = 1
    with pytest.raises(ResultsFileError, match="not a grainlab file .*no 'format' attribute"):
        read_results(plain)
    with pytest.raises(FileFormatError, match="plain.h5: not a grainlab file"):
        read_snapshot(plain)
    cp = write_checkpoint(tmp_path / "checkpoint.h5", b"state", {"phase": "x"})
    with pytest.raises(ResultsFileError, match=r"is a checkpoint .*use read_checkpoint\(\)"):
        read_results(cp)
    with pytest.raises(ResultsFileError, match="file not found"):
        read_results(tmp_path / "missing.h5")


def test_hdf5_reader_is_registered():
    from grainlab.io import READERS

    assert READERS["grainlab-hdf5"] is read_hdf5_snapshot


def test_snapshot_strain_reads_the_record_then_the_name_then_gives_nan(tmp_path):
    from grainlab.io.hdf5 import snapshot_strain

    pos, rad = np.array([[0.0, 0.0], [3e-3, 0.0]]), np.array([1e-3, 1e-3])
    with ResultsWriter(tmp_path / "run.h5", kind="biaxial") as out:
        # recorded 0.01512 under the rounded name strain_0.0151: the record wins
        out.write_snapshot(snapshot_name(0.01512), Snapshot.from_geometry(pos, rad, axial_strain=0.01512))
        out.write_snapshot(snapshot_name(0.03), Snapshot.from_geometry(pos, rad))  # no record: the name's 0.03
        out.write_snapshot(snapshot_name(0.3, prefix="gamma"), Snapshot.from_geometry(pos, rad))  # a shear strain
        out.write_snapshot("initial", Snapshot.from_geometry(pos, rad))
    strains = {info.name: snapshot_strain(info) for info in read_results(tmp_path / "run.h5").snapshots}
    assert strains["strain_0.0151"] == 0.01512
    assert strains["strain_0.0300"] == 0.03
    assert np.isnan(strains["gamma_0.3000"]) and np.isnan(strains["initial"])
