"""DisplacementBand: the shear band read from the grains' cumulative displacements (Fig. 11).

Synthetic lattices split by a line at a known angle, block B sliding along it by a known
jump through a linear transition of known width, give the angle, the thickness, the members
and the jump; fields without a band (a rigid motion, a homogeneous compression, noise) are
not found. The threshold ``min_reduction`` is checked against both sides: what noise reaches
and what bands give."""

from __future__ import annotations

import json

import numpy as np
import pytest
from matplotlib.collections import EllipseCollection
from scipy.spatial import cKDTree

from grainlab.analysis import DisplacementBand
from grainlab.analysis._util import NotComputedError
from grainlab.analysis.band_readings import SHARE_HIGH, SHARE_LOW

D = 1.0e-3  # lattice spacing, m
#: A homogeneous biaxial deformation (dilation along x, compression along y) the blocks share.
BIAXIAL = np.array([[0.01, 0.0], [0.0, -0.02]])


def lattice(nx: int, ny: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Jittered triangular lattice of spacing D (nx x ny grains), radii 0.48-0.54 D."""
    j, i = np.meshgrid(np.arange(ny), np.arange(nx), indexing="ij")
    pos = np.c_[(i + 0.5 * (j % 2)).ravel(), (j * np.sqrt(3.0) / 2.0).ravel()] * D
    return pos + rng.normal(0.0, 0.04 * D, pos.shape), rng.uniform(0.48, 0.54, nx * ny) * D


def sliding(
    pos: np.ndarray,
    angle_deg: float,
    width: float,
    jump: float,
    rng: np.random.Generator,
    *,
    noise: float = 0.0,
    background: np.ndarray | None = BIAXIAL,
) -> tuple[np.ndarray, np.ndarray]:
    """Displacements: block B (the side of the line through the centroid at ``angle_deg``
    that its normal (-sin, cos) points to) slides by ``jump`` (m) along the line through a
    linear transition ``width`` (m) wide (a step for 0), on a homogeneous ``background``,
    plus noise; and each grain's imposed share of the slip."""
    beta = np.radians(angle_deg)
    t, n = np.array([np.cos(beta), np.sin(beta)]), np.array([-np.sin(beta), np.cos(beta)])
    x = pos - pos.mean(axis=0)
    s = x @ n
    share = np.clip(s / width + 0.5, 0.0, 1.0) if width > 0 else (s > 0).astype(float)
    u = share[:, None] * jump * t + rng.normal(0.0, noise, pos.shape)
    if background is not None:
        u += x @ background.T
    return u, share


def correlated_noise(pos: np.ndarray, length: float, rng: np.random.Generator) -> np.ndarray:
    """(N, 2) Gaussian noise of unit standard deviation, correlated over about ``length``
    (m; white noise summed with Gaussian weights of standard deviation length / 2, so that
    the correlation falls to 1/e at ``length``)."""
    ell = 0.5 * length
    white = rng.normal(0.0, 1.0, pos.shape)
    pairs = cKDTree(pos).query_pairs(3.0 * ell, output_type="ndarray")
    i, j = pairs[:, 0], pairs[:, 1]
    w = np.exp(-np.sum((pos[i] - pos[j]) ** 2, axis=1) / (2.0 * ell**2))[:, None]
    out = white.copy()
    np.add.at(out, i, w * white[j])
    np.add.at(out, j, w * white[i])
    return out / out.std()


def angle_error(a: float, b: float) -> float:
    return abs((a - b + 90.0) % 180.0 - 90.0)


@pytest.mark.parametrize("angle", [30.0, 120.0])
def test_a_sliding_block_gives_angle_thickness_members_and_jump(angle):
    rng = np.random.default_rng(int(angle))
    pos, rad = lattice(40, 64, rng)
    width, jump = 6.0 * D, 0.5 * D
    u, share = sliding(pos, angle, width, jump, rng, noise=0.01 * D)
    band = DisplacementBand().compute(pos, u, rad)
    assert band.found, band.reason
    assert band.reason == ""
    assert angle_error(band.angle_degrees, angle) < 1.0
    assert 0.0 <= band.angle_degrees < 180.0
    assert band.inclination_degrees == pytest.approx(min(angle, 180.0 - angle), abs=1.0)
    d_mean = band.mean_diameter
    assert d_mean == pytest.approx(np.mean(2 * rad))
    bin_width = 0.5 * d_mean
    # the 0.1-0.9 zone of a linear transition is 0.8 of its width
    assert band.thickness == pytest.approx((SHARE_HIGH - SHARE_LOW) * width, abs=bin_width)
    assert band.thickness_diameters == pytest.approx(band.thickness / d_mean)
    # members: the transition zone, up to grains within one bin of its edges
    zone = (share > SHARE_LOW) & (share < SHARE_HIGH)
    differ = band.members ^ zone
    edge_distance = np.minimum(np.abs(share - SHARE_LOW), np.abs(share - SHARE_HIGH)) * width
    assert np.all(edge_distance[differ] < bin_width)
    assert differ.sum() <= 0.05 * zone.sum()
    # the jump: block B slides by `jump` along (cos, sin) of the band, without opening
    assert band.slip == pytest.approx(jump, rel=0.03)
    assert abs(band.opening) < 0.03 * jump
    assert band.jump_magnitude == pytest.approx(jump, rel=0.03)
    beta = np.radians(angle)
    assert band.normal @ np.array([-np.sin(beta), np.cos(beta)]) > 0.999  # points into block B
    assert band.residual_reduction > 0.95
    # the centre line runs through the transition's middle
    assert abs((band.center - pos.mean(axis=0)) @ band.normal) < bin_width
    # each grain's share of the relative motion follows the imposed one
    assert np.nanmax(np.abs(band.relative_motion - share)) < 0.15


def test_a_sharp_slip_reads_as_thick_as_the_smoothing():
    rng = np.random.default_rng(4)
    pos, rad = lattice(36, 60, rng)
    u, share = sliding(pos, 55.0, 0.0, 0.3 * D, rng, noise=0.005 * D)
    band = DisplacementBand().compute(pos, u, rad)
    assert band.found, band.reason
    assert angle_error(band.angle_degrees, 55.0) < 1.0
    assert 1.5 < band.thickness_diameters < 2.6  # the running mean over ~2 diameters
    assert band.slip == pytest.approx(0.3 * D, rel=0.03)


def test_the_transition_may_be_wide():
    rng = np.random.default_rng(5)
    pos, rad = lattice(40, 64, rng)
    width = 12.0 * D
    u, share = sliding(pos, 140.0, width, 0.6 * D, rng, noise=0.005 * D)
    band = DisplacementBand().compute(pos, u, rad)
    assert band.found, band.reason
    assert angle_error(band.angle_degrees, 140.0) < 1.0
    assert band.thickness == pytest.approx(0.8 * width, abs=0.5 * band.mean_diameter)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_rigid_motion_with_noise_has_no_band(seed):
    rng = np.random.default_rng(seed)
    pos, rad = lattice(36, 60, rng)
    turn = np.radians(rng.uniform(-3.0, 3.0))
    rot = np.array([[np.cos(turn), -np.sin(turn)], [np.sin(turn), np.cos(turn)]])
    centre = pos.mean(axis=0)
    u = (pos - centre) @ (rot - np.eye(2)).T + rng.normal(0.0, D, 2) + rng.normal(0.0, 0.01 * D, pos.shape)
    band = DisplacementBand().compute(pos, u, rad)
    assert not band.found
    assert "min_reduction" in band.reason
    assert band.residual_reduction < 0.05
    # the candidate keeps its numbers
    assert 0.0 <= band.angle_degrees < 180.0 and np.isfinite(band.residual_reduction)


def rigid_residual(pos: np.ndarray, u: np.ndarray) -> float:
    """Squared residual of the least-squares rigid motion (translation, small rotation)."""
    x, v = pos - pos.mean(axis=0), u - u.mean(axis=0)
    cross = np.sum(x[:, 0] * v[:, 1] - x[:, 1] * v[:, 0])
    return float(np.sum(v * v) - cross**2 / np.sum(x * x))


def test_a_homogeneous_compression_has_no_band():
    """Affine blocks: a deformation the whole sample shares leaves nothing for a split to
    explain, where two rigid blocks would 'explain' most of it."""
    rng = np.random.default_rng(6)
    pos, rad = lattice(30, 60, rng)
    u = (pos - pos.mean(axis=0)) @ BIAXIAL.T
    lower = pos[:, 1] < pos[:, 1].mean()
    rigid_blocks = rigid_residual(pos[lower], u[lower]) + rigid_residual(pos[~lower], u[~lower])
    assert 1.0 - rigid_blocks / rigid_residual(pos, u) > 0.6  # the split the docstring warns of
    noisy = DisplacementBand().compute(pos, u + rng.normal(0.0, 1e-3 * D, pos.shape), rad)
    assert not noisy.found and noisy.residual_reduction < 0.05
    exact = DisplacementBand().compute(pos, u, rad)
    assert not exact.found and exact.residual_reduction == 0.0


def test_min_reduction_separates_noise_from_bands():
    """The calibration of the default threshold (module docstring), in small: fields without
    a band stay well below it, bands whose jump stands out of the noise stay above it."""
    threshold = DisplacementBand().min_reduction
    rng = np.random.default_rng(2026)
    without = []
    for length in (0.0, 0.0, 2.0 * D, 2.0 * D, 4.0 * D, 4.0 * D):
        pos, rad = lattice(30, 52, rng)
        noise = rng.normal(0.0, 1.0, pos.shape) if length == 0.0 else correlated_noise(pos, length, rng)
        u = (pos - pos.mean(axis=0)) @ BIAXIAL.T + 0.01 * D * noise
        band = DisplacementBand().compute(pos, u, rad)
        assert not band.found
        without.append(band.residual_reduction)
    assert max(without) < 0.75 * threshold, without
    with_band = []
    for width, jump in ((0.0, 0.1), (6.0, 0.15), (0.0, np.inf), (6.0, np.inf), (12.0, np.inf)):
        pos, rad = lattice(30, 52, rng)
        noise = 0.0 if jump == np.inf else 0.01 * D
        u, _ = sliding(pos, rng.uniform(25.0, 155.0), width * D, min(jump, 0.3) * D, rng, noise=noise)
        band = DisplacementBand().compute(pos, u, rad)
        assert band.found, band.reason
        with_band.append(band.residual_reduction)
    assert min(with_band) > threshold, with_band
    assert min(with_band[2:]) > 0.85  # without noise: the whole non-affine motion


def test_a_slip_along_part_of_the_line_is_no_band():
    rng = np.random.default_rng(8)
    pos, rad = lattice(40, 70, rng)
    u, share = sliding(pos, 60.0, 6.0 * D, 0.5 * D, rng, noise=0.01 * D, background=None)
    beta = np.radians(60.0)
    along = (pos - pos.mean(axis=0)) @ np.array([np.cos(beta), np.sin(beta)])
    u *= np.clip(-along / (4.0 * D) + 0.5, 0.0, 1.0)[:, None]  # the slip dies out half way
    band = DisplacementBand().compute(pos, u, rad)
    assert not band.found and band.reason


def test_masked_grains_and_missing_displacements_are_left_out():
    rng = np.random.default_rng(9)
    pos, rad = lattice(36, 60, rng)
    u, share = sliding(pos, 35.0, 6.0 * D, 0.5 * D, rng, noise=0.01 * D)
    clean = DisplacementBand().compute(pos, u, rad)
    spoiled = u.copy()
    wild = rng.choice(pos.shape[0], 60, replace=False)
    spoiled[wild] = rng.normal(0.0, 5.0 * D, (60, 2))
    missing = rng.choice(np.setdiff1d(np.arange(pos.shape[0]), wild), 40, replace=False)
    spoiled[missing] = np.nan
    mask = np.ones(pos.shape[0], bool)
    mask[wild] = False
    band = DisplacementBand().compute(pos, spoiled, rad, mask=mask)
    assert band.found, band.reason
    assert band.angle_degrees == pytest.approx(clean.angle_degrees, abs=0.5)
    assert not band.members[wild].any()
    assert np.isnan(band.relative_motion[wild]).all() and np.isnan(band.relative_motion[missing]).all()
    # an unmasked wild displacement spoils the fits: the mask is what keeps them out
    assert DisplacementBand().compute(pos, np.where(np.isnan(spoiled), 0.0, spoiled), rad).residual_reduction < (
        band.residual_reduction
    )


def test_summary_outline_and_plot():
    rng = np.random.default_rng(10)
    pos, rad = lattice(30, 50, rng)
    u, _ = sliding(pos, 30.0, 6.0 * D, 0.5 * D, rng, noise=0.01 * D)
    band = DisplacementBand().compute(pos, u, rad)
    summary = band.summary()
    assert json.loads(json.dumps(summary)) == summary
    assert summary["found"] is True and summary["n_particles"] == int(band.members.sum())
    assert summary["angle_deg"] == pytest.approx(band.angle_degrees)
    assert summary["slip_m"] == pytest.approx(band.slip) and summary["jump_m"] == pytest.approx(band.jump_magnitude)
    edges = band.outline()
    assert len(edges) == 2
    for seg, side in zip(edges, (-0.5, 0.5), strict=True):
        np.testing.assert_allclose((seg - band.center) @ band.normal, side * band.thickness, atol=1e-12)
    ax = band.plot()
    coll = [c for c in ax.collections if isinstance(c, EllipseCollection)][0]
    np.testing.assert_allclose(coll.get_array(), np.hypot(u[:, 0], u[:, 1]))
    assert any(line.get_label() == "shear band" for line in ax.get_lines())
    assert "DisplacementBand(" in repr(band)


def test_results_raise_until_computed():
    with pytest.raises(NotComputedError, match="DisplacementBand.angle"):
        _ = DisplacementBand().angle


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"bin_width": 0.0}, "bin_width"),
        ({"bin_width": float("nan")}, "bin_width"),
        ({"max_points": 10}, "max_points"),
        ({"max_points": 500.5}, "max_points"),
        ({"min_share": 0.0}, "min_share"),
        ({"min_share": 0.5}, "min_share"),
        ({"min_reduction": 0.0}, "min_reduction"),
        ({"min_reduction": 1.5}, "min_reduction"),
        ({"crossing": -0.1}, "crossing"),
        ({"crossing": 1.1}, "crossing"),
    ],
)
def test_bad_parameters_raise_naming_them(kwargs, name):
    with pytest.raises(ValueError, match=f"^{name}:"):
        DisplacementBand(**kwargs)


def test_bad_input_raises_naming_it():
    rng = np.random.default_rng(11)
    pos, rad = lattice(10, 10, rng)
    u = np.zeros_like(pos)
    with pytest.raises(ValueError, match="^positions, displacement, radii:"):
        DisplacementBand().compute(pos, u[:-1], rad)
    with pytest.raises(ValueError, match="^mask:"):
        DisplacementBand().compute(pos, u, rad, mask=np.ones(5, bool))
    with pytest.raises(ValueError, match="^displacement: need at least 40"):
        DisplacementBand().compute(pos, np.where(np.arange(100)[:, None] < 70, np.nan, u), rad)
