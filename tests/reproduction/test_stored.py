"""The shipped paper-scale verdicts: read by name, one entry per claim."""

from __future__ import annotations

import pytest

from grainlab.reproduction.stored import CAMPAIGNS, paper_scale_verdicts, stored_claims


def test_verdicts_by_claim_from_a_document():
    doc = {"seeds": [1, 2, 3], "claims": [
        {"id": "a", "verdict": "reproduced", "mean": 1.0, "ci95": [0.5, 1.5], "n": 3},
        {"id": "b", "verdict": "inconclusive", "mean": None, "ci95": [None, None], "n": 0}]}
    v = paper_scale_verdicts(doc)
    assert v["a"] == {"verdict": "reproduced", "mean": 1.0, "ci95": [0.5, 1.5], "n": 3, "seeds": 3}
    assert v["b"]["mean"] is None and set(v) == {"a", "b"}
    assert paper_scale_verdicts({}) == {}


def test_an_unknown_campaign_is_refused():
    with pytest.raises(ValueError, match="name: expected one of main, readings, rates, rate1, rate05, study, study_readings"):
        stored_claims("nope")
    assert set(CAMPAIGNS) == {"main", "readings", "rates", "rate1", "rate05", "study", "study_readings"}


def test_the_shipped_campaign_judges_every_biaxial_claim():
    from grainlab.reproduction.claims import BIAXIAL_CLAIMS

    verdicts = paper_scale_verdicts()
    assert {c.id for c in BIAXIAL_CLAIMS} <= set(verdicts)
    assert all(v["seeds"] == 20 for v in verdicts.values())  # the ensemble size fixed in advance
    main = stored_claims("main")
    # every analysis variant of the sensitivity table judges the same 20 runs
    assert {b["variant"] for b in main["variants"]} >= {
        "paper", "lambda_raw", "band:displacement", "band:lambda", "band:final", "lambda:deviation=per_contact"}
    assert all(b["seeds"] == main["seeds"] for b in main["variants"])
    readings = stored_claims("readings")
    assert readings["seeds"] == main["seeds"]
    assert verdicts["band_lambda_above_rest"]["verdict"] in ("reproduced", "not reproduced", "inconclusive")
    rates = stored_claims("rate1")
    assert {e["rate"] for e in rates["rate_convergence"]} == {"2%/min", "4%/min", "8%/min"}
    slowest = stored_claims("rate05")
    (pair,) = slowest["rate_convergence"]
    assert (pair["rate"], pair["half_rate"]) == ("1%/min", "0.5%/min")
    # the macro response converged, the band's lambda (near 0 at both rates) did not by the rule
    assert [q["within"] for q in pair["quantities"].values()] == [True, True, True, False]
    assert not pair["converged"]
    one = next(b for b in slowest["variants"] if b["variant"] == "rate=1%/min")
    earlier = next(b for b in rates["variants"] if b["variant"] == "rate=1%/min")
    now, then = ({r["id"]: r for r in b["claims"]} for b in (one, earlier))
    for claim in ("peak_near_1.5", "z_initial", "band_lambda_above_rest"):
        assert now[claim]["per_seed"] == then[claim]["per_seed"], claim  # the same runs, bit for bit


def test_the_shipped_packing_study_judges_every_study_claim():
    from grainlab.reproduction.claims import STUDY_CLAIMS

    study = stored_claims("study")
    assert study is not None and study["variant"] == "study:generation_friction=0"
    for block in study["variants"]:
        assert {c.id for c in STUDY_CLAIMS} <= {row["id"] for row in block["claims"]}
    readings = stored_claims("study_readings")
    # the readings measure the same packings again: the default reading is the study's own block
    own = next(b for b in readings["variants"] if b["variant"] == "study:generation_friction=0")
    assert own["claims"] == study["variants"][0]["claims"]
    lambdas = [b for b in readings["variants"] if b["variant"].startswith("lambda:")]
    assert len(lambdas) == 8 and all(b["runs_of"] == "study:generation_friction=0" for b in lambdas)
    for block in lambdas:
        assert {c.id for c in STUDY_CLAIMS} <= {row["id"] for row in block["claims"]}
