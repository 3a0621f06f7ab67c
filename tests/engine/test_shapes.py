"""Grain shapes: every shape's circumscribed radius is 1 and its inscribed
radius 1 - eta (the definition of CEGEO's parameter), the inscribed radius
against a fine sampling of the union's boundary, user templates, and bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

from grainlab.shapes import inscribed_radius, shape_template, template_of


def _sampled_inscribed_radius(offsets, radii, samples=200_000):
    """The nearest point of the union's boundary to the origin by sampling every
    circle finely and keeping the points inside no other disk."""
    best = math.inf
    t = np.linspace(0.0, 2.0 * np.pi, samples, endpoint=False)
    for k, (c, r) in enumerate(zip(offsets, radii, strict=True)):
        pts = c + r * np.column_stack([np.cos(t), np.sin(t)])
        inside = np.zeros(len(pts), dtype=bool)
        for m, (c2, r2) in enumerate(zip(offsets, radii, strict=True)):
            if m != k:
                inside |= np.hypot(*(pts - c2).T) < r2
        if (~inside).any():
            best = min(best, float(np.hypot(*pts[~inside].T).min()))
    return best


@pytest.mark.parametrize(
    ("name", "n"), [("dimer", None), ("trimer", None), ("rod", 3), ("rod", 4), ("rod", 5), ("rod", 6)]
)
@pytest.mark.parametrize("eta", [0.05, 0.1, 0.2, 0.3, 0.4, 0.5])
def test_every_shape_has_circumscribed_radius_one_and_inscribed_one_minus_eta(name, n, eta):
    t = shape_template(name, eta, n_pebbles=n)
    assert t.circumscribed_radius == pytest.approx(1.0, abs=1e-12)
    assert t.inscribed_radius == pytest.approx(1.0 - eta, abs=1e-12)
    # the pebbles sit about the centroid (symmetric shapes)
    assert np.abs(t.offsets.mean(axis=0)).max() < 1e-15
    assert t.area < math.pi and t.equal_area_radius < 1.0


@pytest.mark.parametrize("name", ["dimer", "trimer"])
def test_the_inscribed_radius_matches_a_fine_sampling_of_the_boundary(name):
    # the sampling can only overestimate: it misses a corner (a waist) by up to
    # about r 2 pi / samples, 2e-5 here
    t = shape_template(name, 0.35)
    rng = np.random.default_rng(3)
    cases = [(t.offsets, t.radii)] + [(rng.uniform(-0.4, 0.4, (4, 2)), rng.uniform(0.5, 0.8, 4)) for _ in range(5)]
    for offsets, radii in cases:
        exact, sampled = inscribed_radius(offsets, radii), _sampled_inscribed_radius(offsets, radii)
        assert exact - 1e-12 <= sampled <= exact + 1e-4


def test_eta_zero_is_a_disk_for_every_shape():
    for name, n in [("disk", None), ("dimer", None), ("trimer", None), ("rod", 4)]:
        t = shape_template(name, 0.0, n_pebbles=n)
        assert t.n_pebbles == 1 and t.radii[0] == 1.0 and t.area == pytest.approx(math.pi, rel=1e-15)


def test_a_user_template_is_centred_and_scaled_and_keeps_its_eta():
    trimer = shape_template("trimer", 0.25)
    c, s = math.cos(0.7), math.sin(0.7)
    moved = 3.0e-3 * trimer.offsets @ np.array([[c, s], [-s, c]]) + [0.1, -0.2]
    user = template_of(moved, 3.0e-3 * trimer.radii)
    assert user.name == "template"
    assert user.eta == pytest.approx(0.25, abs=1e-12)
    assert user.circumscribed_radius == pytest.approx(1.0, abs=1e-12)
    assert user.area == pytest.approx(trimer.area, rel=1e-12)


@pytest.mark.parametrize(
    ("args", "kwargs", "message"),
    [
        (("hexagon", 0.1), {}, r"shape: must be one of disk, dimer, trimer, rod"),
        (("trimer", 0.8), {}, r"shape_parameter: a trimer's eta must be in \[0, 0.7321\)"),
        (("dimer", -0.1), {}, r"shape_parameter: a dimer's eta"),
        (("dimer", float("nan")), {}, r"shape_parameter"),
        (("rod", 0.1), {}, r"n_pebbles: a rod needs 2 or more pebbles"),
        (("rod", 0.1), {"n_pebbles": 1}, r"n_pebbles: a rod needs 2 or more pebbles"),
        (("rod", 0.7), {"n_pebbles": 3}, r"a rod's eta must be in \[0, 0.6667\)"),
        (("trimer", 0.1), {"n_pebbles": 3}, r"n_pebbles: only a rod takes it"),
        (("disk", 0.1), {}, r"a disk's eta must be in \[0, 0\)"),
    ],
)
def test_bad_shapes_are_refused_naming_the_field(args, kwargs, message):
    with pytest.raises(ValueError, match=message):
        shape_template(*args, **kwargs)
