"""The compiled analysis kernels against their NumPy references (docs/analysis.md, "Speed").

Contact detection must find exactly the reference's pairs in the same order;
lambda, Z, Z_m, the rattlers, the histograms, the anisotropies and the fabric
tensor must agree to round-off, on random packings, lattices with known
answers, periodic boxes, walls and membrane chains, 0/1-contact grains and
empty input; and no result may depend on the number of threads.
"""

from __future__ import annotations

import re

import numpy as np
import pytest
from factories_analysis import grain_on_membrane, hex_lattice, jittered_packing, square_lattice

from grainlab import _kernels
from grainlab.analysis import ContactAnisotropy, CoordinationNumber, StabilityIndex
from grainlab.analysis.fabric import angular_histogram, anisotropy_fourier, fabric_tensor, rattlers
from grainlab.analysis.stability import stability_index
from grainlab.snapshot import ParticleKind, Snapshot, detect_contacts

MEASURES = {
    "lambda": lambda: StabilityIndex(),
    "lambda each": lambda: StabilityIndex(boundary="each"),
    "lambda no boundary": lambda: StabilityIndex(include_boundary=False),
    "Z": lambda: CoordinationNumber(),
    "Z boundary": lambda: CoordinationNumber(include_boundary=True),
    "Z boundary each": lambda: CoordinationNumber(include_boundary=True, boundary="each"),
    "Z min 3": lambda: CoordinationNumber(min_contacts=3),
    "a": lambda: ContactAnisotropy(),
    "a boundary": lambda: ContactAnisotropy(include_boundary=True),
    "a_n": lambda: ContactAnisotropy(weight="normal_force"),
}


def random_disks(
    n: int, seed: int, *, density: float = 0.8
) -> tuple[np.ndarray, np.ndarray, float]:
    """n polydisperse disks (radii 0.25-1.5 mm) placed at random in a square of side L."""
    rng = np.random.default_rng(seed)
    radii = rng.uniform(0.25e-3, 1.5e-3, n)
    side = float(np.sqrt(np.pi * np.sum(radii**2) / density))
    return rng.uniform(0.0, side, (n, 2)), radii, side


def results(measure, snapshot: Snapshot) -> dict[str, object]:
    """Every result of a computed measure, by name."""
    measure.compute(snapshot)
    return dict(vars(measure._results))


def assert_same(new: dict, old: dict, *, exact: bool = False) -> None:
    assert new.keys() == old.keys()
    for key, value in old.items():
        if isinstance(value, Snapshot):
            continue
        got = new[key]
        size = old.get(key.replace("direction", "anisotropy"))
        if key.startswith("direction") and size is not None and not size > 1e-9:
            continue  # the direction of a vanishing anisotropy is round-off
        if exact or np.asarray(value).dtype.kind in "biu":
            np.testing.assert_array_equal(got, value, err_msg=key)
        else:
            np.testing.assert_allclose(got, value, rtol=1e-12, atol=1e-14, err_msg=key)


def both_ways(make_measure, snapshot_factory) -> tuple[dict, dict]:
    """Results of the compiled and the reference path, each on a fresh snapshot."""
    new = results(make_measure(), snapshot_factory())
    with _kernels.numpy_reference():
        old = results(make_measure(), snapshot_factory())
    return new, old


# --------------------------------------------------------------------------- detection
@pytest.mark.parametrize("periodic", [(False, False), (True, False), (False, True), (True, True)])
@pytest.mark.parametrize("tolerance", [0.0, 2e-4])
def test_detection_finds_the_reference_pairs_in_order(periodic, tolerance):
    pos, rad, side = random_disks(3000, seed=1)
    box = [[-0.3 * side, 0.7 * side], [0.1 * side, 1.1 * side]]  # positions outside the box wrap
    new = detect_contacts(pos, rad, tolerance=tolerance, box=box, periodic=periodic)
    with _kernels.numpy_reference():
        old = detect_contacts(pos, rad, tolerance=tolerance, box=box, periodic=periodic)
    assert new[0].size > 3000
    assert new[0].dtype == np.int64 and new[1].dtype == np.int64
    np.testing.assert_array_equal(new[0], old[0])
    np.testing.assert_array_equal(new[1], old[1])


def test_detection_of_spheres_periodic_in_x():
    rng = np.random.default_rng(5)
    pos, rad, side = random_disks(1500, seed=2)
    pos3 = np.c_[pos, rng.uniform(0.0, 2e-3, len(pos))]
    box = [[0.0, side], [0.0, side]]
    new = detect_contacts(pos3, rad, box=box, periodic=(True, False))
    with _kernels.numpy_reference():
        old = detect_contacts(pos3, rad, box=box, periodic=(True, False))
    assert new[0].size > 500
    np.testing.assert_array_equal(np.c_[new], np.c_[old])


def test_small_periodic_boxes_count_each_pair_once():
    # boxes of one to four cut-offs across: the cell list has one, three or four cells
    rng = np.random.default_rng(3)
    for side in (3.5, 7.0, 10.0, 13.0):
        pos = rng.uniform(0.0, side, (40, 2))
        rad = rng.uniform(0.5, 1.5, 40)
        box = [[0.0, side], [0.0, side]]
        new = detect_contacts(pos, rad, tolerance=0.1, box=box, periodic=(True, True))
        with _kernels.numpy_reference():
            old = detect_contacts(pos, rad, tolerance=0.1, box=box, periodic=(True, True))
        np.testing.assert_array_equal(np.c_[new], np.c_[old])


@pytest.mark.parametrize("factory, z", [(hex_lattice, 6.0), (square_lattice, 4.0)])
def test_lattices_of_touching_disks(factory, z):
    snap = factory(10, 10)
    assert CoordinationNumber().compute(snap).coordination_number == z
    lam = StabilityIndex().compute(snap)
    assert np.abs(lam.stability_index).max() < 1e-12
    assert ContactAnisotropy().compute(snap).anisotropy < 1e-12


def test_detection_of_few_disks_and_none_touching():
    for n in (0, 1):
        i, j = detect_contacts(np.zeros((n, 2)), np.ones(n))
        assert i.size == j.size == 0 and i.dtype == np.int64
    i, j = detect_contacts([[0.0, 0.0], [3.0, 0.0]], [1.0, 1.0])
    assert i.size == 0
    # exactly touching disks need a tolerance, as in the reference
    assert detect_contacts([[0.0, 0.0], [2.0, 0.0]], [1.0, 1.0])[0].size == 0
    assert detect_contacts([[0.0, 0.0], [2.0, 0.0]], [1.0, 1.0], tolerance=1e-12)[0].size == 1


@pytest.mark.parametrize(
    "positions, radii, kwargs, field",
    [
        ([[0.0, np.nan], [1.0, 0.0]], [1.0, 1.0], {}, "positions[0]"),
        ([[0.0, 0.0], [1.0, 0.0]], [1.0, -1.0], {}, "radii[1]"),
        ([[0.0, 0.0], [1.0, 0.0]], [1.0, 0.0], {}, "radii[1]"),
        ([[0.0, 0.0], [1.0, 0.0]], [1.0], {}, "radii"),
        ([[0.0], [1.0]], [1.0, 1.0], {}, "positions"),
        ([[0.0, 0.0], [1.0, 0.0]], [1.0, 1.0], {"periodic": (True, False)}, "box"),
        ([[0.0, 0.0], [1.0, 0.0]], [1.0, 1.0], {"tolerance": -1.0}, "tolerance"),
        ([[0.0, 0.0], [1.0, 0.0]], [1.0, 1.0], {"tolerance": np.inf}, "tolerance"),
    ],
)
def test_detection_rejects_bad_input_by_name(positions, radii, kwargs, field):
    with pytest.raises(ValueError, match="^" + re.escape(field)):
        detect_contacts(positions, radii, **kwargs)


# --------------------------------------------------------------------------- measures
def periodic_random_snapshot() -> Snapshot:
    pos, rad, side = random_disks(2500, seed=7, density=0.85)
    return Snapshot.from_geometry(
        pos, rad, box=[[0.0, side], [0.0, side]], periodic=(True, True), tolerance=1e-5
    )


def forced_packing() -> Snapshot:
    snap = jittered_packing(30, 30, seed=4)
    rng = np.random.default_rng(4)
    return snap.with_contacts(
        snap.contact_i, snap.contact_j, normal_force=rng.uniform(0.0, 5.0, snap.n_contacts)
    )


def bounded_packing() -> Snapshot:
    """A packing on a floor (wall 0) and against a membrane chain on its left:
    grains with wall contacts, a boundary body touched several times, rattlers."""
    snap = jittered_packing(24, 20, seed=9)
    pos = np.asarray(snap.positions)
    rad = np.asarray(snap.radii)
    kind = np.where(pos[:, 0] < 1.2e-3, ParticleKind.MEMBRANE, ParticleKind.SOIL)
    body = np.where(kind == ParticleKind.MEMBRANE, (pos[:, 1] > 8e-3).astype(int), -1)
    floor = np.flatnonzero(pos[:, 1] < 0.6e-3)
    rng = np.random.default_rng(9)
    ci = np.r_[snap.contact_i, floor]
    cj = np.r_[snap.contact_j, np.full(floor.size, -1)]
    point = np.zeros((ci.size, 2))
    point[-floor.size :] = np.c_[pos[floor, 0], pos[floor, 1] - rad[floor]]
    return Snapshot(
        pos,
        rad,
        kind=kind,
        contact_i=ci,
        contact_j=cj,
        contact_point=point,
        normal_force=rng.uniform(0.0, 3.0, ci.size),
        particle_fields={"body": body},
    )


SNAPSHOTS = {
    "periodic random": periodic_random_snapshot,
    "jittered with forces": forced_packing,
    "walls and membrane": bounded_packing,
    "grain on membrane": lambda: grain_on_membrane(forces=np.arange(1.0, 8.0)),
    "hex lattice": lambda: hex_lattice(8, 8),
    "empty": lambda: Snapshot(np.zeros((0, 2)), np.zeros(0), normal_force=np.zeros(0)),
    "no contacts": lambda: Snapshot([[0.0, 0.0], [5.0, 0.0]], [1.0, 1.0], normal_force=np.zeros(0)),
}


@pytest.mark.parametrize("snapshot", SNAPSHOTS)
@pytest.mark.parametrize("measure", MEASURES)
def test_measures_equal_the_numpy_reference(snapshot, measure):
    factory = SNAPSHOTS[snapshot]
    if measure == "a_n" and factory().normal_force is None:
        pytest.skip("no forces")
    new, old = both_ways(MEASURES[measure], factory)
    assert_same(new, old)


def test_zero_and_one_contact_grains_have_lambda_one():
    # particle 0 with two contacts, 1 and 2 with one each, 3 with none
    snap = Snapshot(
        [[0.0, 0.0], [2.0, 0.0], [0.0, 2.0], [9.0, 9.0]],
        np.ones(4),
        contact_i=[0, 0],
        contact_j=[1, 2],
    )
    lam = StabilityIndex().compute(snap)
    np.testing.assert_array_equal(lam.n_contacts, [2, 1, 1, 0])
    np.testing.assert_allclose(lam.stability_index, [0.25, 1.0, 1.0, 1.0], rtol=0, atol=1e-15)
    assert lam.mean == pytest.approx(0.25) and lam.mean_all == pytest.approx(3.25 / 4)
    assert CoordinationNumber().compute(snap).rattlers.all()


def test_functions_equal_the_numpy_reference():
    rng = np.random.default_rng(11)
    angles = rng.uniform(-10.0, 10.0, 50_000)
    weights = rng.uniform(0.0, 2.0, angles.size)
    owner = rng.integers(0, 9000, angles.size)
    lattice = np.radians(np.arange(0.0, 360.0, 20.0))  # on the bin edges
    normals = np.c_[np.cos(angles), np.sin(angles)]
    cases = [
        lambda: stability_index(owner, angles, 9000),
        lambda: angular_histogram(angles, 18, weights),
        lambda: angular_histogram(lattice, 18),
        lambda: angular_histogram(angles, 7, edge_tolerance=0.0),
        lambda: anisotropy_fourier(angles, weights),
        lambda: anisotropy_fourier(angles[:0]),
        lambda: fabric_tensor(normals, weights),
        lambda: fabric_tensor(normals[:0]),
    ]
    for case in cases:
        new = case()
        with _kernels.numpy_reference():
            old = case()
        new, old = (v if isinstance(v, tuple) else (v,) for v in (new, old))
        for a, b in zip(new, old, strict=True):
            np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12)
    ci = rng.integers(0, 3000, 4000)
    cj = (ci + rng.integers(1, 3000, ci.size)) % 3000
    cj[::50] = -1  # walls
    for k in (2, 3, 4):
        candidates = rng.random(3000) < 0.9
        new = rattlers(ci, cj, 3000, min_contacts=k, candidates=candidates)
        with _kernels.numpy_reference():
            old = rattlers(ci, cj, 3000, min_contacts=k, candidates=candidates)
        assert 0 < new.sum() < 3000
        np.testing.assert_array_equal(new, old)


def test_kernels_reject_bad_input_by_name():
    with pytest.raises(ValueError, match="^owner"):
        stability_index([0, 5], [0.0, 1.0], 3)
    with pytest.raises(ValueError, match=r"^angles\[1\]"):
        stability_index([0, 1], [0.0, np.nan], 3)
    with pytest.raises(ValueError, match="^bins"):
        angular_histogram([0.0], 1)
    with pytest.raises(ValueError, match="^contact_j"):
        rattlers([0, 1], [1, 7], 3)
    with pytest.raises(ValueError, match="^threads"):
        with _kernels.kernel_threads(0):
            pass


# --------------------------------------------------------------------------- threads
def test_results_do_not_depend_on_the_thread_count():
    # enough disks and contacts for many pieces of parallel work (16,384 each)
    pos, rad, side = random_disks(60_000, seed=13, density=0.86)
    box = [[0.0, side], [0.0, side]]
    runs = []
    for threads in (1, 2):
        with _kernels.kernel_threads(threads):
            snap = Snapshot.from_geometry(pos, rad, box=box, periodic=(True, False))
            snap = snap.with_contacts(
                snap.contact_i, snap.contact_j, normal_force=np.linspace(0.0, 1.0, snap.n_contacts)
            )
            out = {"i": snap.contact_i, "j": snap.contact_j, "normals": snap.contact_normals()}
            for name, make in MEASURES.items():
                out.update({f"{name}: {k}": v for k, v in results(make(), snap).items()})
            runs.append(out)
    assert runs[0]["i"].size > 4 * 16_384
    assert runs[0].keys() == runs[1].keys()
    for key, value in runs[0].items():
        if not isinstance(value, Snapshot):
            np.testing.assert_array_equal(runs[1][key], value, err_msg=key)
