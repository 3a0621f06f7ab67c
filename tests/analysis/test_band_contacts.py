"""Band against rest at equal contact number (grainlab.analysis.band_contacts): constructed snapshots
with known answers."""

import math

import numpy as np
import pytest

from grainlab.analysis.band_contacts import STRATA, BandContacts, cross_fitted_scores


def _grains(rng, n_per, lam_band, lam_rest, band_share_by_n):
    """Grains of contact numbers 0..6, ``n_per`` of each; in each class a share of band grains;
    lambda drawn around ``lam_band[n]`` / ``lam_rest[n]`` (0/1-contact grains at 1)."""
    lam, counts, band = [], [], []
    for n in range(7):
        k_in = int(round(band_share_by_n[n] * n_per))
        for inside, k in ((True, k_in), (False, n_per - k_in)):
            counts += [n] * k
            band += [inside] * k
            if n < 2:
                lam += [1.0] * k
            else:
                centre = (lam_band if inside else lam_rest)[n]
                lam += list(centre + 0.02 * rng.standard_normal(k))
    return np.array(lam), np.array(counts), np.array(band)


def test_a_contact_count_effect_alone_gives_no_difference_at_equal_contacts():
    # lambda depends on n only (same in band and rest); the band holds more low-n grains.
    rng = np.random.default_rng(1)
    lam_n = {n: 0.05 * n for n in range(2, 7)}
    share = {0: 0.6, 1: 0.6, 2: 0.5, 3: 0.3, 4: 0.15, 5: 0.1, 6: 0.1}
    lam, counts, band = _grains(rng, 400, lam_n, lam_n, share)
    bc = BandContacts().compute(lam, counts, band)
    # the raw difference over every grain is large (0/1-contact grains at 1, more of them in the band) ...
    raw = lam[band].mean() - lam[~band].mean()
    assert raw > 0.1
    # ... but at equal contact number there is none
    assert abs(bc.stratified_difference) < 0.005
    for label, _, _ in STRATA:
        assert abs(bc.strata[label]["difference"]) < 0.01
    assert bc.auc_within == pytest.approx(0.5, abs=0.03)
    # the contact number alone tells band grains apart; lambda adds nothing out of sample
    assert bc.auc_contacts > 0.65
    assert abs(bc.auc_gain) < 0.01


def test_a_lambda_shift_at_equal_contacts_is_found_and_adds_to_the_count():
    rng = np.random.default_rng(2)
    rest = {n: 0.05 * n for n in range(2, 7)}
    inside = {n: 0.05 * n + 0.03 for n in range(2, 7)}
    share = dict.fromkeys(range(7), 0.3)  # the same share in every class: n says nothing
    lam, counts, band = _grains(rng, 400, inside, rest, share)
    bc = BandContacts().compute(lam, counts, band)
    assert bc.stratified_difference == pytest.approx(0.03, abs=0.003)
    assert bc.strata["5+"]["n_inside"] == 2 * 120 and bc.strata["5+"]["n_outside"] == 2 * 280
    assert bc.auc_within > 0.75  # 0.855 in a pure stratum (shift 0.03, sd 0.02); 5+ mixes n = 5 and 6
    assert bc.auc_contacts == pytest.approx(0.5, abs=0.05)
    assert bc.auc_gain > 0.15  # diluted by the 0/1-contact grains, where lambda is 1 on both sides


def test_strata_counts_means_and_pooling_by_hand():
    lam = np.array([0.4, 0.3, 0.1, 0.2, 0.5, 0.1, 0.2, 0.6, 0.9, 1.0])
    n = np.array([2, 2, 2, 2, 3, 3, 3, 3, 7, 1])
    band = np.array([True, True, False, False, True, False, False, True, True, True])
    bc = BandContacts().compute(lam, n, band)
    s2, s3, s4, s5 = (bc.strata[k] for k in ("2", "3", "4", "5+"))
    assert (s2["n_inside"], s2["n_outside"], s3["n_inside"], s3["n_outside"]) == (2, 2, 2, 2)
    assert s2["difference"] == pytest.approx(0.35 - 0.15) and s3["difference"] == pytest.approx(0.55 - 0.15)
    assert (s4["n_inside"], s4["n_outside"]) == (0, 0) and math.isnan(s4["difference"])
    # the 7-contact grain is in 5+ with no rest grain: it counts, but is not pooled
    assert (s5["n_inside"], s5["n_outside"]) == (1, 0) and math.isnan(s5["auc_lambda"])
    # equal weights (2 * 2 / 4 = 1 each): the mean of the two differences
    assert bc.stratified_difference == pytest.approx(0.3)
    assert bc.auc_within == 1.0
    summary = bc.summary()
    assert summary["stratum_3_difference"] == pytest.approx(0.4)
    assert summary["auc_gain_lambda"] == pytest.approx(summary["auc_contacts_lambda"] - summary["auc_contacts"])


def test_cross_fitting_is_out_of_sample():
    # pure noise features: an in-sample fit would score above 0.5; out of sample it does not
    rng = np.random.default_rng(5)
    x = rng.standard_normal((600, 40))
    y = rng.random(600) < 0.5
    from grainlab.analysis.band_contacts import _fit_logistic
    from grainlab.analysis.band_fabric import roc_auc

    in_sample = roc_auc(x @ _fit_logistic(x, y), y)
    assert in_sample > 0.6
    assert roc_auc(cross_fitted_scores(x, y), y) < 0.55
    # and a real signal is kept
    y2 = x[:, 0] + 0.5 * rng.standard_normal(600) > 0
    assert roc_auc(cross_fitted_scores(x, y2), y2) > 0.85


def test_bad_input():
    with pytest.raises(ValueError, match="members"):
        BandContacts().compute(np.zeros(3), np.ones(3, int), np.zeros(2, bool))
    with pytest.raises(ValueError, match="n_contacts"):
        BandContacts().compute(np.zeros(3), np.array([1, -1, 2]), np.zeros(3, bool))
