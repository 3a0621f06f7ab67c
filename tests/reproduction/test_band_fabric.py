"""Band-resolved fabric and the ROC AUC of lambda: exact cases and the brute-force definition."""

from __future__ import annotations

import math

import numpy as np
import pytest

from grainlab.analysis.band_fabric import BandFabric, coarse_grained, roc_auc


def brute_auc(scores, labels):
    pos, neg = scores[labels], scores[~labels]
    wins = (pos[:, None] > neg[None, :]).sum() + 0.5 * (pos[:, None] == neg[None, :]).sum()
    return wins / (pos.size * neg.size)


def test_auc_is_the_share_of_pairs_ranked_right_with_ties_halved():
    rng = np.random.default_rng(7)
    scores = np.round(rng.normal(size=300), 1)  # many ties
    labels = rng.random(300) < 0.3
    assert roc_auc(scores, labels) == pytest.approx(brute_auc(scores, labels), abs=1e-12)
    assert roc_auc(-scores, labels) == pytest.approx(1.0 - brute_auc(scores, labels), abs=1e-12)


def test_auc_of_an_uninformative_score_is_one_half_and_empty_classes_give_nan():
    assert roc_auc(np.ones(10), np.arange(10) < 4) == 0.5
    assert math.isnan(roc_auc(np.arange(4.0), np.zeros(4, bool)))
    assert roc_auc(np.array([np.nan, 1.0, 0.0]), np.array([True, True, False])) == 1.0
    with pytest.raises(ValueError, match="shapes"):
        roc_auc(np.ones(3), np.ones(4, bool))


def test_coarse_graining_averages_the_disk_around_each_grain():
    pos = np.c_[np.arange(5.0), np.zeros(5)]  # unit spacing on a line
    values = np.array([0.0, 1.0, 2.0, 3.0, np.nan])
    field = coarse_grained(pos, values, 1.01)  # self and nearest neighbours
    np.testing.assert_allclose(field, [0.5, 1.0, 2.0, 2.5, 3.0])
    with pytest.raises(ValueError, match="radius"):
        coarse_grained(pos, values, 0.0)


def test_groups_inside_and_outside_a_band():
    # a band of two-contact grains with high lambda in a rest of three- and four-contact grains
    n = 40
    x = np.linspace(0.0, 39.0, n)
    pos = np.c_[x, np.zeros(n)]
    band = (x >= 15) & (x < 25)
    counts = np.where(band, 2, 3 + (np.arange(n) % 2))
    counts[0] = 1  # a rattler outside: lambda 1, left out of the >= 2 mean
    lam = np.where(band, 0.4, 0.1)
    lam[0] = 1.0
    rot = np.where(band, 0.2, -0.01)
    bf = BandFabric(coarse_radius=2.0).compute(pos, np.ones(n), lam, counts, band, rotation=rot)
    inside, outside = bf.inside, bf.outside
    assert inside["n_grains"] == 10 and outside["n_grains"] == 30
    assert inside["mean_lambda"] == pytest.approx(0.4) and inside["fraction_2"] == 1.0
    assert outside["mean_lambda"] == pytest.approx(0.1)  # the rattler is filtered out
    assert outside["mean_lambda_all"] == pytest.approx((29 * 0.1 + 1.0) / 30)
    assert outside["fraction_1"] == pytest.approx(1 / 30)
    assert outside["fraction_3_or_more_of_load_bearing"] == 1.0
    assert inside["mean_abs_rotation_rad"] == pytest.approx(0.2) and outside["mean_abs_rotation_rad"] == pytest.approx(0.01)
    assert inside["coordination_number"] == 2.0
    # the rattler's lambda = 1 outranks the band: per-grain AUC just below 1, the field's is 1
    assert bf.auc_lambda == pytest.approx(1.0 - 1.0 / 30)
    assert bf.auc_lambda_field > bf.auc_lambda
    summary = bf.summary()
    assert summary["inside_fraction_2"] == 1.0 and "auc_lambda_field" in summary


def test_mismatched_arrays_are_refused():
    with pytest.raises(ValueError, match="members"):
        BandFabric().compute(np.zeros((3, 2)), np.ones(3), np.zeros(3), np.ones(3, int), np.zeros(2, bool))
