"""Samples of shaped grains: radius expansion of rigid clumps (trimers, dimers) at
random angles to a nominal porosity counted on each clump's union, and that
porosity against a raster of the union."""

from __future__ import annotations

import numpy as np
import pytest

from grainlab.samples import (
    UniformByNumber,
    expand_to_porosity,
    grain_overlap_area,
    nominal_porosity,
    overlap_corrected_porosity,
)
from grainlab.shapes import shape_template

BOX = (0.0, 0.0, 0.008, 0.008)
GRADING = UniformByNumber(0.5e-3, 1.5e-3)


@pytest.fixture(scope="module")
def trimers():
    return expand_to_porosity(BOX, 0.14, GRADING, seed=3, shape=shape_template("trimer", 0.3), keep_simulation=True)


def raster_porosity(positions, radii, box, step):
    """``1 - covered / area`` on a grid of cell centres ``step`` apart."""
    x0, y0, x1, y1 = box
    xs = np.arange(x0 + step / 2, x1, step)
    ys = np.arange(y0 + step / 2, y1, step)
    covered = np.zeros((len(ys), len(xs)), dtype=bool)
    for (cx, cy), r in zip(positions, radii, strict=True):
        ix = slice(max(0, int((cx - r - x0) / step)), int((cx + r - x0) / step) + 2)
        iy = slice(max(0, int((cy - r - y0) / step)), int((cy + r - y0) / step) + 2)
        gx, gy = np.meshgrid(xs[ix], ys[iy])
        covered[iy, ix] |= (gx - cx) ** 2 + (gy - cy) ** 2 <= r * r
    return 1.0 - covered.mean()


def test_a_trimer_sample_reaches_its_porosity_counted_on_each_clumps_union(trimers):
    s = trimers
    template = shape_template("trimer", 0.3)
    assert s.shape == "trimer" and s.shape_parameter == 0.3 and s.n_particles == 3 * s.n_grains
    np.testing.assert_array_equal(s.grain, np.repeat(np.arange(s.n_grains), 3))
    # nominal porosity: the clumps' unions, R^2 times the template's area, fill 1 - n of the box
    circumscribed = s.radii[::3] / template.radii[0]
    area = (BOX[2] - BOX[0]) * (BOX[3] - BOX[1])
    assert 1.0 - template.area * np.sum(circumscribed**2) / area == pytest.approx(0.14, abs=1e-12)
    assert s.porosity == pytest.approx(0.14, abs=1e-12)
    # every clump kept its template's shape through the growth (rigid, similar)
    for k in range(0, s.n_particles, 3):
        centres = s.positions[k:k + 3]
        sides = np.linalg.norm(centres - np.roll(centres, 1, axis=0), axis=1)
        np.testing.assert_allclose(sides, np.sqrt(3) * np.hypot(*template.offsets[0]) * circumscribed[k // 3],
                                   rtol=1e-9)
    # jammed and at rest, the coordination number per grain (contacts per clump)
    assert s.jammed and s.equilibrium_reached
    contacts = s.simulation.contacts()
    assert not np.any(s.grain[contacts.i] == s.grain[contacts.j])
    assert s.coordination_number == pytest.approx(2 * len(contacts) / s.n_grains)
    assert 3.0 < s.mechanical_coordination_number < 7.0
    # the simulation hands over the clumps at Table 1's density
    assert len(s.simulation.clumps) == s.n_grains


def test_the_clump_packings_porosity_is_the_raster_of_its_union(trimers):
    """Oracle: the porosity by grain (each clump's exact union, lenses only between
    grains) against the fraction of a 2 micrometre grid that no pebble covers."""
    s = trimers
    by_grain = overlap_corrected_porosity(s.positions, s.radii, BOX, grain=s.grain)
    raster = raster_porosity(s.positions, s.radii, BOX, 2e-6)
    assert by_grain == pytest.approx(raster, abs=5e-5)
    # the pair-wise correction alone misses a trimer's triple overlap by far more
    pairwise = overlap_corrected_porosity(s.positions, s.radii, BOX)
    assert abs(pairwise - raster) > 10 * abs(by_grain - raster)
    # the own overlaps are the pebbles' areas less the clumps' unions
    own = grain_overlap_area(s.positions, s.radii, s.grain)
    assert own == pytest.approx(np.pi * np.sum(s.radii**2) - shape_template("trimer", 0.3).area
                                * np.sum((s.radii[::3] / shape_template("trimer", 0.3).radii[0]) ** 2), rel=1e-9)
    assert nominal_porosity(s.radii, 64e-6, positions=s.positions, grain=s.grain) == pytest.approx(s.porosity)


def test_one_disk_grains_keep_the_disk_sample_to_the_bit():
    disks = expand_to_porosity(BOX, 0.16, GRADING, seed=3)
    shaped = expand_to_porosity(BOX, 0.16, GRADING, seed=3, shape=shape_template("trimer", 0.0))
    assert shaped.grain is None and shaped.shape == "disk"
    np.testing.assert_array_equal(shaped.positions, disks.positions)
    np.testing.assert_array_equal(shaped.radii, disks.radii)
    assert overlap_corrected_porosity(disks.positions, disks.radii, BOX,
                                      grain=np.arange(disks.n_particles)) == disks.porosity_overlap_corrected


def test_dimers_pack_at_random_angles():
    s = expand_to_porosity(BOX, 0.16, GRADING, seed=5, shape=shape_template("dimer", 0.4))
    axis = s.positions[1::2] - s.positions[::2]
    angles = np.mod(np.arctan2(axis[:, 1], axis[:, 0]), np.pi)
    # random orientations: no direction preferred (a uniform angle's mean resultant is small)
    assert abs(np.mean(np.exp(2j * angles))) < 0.35
    assert s.n_grains == s.n_particles // 2 and s.porosity == pytest.approx(0.16, abs=1e-12)


def test_a_shape_that_is_not_a_template_is_refused_before_any_work():
    with pytest.raises(TypeError, match="shape: expected a ShapeTemplate"):
        expand_to_porosity(BOX, 0.16, GRADING, shape="trimer")  # type: ignore[arg-type]


def test_a_clump_sample_keeps_the_gradings_sizes():
    """The default grain count fills the box with grains of the shape's area, so the
    common growth factor stays near 1: the clumps' circumscribed diameters are the
    grading's, not 1 / sqrt(area fraction) larger."""
    shape = shape_template("trimer", 0.5)
    s = expand_to_porosity(BOX, 0.16, GRADING, seed=2, shape=shape)
    assert abs(s.radius_factor - 1.0) < 0.1  # the draw's own scatter, not 1 / sqrt(0.71) = 1.19
    diameters = 2 * s.radii[::3] / shape.radii[0]
    assert diameters.min() > 0.9 * GRADING.d_min and diameters.max() < 1.1 * GRADING.d_max
