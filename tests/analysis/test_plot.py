"""Figures: the right artists with the right data, written as PNG and SVG."""

from __future__ import annotations

import numpy as np
import pytest
from factories_analysis import hex_lattice, jittered_packing
from matplotlib.collections import EllipseCollection

from grainlab import plot
from grainlab.analysis import (
    ContactAnisotropy,
    CoordinationNumber,
    LocalStrain,
    ShearBand,
    StabilityIndex,
)


def test_particle_map_draws_disks_to_scale_in_one_collection(tmp_path):
    snap = jittered_packing(10, 10, seed=2)
    lam = StabilityIndex().compute(snap)
    ax = lam.plot()
    colls = [c for c in ax.collections if isinstance(c, EllipseCollection)]
    assert len(colls) == 1
    coll = colls[0]
    np.testing.assert_allclose(coll.get_offsets(), snap.positions)
    np.testing.assert_allclose(coll._widths, snap.radii)  # half-widths in data units
    np.testing.assert_allclose(coll.get_array(), lam.stability_index)
    assert coll.norm.vmin == 0.0 and coll.norm.vmax == 1.0
    written = plot.save_figure(ax, tmp_path / "lambda")
    assert [p.suffix for p in written] == [".png", ".svg"]
    assert written[0].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert b"<svg" in written[1].read_bytes()[:500]


def test_discrete_contact_count_map():
    snap = jittered_packing(8, 8, seed=3)
    counts = CoordinationNumber().compute(snap).n_contacts
    ax = plot.particle_map(snap.positions, snap.radii, counts, discrete=True, label="contacts")
    coll = ax.collections[0]
    bounds = coll.norm.boundaries
    np.testing.assert_allclose(bounds, np.arange(counts.min() - 0.5, counts.max() + 1.0))


def test_polar_distribution_bars_and_fit():
    snap = hex_lattice(rotation_deg=7.0)
    an = ContactAnisotropy(bins=18).compute(snap)
    ax = an.plot()
    heights = [p.get_height() for p in ax.patches]
    np.testing.assert_allclose(heights, an.histogram)
    assert len(ax.lines) == 1  # the fitted E(theta)
    np.testing.assert_allclose(
        ax.lines[0].get_ydata(), an.histogram.mean(), atol=1e-9
    )  # a = 0: a circle
    assert ax.name == "polar"


def test_shear_band_outline_and_strain_map():
    x, y = np.meshgrid(np.arange(30.0), np.arange(30.0))
    pos = np.c_[x.ravel(), y.ravel()]
    gamma = np.where(np.abs(pos[:, 1] - 15.0) <= 2.0, 0.1, 0.0)
    band = ShearBand().compute(pos, gamma, np.full(len(pos), 0.5))
    ax = band.plot()
    labelled = [ln for ln in ax.lines if ln.get_label() == "shear band"]
    assert len(labelled) == 1 and len(ax.lines) == 2
    ys = sorted(float(np.mean(ln.get_ydata())) for ln in ax.lines)
    np.testing.assert_allclose(ys, [12.5, 17.5], atol=0.05)


def test_displacement_map_uses_magnitudes():
    snap = jittered_packing(8, 8, seed=5)
    from grainlab.snapshot import Snapshot

    cur = Snapshot(snap.positions * 1.01, snap.radii)
    s = LocalStrain().compute(snap, cur)
    ax = s.plot()
    np.testing.assert_allclose(ax.collections[0].get_array(), np.hypot(*(0.01 * snap.positions).T))
    with pytest.raises(ValueError, match="quantity"):
        s.plot(quantity="pressure")


def test_time_series(tmp_path):
    eps = np.array([0.0, 0.005, 0.01, 0.015])
    ax = plot.anisotropy_series(eps, [0.003, 0.18, 0.2, 0.15], normal_force=[0.009, 0.2, 0.25, 0.2])
    np.testing.assert_allclose(ax.lines[0].get_xdata(), 100 * eps)
    assert len(ax.lines) == 2
    assert "compression positive" in ax.get_xlabel()
    ax2 = plot.mean_lambda_series(eps, [0.30, 0.33, 0.34, 0.32])
    np.testing.assert_allclose(ax2.lines[0].get_ydata(), [0.30, 0.33, 0.34, 0.32])
    assert len(plot.save_figure(ax2, tmp_path / "lambda_series", formats=("svg",))) == 1
    with pytest.raises(ValueError, match="anisotropy"):
        plot.anisotropy_series(eps, [0.1, 0.2])
    with pytest.raises(ValueError, match="mean_lambda"):
        plot.mean_lambda_series(eps, [0.1])
