"""Shear band detection on synthetic fields with a known band."""

from __future__ import annotations

import numpy as np
import pytest
from factories_analysis import jittered_packing

from grainlab.analysis import LocalStrain, ShearBand, analyze_snapshot
from grainlab.snapshot import Snapshot


def banded(ref: Snapshot, angle_deg: float, width: float, gamma: float = 0.04):
    """Affine biaxial background plus simple shear of amount gamma inside a slab."""
    beta = np.radians(angle_deg)
    t = np.array([np.cos(beta), np.sin(beta)])
    n = np.array([-np.sin(beta), np.cos(beta)])
    x = ref.positions - ref.positions.mean(axis=0)
    s = x @ n
    background = np.array([[-0.004, 0.0], [0.0, 0.002]])  # compression along y... and x
    u = ref.positions @ background.T + gamma * np.clip(s, -width / 2, width / 2)[:, None] * t
    return Snapshot.from_geometry(ref.positions + u, ref.radii, ids=ref.ids, tolerance=0.02e-3), s


@pytest.fixture(scope="module")
def packing():
    return jittered_packing(50, 90, seed=11)  # about 50 x 78 diameters


@pytest.mark.parametrize(("angle", "width_d"), [(55.0, 8.0), (128.0, 6.0), (90.0, 10.0)])
def test_band_angle_and_thickness(packing, angle, width_d):
    d_mean = float(np.mean(packing.diameters))
    width = width_d * d_mean
    cur, s = banded(packing, angle, width)
    strain = LocalStrain().compute(packing, cur)
    band = ShearBand().compute(cur, strain.excess_shear_strain)
    diff = (band.angle_degrees - angle + 90.0) % 180.0 - 90.0
    assert abs(diff) < 2.0
    assert band.thickness == pytest.approx(width, abs=d_mean)
    assert band.thickness_diameters == pytest.approx(width_d, abs=1.0)
    # members: everything well inside the slab, nothing well outside
    assert band.members[np.abs(s) < width / 2 - d_mean].all()
    assert not band.members[np.abs(s) > width / 2 + d_mean].any()
    assert band.contrast > 0.9


def test_no_preferred_angle_bias_for_a_square_domain():
    # regular square grid: band at 30 degrees
    x, y = np.meshgrid(np.arange(60.0), np.arange(60.0))
    pos = np.c_[x.ravel(), y.ravel()]
    beta = np.radians(30.0)
    s = (pos - pos.mean(axis=0)) @ np.array([-np.sin(beta), np.cos(beta)])
    gamma = np.where(np.abs(s) < 4.0, 0.05, 0.0) + 0.001
    band = ShearBand().compute(pos, gamma, np.full(len(pos), 0.5))
    assert abs(band.angle_degrees - 30.0) < 1.0
    assert band.thickness == pytest.approx(8.0, abs=1.0)


def test_mean_lambda_inside_and_outside(packing):
    width = 8 * float(np.mean(packing.diameters))
    cur, s = banded(packing, 40.0, width)
    lam = np.where(np.abs(s) < width / 2, 0.5, 0.2)
    counts = np.full(cur.n_particles, 4)
    counts[:10] = 1  # excluded from the means
    lam[:10] = 1.0
    strain = LocalStrain().compute(packing, cur)
    band = ShearBand().compute(
        cur, strain.excess_shear_strain, stability_index=lam, n_contacts=counts
    )
    inside = band.members & (counts >= 2)
    assert band.mean_lambda_inside == pytest.approx(lam[inside].mean())
    assert band.mean_lambda_outside == pytest.approx(lam[~band.members & (counts >= 2)].mean())
    assert band.mean_lambda_inside > 0.45 and band.mean_lambda_outside < 0.25


def test_analyze_snapshot_finds_the_band(packing):
    cur, _ = banded(packing, 62.0, 7 * float(np.mean(packing.diameters)))
    result = analyze_snapshot(cur, packing)
    summary = result.summary()
    assert abs(summary["band_angle_deg"] - 62.0) < 2.0
    assert summary["band_thickness_diameters"] == pytest.approx(7.0, abs=1.0)
    assert summary["has_reference"] is True


def test_outline_segments_lie_on_the_band_edges():
    x, y = np.meshgrid(np.arange(30.0), np.arange(30.0))
    pos = np.c_[x.ravel(), y.ravel()]
    gamma = np.where(np.abs(pos[:, 0] - 15.0) <= 2.0, 0.1, 0.0)  # vertical band, columns 13..17
    band = ShearBand().compute(pos, gamma, np.full(len(pos), 0.5))
    edges = band.outline()
    assert len(edges) == 2
    xs = sorted(float(e[:, 0].mean()) for e in edges)
    np.testing.assert_allclose(xs, [12.5, 17.5], atol=0.05)
    for e in edges:
        assert e[:, 1].min() == pytest.approx(0.0, abs=1e-6) and e[:, 1].max() == pytest.approx(
            29.0, abs=1e-6
        )


def test_input_validation():
    with pytest.raises(ValueError, match="radii"):
        ShearBand().compute(np.zeros((20, 2)), np.zeros(20))
    with pytest.raises(ValueError, match="at least 10"):
        ShearBand().compute(np.zeros((20, 2)), np.full(20, np.nan), np.ones(20))
    with pytest.raises(ValueError, match="bin_width"):
        ShearBand(bin_width=0.0)
