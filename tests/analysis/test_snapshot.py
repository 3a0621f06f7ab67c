"""The Snapshot data model: validation, contact detection, engine constructor."""

from __future__ import annotations

import numpy as np
import pytest

from grainlab.snapshot import (
    ParticleKind,
    Snapshot,
    boundary_end_groups,
    detect_contacts,
    wall_code,
)


def three_disks(**kw):
    return Snapshot([[0, 0], [1e-3, 0], [0, 1e-3]], [0.5e-3] * 3, **kw)


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        (dict(positions=[[0, 0, 0]], radii=[1.0]), "positions"),
        (dict(positions=[[0, np.nan]], radii=[1.0]), "positions"),
        (dict(positions=[[0, 0]], radii=[-1.0]), "radii"),
        (dict(positions=[[0, 0]], radii=[0.0]), "radii"),
        (dict(positions=[[0, 0]], radii=[1.0, 2.0]), "radii"),
        (dict(positions=[[0, 0], [1, 1]], radii=[1.0, 1.0], ids=[7, 7]), "ids"),
        (dict(positions=[[0, 0], [1, 1]], radii=[1.0, 1.0], ids=[1.5, 2]), "ids"),
        (
            dict(positions=[[0, 0], [1, 1]], radii=[1.0, 1.0], contact_i=[0], contact_j=[2]),
            "contact_j",
        ),
        (
            dict(positions=[[0, 0], [1, 1]], radii=[1.0, 1.0], contact_i=[-1], contact_j=[1]),
            "contact_i",
        ),
        (
            dict(positions=[[0, 0], [1, 1]], radii=[1.0, 1.0], contact_i=[1], contact_j=[1]),
            "contact_j",
        ),
        (dict(positions=[[0, 0], [1, 1]], radii=[1.0, 1.0], contact_i=[0]), "contact_i"),
        (
            dict(positions=[[0, 0], [1, 1]], radii=[1.0, 1.0], contact_i=[0], contact_j=[-1]),
            "contact_normal",
        ),
        (
            dict(
                positions=[[0, 0], [1, 1]],
                radii=[1.0, 1.0],
                contact_i=[0],
                contact_j=[1],
                contact_normal=[[2, 0]],
            ),
            "contact_normal",
        ),
        (
            dict(
                positions=[[0, 0], [1, 1]],
                radii=[1.0, 1.0],
                contact_i=[0],
                contact_j=[1],
                normal_force=[np.inf],
            ),
            "normal_force",
        ),
        (
            dict(
                positions=[[0, 0], [1, 1]],
                radii=[1.0, 1.0],
                contact_i=[0],
                contact_j=[1],
                shear_force=[1, 2],
            ),
            "shear_force",
        ),
        (dict(positions=[[0, 0]], radii=[1.0], kind=[5]), "kind"),
        (dict(positions=[[0, 0]], radii=[1.0], rotations=[np.nan]), "rotations"),
        (dict(positions=[[0, 0]], radii=[1.0], periodic=(True, False)), "box"),
        (dict(positions=[[0, 0]], radii=[1.0], box=[[1, 0], [0, 1]]), "box"),
        (dict(positions=[[0, 0]], radii=[1.0], particle_fields={"v": [1, 2]}), "particle_fields"),
        (dict(positions=[[0, 0]], radii=[1.0], particle_fields={"body": [-2]}), "particle_fields"),
        (dict(positions=[[0, 0]], radii=[1.0], particle_fields={"body": [0.5]}), "particle_fields"),
    ],
)
def test_validation_names_the_field(kwargs, field):
    with pytest.raises(ValueError, match=rf"^{field}"):
        Snapshot(**kwargs)


def test_arrays_are_read_only_views_and_defaults():
    pos = np.array([[0.0, 0.0], [1e-3, 0.0]])
    snap = Snapshot(pos, [0.5e-3, 0.5e-3])
    with pytest.raises(ValueError):
        snap.positions[0, 0] = 1.0
    pos[0, 0] = 5.0  # the caller's array stays writable
    np.testing.assert_array_equal(snap.ids, [0, 1])
    np.testing.assert_array_equal(snap.kind, [ParticleKind.SOIL] * 2)
    assert snap.n_contacts == 0 and snap.contact_i.dtype == np.int64


def test_detect_contacts_matches_brute_force(rng):
    n = 400
    pos = rng.uniform(0, 20e-3, (n, 2))
    rad = rng.uniform(0.3e-3, 1.0e-3, n)
    i, j = detect_contacts(pos, rad)
    d = np.hypot(*(pos[:, None, :] - pos[None, :, :]).transpose(2, 0, 1))
    bi, bj = np.nonzero(np.triu(d < rad[:, None] + rad[None, :], 1))
    np.testing.assert_array_equal(i, bi)
    np.testing.assert_array_equal(j, bj)
    assert i.size > 100


def test_detect_contacts_of_spheres_periodic_in_x(rng):
    # spheres (N, 3), x periodic, y and z not: as the readers' projection of 3D data uses it
    n = 300
    box = np.array([[0.0, 20e-3], [0.0, 20e-3]])
    pos = rng.uniform(0, 20e-3, (n, 3))
    rad = rng.uniform(0.5e-3, 1.5e-3, n)
    i, j = detect_contacts(pos, rad, box=box, periodic=(True, False))
    d = pos[:, None, :] - pos[None, :, :]
    d[..., 0] -= 20e-3 * np.round(d[..., 0] / 20e-3)
    bi, bj = np.nonzero(np.triu(np.linalg.norm(d, axis=2) < rad[:, None] + rad[None, :], 1))
    np.testing.assert_array_equal(np.c_[i, j], np.c_[bi, bj])
    flat_i, _ = detect_contacts(pos[:, :2], rad, box=box, periodic=(True, False))
    assert 50 < i.size < flat_i.size / 2  # the projected disks touch far more often


def test_touching_tolerance():
    pos = [[0.0, 0.0], [1.0e-3 + 1e-9, 0.0]]
    assert detect_contacts(pos, [0.5e-3, 0.5e-3])[0].size == 0
    assert detect_contacts(pos, [0.5e-3, 0.5e-3], tolerance=2e-9)[0].size == 1
    with pytest.raises(ValueError, match="tolerance"):
        detect_contacts(pos, [0.5e-3, 0.5e-3], tolerance=-1.0)


def test_periodic_detection_and_normals():
    box = [[0.0, 10e-3], [0.0, 10e-3]]
    snap = Snapshot.from_geometry(
        [[0.2e-3, 5e-3], [9.6e-3, 5e-3], [5e-3, 5e-3]],
        [0.5e-3] * 3,
        box=box,
        periodic=(True, False),
    )
    np.testing.assert_array_equal(snap.contact_i, [0])
    np.testing.assert_array_equal(snap.contact_j, [1])
    # minimum image: from particle 0 the partner sits just to the left
    np.testing.assert_allclose(snap.contact_normals(), [[-1.0, 0.0]], atol=1e-12)
    assert np.degrees(snap.contact_angles()[0]) == pytest.approx(180.0)
    flat = Snapshot.from_geometry(snap.positions, snap.radii, box=box, periodic=(False, False))
    assert flat.n_contacts == 0


def test_wall_codes_and_boundary_masks():
    snap = three_disks(
        kind=[0, 0, ParticleKind.MEMBRANE],
        contact_i=[0, 0, 1],
        contact_j=[1, 2, wall_code(3)],
        contact_point=[[0.5e-3, 0], [0, 0.5e-3], [1e-3, -0.5e-3]],
    )
    np.testing.assert_array_equal(snap.is_wall_contact, [False, False, True])
    np.testing.assert_array_equal(snap.wall_ids, [-1, -1, 3])
    np.testing.assert_array_equal(snap.is_boundary_contact, [False, True, True])
    np.testing.assert_allclose(np.degrees(snap.contact_angles()), [0, 90, 270])
    np.testing.assert_array_equal(snap.contact_counts(), [2, 2, 1])
    np.testing.assert_array_equal(snap.contact_counts(include_boundary=False), [1, 1, 0])
    with pytest.raises(ValueError, match="wall_id"):
        wall_code(-1)


def chains(gap: float = 0.5):
    """Two membrane chains (disks 1-3 and 4-5, neighbours overlapping) and grain 0
    touching disk 2 and disk 4; ``gap`` is the chains' spacing in diameters."""
    d = 1e-3
    y = np.arange(3) * gap * d
    pos = np.vstack([[[1.0 * d, 0.5 * d]], np.c_[np.zeros(3), y], np.c_[np.full(2, 2 * d), y[:2]]])
    kind = [0] + [ParticleKind.MEMBRANE] * 5
    return Snapshot(pos, [0.6 * d] + [0.5 * d] * 5, kind=kind, contact_i=[0, 4, 0], contact_j=[2, 0, -3],
                    contact_normal=[[-1, 0], [-1, 0], [0, -1]])


def test_boundary_bodies_from_labels_or_geometry():
    snap = chains()
    np.testing.assert_array_equal(snap.boundary_bodies(), [-1, 0, 0, 0, 1, 1])
    # spaced beyond touching, every disk is a body of its own
    np.testing.assert_array_equal(chains(gap=1.01).boundary_bodies(), [-1, 0, 1, 2, 3, 4])
    # stored labels win; an unlabelled membrane disk becomes a body of its own
    labelled = snap.with_boundary_bodies([-1, 7, 7, -1, 3, 3])
    np.testing.assert_array_equal(labelled.boundary_bodies(), [-1, 7, 7, 8, 3, 3])
    # keys: wall w -> 2w, chain b -> 2b + 1; -1 where the far side is no boundary body
    np.testing.assert_array_equal(snap.boundary_body_keys(), [[1, -1], [-1, 3], [4, -1]])
    np.testing.assert_array_equal(snap.contact_counts(), [3, 0, 1, 0, 1, 0])
    same_chain = snap.with_boundary_bodies([-1, 0, 0, 0, 0, 0])
    np.testing.assert_array_equal(same_chain.contact_counts(), [2, 0, 1, 0, 1, 0])
    np.testing.assert_array_equal(same_chain.contact_counts(boundary="each"), [3, 0, 1, 0, 1, 0])
    assert "body" in same_chain.particle_fields
    with pytest.raises(ValueError, match="boundary"):
        snap.contact_counts(boundary="chains")


def test_boundary_end_groups():
    np.testing.assert_array_equal(
        boundary_end_groups([0, 0, 1, 0, 1, 2], [3, -1, 3, 3, -1, 5]), [0, 1, 2, 0, 4, 5]
    )
    assert boundary_end_groups([], []).size == 0


def test_index_of_and_select_contacts():
    snap = three_disks(
        ids=[30, 10, 20], contact_i=[0, 0], contact_j=[1, 2], normal_force=[1.0, 2.0]
    )
    np.testing.assert_array_equal(snap.index_of([20, 30, 99]), [2, 0, -1])
    sub = snap.select_contacts([False, True])
    np.testing.assert_array_equal(sub.contact_j, [2])
    np.testing.assert_array_equal(sub.normal_force, [2.0])


def test_from_engine_arrays_merges_particle_and_wall_contacts():
    snap = Snapshot.from_engine_arrays(
        [[0, 0], [1e-3, 0]],
        [0.5e-3, 0.5e-3],
        ids=[5, 6],
        contact_i=[0],
        contact_j=[1],
        contact_point=[[0.5e-3, 0]],
        contact_normal=[[1.0, 0.0]],
        overlap=[1e-6],
        normal_force=[84.5],
        shear_force=[-3.0],
        sliding=[True],
        bonded=[False],
        wall_i=[0, 1],
        wall_id=[2, 0],
        wall_point=[[0, -0.5e-3], [1e-3, -0.5e-3]],
        wall_normal=[[0.0, -1.0], [0.0, -1.0]],
        wall_normal_force=[10.0, 12.0],
        wall_shear_force=[0.0, 0.0],
        wall_overlap=[1e-7, 2e-7],
        time=0.5,
    )
    np.testing.assert_array_equal(snap.contact_i, [0, 0, 1])
    np.testing.assert_array_equal(snap.contact_j, [1, -3, -1])
    np.testing.assert_array_equal(snap.wall_ids, [-1, 2, 0])
    np.testing.assert_allclose(snap.normal_force, [84.5, 10.0, 12.0])
    np.testing.assert_allclose(snap.contact_fields["overlap"], [1e-6, 1e-7, 2e-7])
    np.testing.assert_array_equal(snap.contact_fields["sliding"], [True, False, False])
    np.testing.assert_array_equal(snap.contact_fields["bonded"], [False, False, False])
    np.testing.assert_allclose(np.degrees(snap.contact_angles()), [0, 270, 270])
    assert snap.time == 0.5
    with pytest.raises(ValueError, match="normal_force"):
        Snapshot.from_engine_arrays(
            [[0, 0], [1e-3, 0]],
            [0.5e-3] * 2,
            contact_i=[0],
            contact_j=[1],
            normal_force=[1.0],
            wall_i=[0],
            wall_id=[0],
            wall_normal=[[0, -1]],
            contact_normal=[[1, 0]],
        )
