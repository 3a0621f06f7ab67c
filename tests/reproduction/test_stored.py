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
    with pytest.raises(ValueError, match="name: expected one of main, rates, rate1"):
        stored_claims("nope")
    assert set(CAMPAIGNS) == {"main", "rates", "rate1"}
