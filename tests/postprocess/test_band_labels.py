"""The band read three ways (band_labels' ``reading``): the local strain (find_band, unchanged),
the blocks of the displacement field (Fig. 11) and the grains with lambda > 0.5 (Fig. 12), and
find_field_band: a band in any per-grain field, accepted as the strain band is."""

from __future__ import annotations

import math
from dataclasses import asdict

import numpy as np
import pytest
from test_figures import D, _grains, _membrane

import grainlab.postprocess.band as band_module
from grainlab.analysis import DisplacementBand, LocalStrain, StabilityIndex
from grainlab.postprocess.band import (
    LAMBDA_LIMIT,
    READINGS,
    band_labels,
    displacement_band,
    find_band,
    find_field_band,
    grains_only,
    lambda_indicator,
    slab_members,
)
from grainlab.snapshot import Snapshot

ANGLE = 60.0  # degrees, CCW from +x
WIDTH = 6.0 * D  # band thickness
SHEAR = 0.08  # simple shear inside the band: block B slides SHEAR * WIDTH along it


def _frame(angle: float) -> tuple[np.ndarray, np.ndarray]:
    beta = np.radians(angle)
    return np.array([np.cos(beta), np.sin(beta)]), np.array([-np.sin(beta), np.cos(beta)])


def sample(nx: int = 20, ny: int = 36, seed: int = 7) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Grains (jittered lattice) and a membrane chain around them: positions, radii, kinds."""
    rng = np.random.default_rng(seed)
    grains, radii = _grains(nx, ny, rng)
    membrane = _membrane(grains)
    pos = np.vstack([grains, membrane])
    rad = np.r_[radii, np.full(len(membrane), 0.25 * D)]
    kind = np.r_[np.zeros(len(grains), np.int8), np.ones(len(membrane), np.int8)]
    return pos, rad, kind


def across(pos: np.ndarray, kind: np.ndarray, angle: float = ANGLE) -> np.ndarray:
    """Signed distance of each particle from the line at ``angle`` through the grains' centroid."""
    return (pos - pos[kind == 0].mean(axis=0)) @ _frame(angle)[1]


@pytest.fixture(scope="module")
def sheared():
    """(reference, current, imposed share of the slip per particle): a biaxial background,
    simple shear inside a band WIDTH thick at ANGLE, small noise; membrane disks move with it."""
    rng = np.random.default_rng(11)
    pos, rad, kind = sample()
    t, _ = _frame(ANGLE)
    x = pos - pos[kind == 0].mean(axis=0)
    s = across(pos, kind)
    u = x @ np.array([[0.012, 0.0], [0.0, -0.02]]).T
    u += SHEAR * np.clip(s, -WIDTH / 2, WIDTH / 2)[:, None] * t
    current = pos + u + rng.normal(0.0, 0.003 * D, pos.shape)
    reference = Snapshot.from_geometry(pos, rad, kind=kind, tolerance=0.03 * D)
    snap = Snapshot.from_geometry(current, rad, kind=kind, tolerance=0.03 * D, axial_strain=0.02)
    return reference, snap, np.clip(s / WIDTH + 0.5, 0.0, 1.0)


def unstable_band(angle: float = ANGLE) -> tuple[Snapshot, np.ndarray]:
    """A snapshot whose grains within WIDTH / 2 of a line at ``angle`` have lost every contact
    (so lambda = 1 > 0.5), and that band's grains."""
    pos, rad, kind = sample()
    snap = Snapshot.from_geometry(pos, rad, kind=kind, tolerance=0.03 * D)
    inside = (np.abs(across(pos, kind, angle)) <= WIDTH / 2) & (kind == 0)
    ci, cj = np.asarray(snap.contact_i), np.asarray(snap.contact_j)
    keep = ~inside[ci] & ~np.where(cj >= 0, inside[np.maximum(cj, 0)], False)
    return snap.select_contacts(keep), inside


def angle_error(a: float, b: float) -> float:
    return abs((a - b + 90.0) % 180.0 - 90.0)


def test_the_strain_reading_is_the_default_and_find_bands(sheared):
    reference, current, _ = sheared
    labels = band_labels(reference, current)
    np.testing.assert_array_equal(band_labels(reference, current, "strain"), labels)
    np.testing.assert_array_equal(band_labels(reference, current, reading="strain"), labels)
    found = find_band(reference, current, StabilityIndex().compute(current))
    assert found.band is not None and found.numbers.found
    grains = np.flatnonzero(current.is_sample)
    expected = np.zeros(current.n_particles, np.int32)
    expected[grains[slab_members(found.band, current.positions[grains])]] = 1
    assert np.array_equal(labels == 1, expected == 1)
    assert not labels[~current.is_sample].any()


def test_the_displacement_reading_labels_the_zone_between_the_blocks(sheared):
    reference, current, share = sheared
    labels = band_labels(reference, current, reading="displacement")
    assert set(np.unique(labels)) == {0, 1}  # no conjugate band
    assert not labels[~current.is_sample].any()  # membrane disks are no grains
    moved = displacement_band(reference, current)
    assert isinstance(moved, DisplacementBand) and moved.found, moved and moved.reason
    assert angle_error(moved.angle_degrees, ANGLE) < 1.0
    assert moved.slip == pytest.approx(SHEAR * WIDTH, rel=0.05)  # block B's jump along the band
    assert moved.thickness == pytest.approx(0.8 * WIDTH, abs=0.5 * moved.mean_diameter)
    grains = np.flatnonzero(current.is_sample)
    np.testing.assert_array_equal(labels[grains] == 1, moved.members)
    # the transition zone, up to grains within one bin (half a mean diameter) of its edges
    zone = (share > 0.1) & (share < 0.9) & current.is_sample
    differ = (labels == 1) ^ zone
    to_edge = np.minimum(np.abs(share - 0.1), np.abs(share - 0.9)) * WIDTH
    assert np.all(to_edge[differ] < 0.5 * moved.mean_diameter)


def test_the_displacement_reading_matches_grains_by_id(sheared):
    reference, current, _ = sheared
    order = np.random.default_rng(3).permutation(current.n_particles)
    shuffled = Snapshot(current.positions[order], current.radii[order], current.ids[order], kind=current.kind[order])
    labels = band_labels(reference, shuffled, reading="displacement")
    np.testing.assert_array_equal(labels, band_labels(reference, current, reading="displacement")[order])


def test_the_lambda_reading_labels_the_unstable_grains():
    snap, inside = unstable_band()
    stability = StabilityIndex().compute(snap)
    indicator = lambda_indicator(stability)
    assert LAMBDA_LIMIT == 0.5 and np.all(indicator[inside] == 1.0)
    assert np.isnan(indicator[~snap.is_sample]).all()
    labels = band_labels(snap, snap, reading="lambda")  # the reference is not read
    assert not labels[~snap.is_sample].any()
    band = labels == 1
    assert np.sum(band & inside) >= 0.9 * inside.sum()
    assert np.sum(band & ~inside) <= 0.2 * inside.sum()
    found = find_field_band(snap, indicator, stability)
    assert found.numbers.found and angle_error(found.numbers.angle_deg, ANGLE) < 2.0


@pytest.mark.parametrize("angle", [30.0, 120.0])
def test_a_band_of_the_indicator_is_found_at_its_angle_and_a_random_one_is_not(angle):
    snap, inside = unstable_band(angle)
    grains = snap.is_sample
    rng = np.random.default_rng(int(angle))
    field = inside[grains].astype(float)
    flip = rng.random(field.size) < 0.05  # a few stray grains either way
    field[flip] = 1.0 - field[flip]
    found = find_field_band(snap, field, name="s", axial_strain=0.1)
    n = found.numbers
    assert n.found, n.reason
    assert angle_error(n.angle_deg, angle) < 2.0
    assert n.thickness_m == pytest.approx(WIDTH, abs=1.5 * D)
    assert n.p_value <= 0.05 and n.reason == ""
    assert (n.snapshot, n.reference, n.axial_strain) == ("s", "", 0.1)
    assert np.isnan(found.displacement).all() and found.displacement.shape == (snap.n_particles,)
    assert found.band is not None and found.band.found
    # the same share of ones, at random
    random = rng.permutation(field)
    rejected = find_field_band(snap, random)
    assert not rejected.numbers.found and rejected.band is None
    assert "best candidate" in rejected.numbers.reason or "field" in rejected.numbers.reason


def test_a_field_per_particle_or_per_grain_gives_the_same_band():
    snap, inside = unstable_band()
    stability = StabilityIndex().compute(snap)
    per_particle = find_field_band(snap, lambda_indicator(stability), stability)
    per_grain = find_field_band(snap, lambda_indicator(stability)[snap.is_sample], stability)
    assert asdict(per_particle.numbers) == asdict(per_grain.numbers)


def test_the_field_band_runs_the_strain_band_acceptance(sheared, monkeypatch):
    """The strain band is the field band of the excess local strain: one code path."""
    reference, current, _ = sheared
    stability = StabilityIndex().compute(current)
    strain = LocalStrain().compute(grains_only(reference), grains_only(current))
    calls = []
    real = band_module._accepted_band

    def spy(*args, **kwargs):
        calls.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(band_module, "_accepted_band", spy)
    by_strain = find_band(reference, current, stability)
    by_field = find_field_band(current, strain.excess_shear_strain, stability)
    assert len(calls) == 2
    assert asdict(by_field.numbers) == asdict(by_strain.numbers)
    assert by_strain.band is not None and by_field.band is not None
    assert by_field.band.angle == by_strain.band.angle and by_field.band.thickness == by_strain.band.thickness


def test_nothing_accepted_gives_all_zeros(sheared):
    reference, _, _ = sheared
    for reading in READINGS:
        labels = band_labels(reference, reference, reading=reading)  # nothing moved, all stable
        assert labels.dtype == np.int32 and labels.shape == (reference.n_particles,)
        assert not labels.any(), reading
    moved = displacement_band(reference, reference)
    assert moved is not None and not moved.found and moved.residual_reduction == 0.0
    # grains that cannot be matched: no displacement, no band
    renamed = Snapshot(reference.positions, reference.radii, reference.ids + 10**6, kind=reference.kind)
    assert displacement_band(reference, renamed) is None
    assert not band_labels(reference, renamed, reading="displacement").any()


def test_an_unknown_reading_raises():
    snap, _ = unstable_band()
    with pytest.raises(ValueError, match="^reading: must be one of 'strain', 'displacement', 'lambda'"):
        band_labels(snap, snap, reading="rotation")


def test_a_field_of_the_wrong_shape_raises():
    snap, _ = unstable_band()
    with pytest.raises(ValueError, match="^field: expected shape"):
        find_field_band(snap, np.zeros(7))


def test_too_few_grains_give_no_field_band():
    snap, _ = unstable_band()
    field = np.full(int(snap.is_sample.sum()), np.nan)
    field[:5] = 1.0
    found = find_field_band(snap, field)
    assert not found.numbers.found and "finite value of the field" in found.numbers.reason
    assert math.isnan(found.numbers.angle_deg)
