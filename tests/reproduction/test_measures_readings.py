"""The reproduction's measures under the readings of lambda and of the band, on a real quick run:
the readings change what they should and nothing else."""

from __future__ import annotations

import math

import numpy as np
import pytest

from grainlab.reproduction.measures import measure_biaxial, measure_biaxial_each


@pytest.mark.slow
def test_every_reading_on_one_run(quick_biaxial_run):
    options = [{}, {"band": "displacement"}, {"band": "final"}, {"band": "lambda"},
               {"lambda_deviation": "per_contact"}, {"lambda_slots": "nearest"}]
    default, displacement, final, in_lambda, per_contact, nearest = measure_biaxial_each(quick_biaxial_run, options)
    # the default options are the measures the claims always used
    assert default == measure_biaxial(quick_biaxial_run)
    for m in (displacement, final, in_lambda, per_contact, nearest):
        assert m["macro"] == default["macro"] and m["peak_snapshot"] == default["peak_snapshot"]
    rows = list(zip(default["snapshots"], per_contact["snapshots"], nearest["snapshots"], strict=True))
    for d, p, n in rows:
        # D / (n - 1) <= D for every grain with n >= 2 contacts, equal at n = 2; the nearest slot is never
        # further than the angular one
        assert p["mean_lambda"] <= d["mean_lambda"] + 1e-12
        assert n["mean_lambda"] <= d["mean_lambda"] + 1e-12
        # readings of lambda leave the band and the contact counts alone
        assert p["band_found"] == d["band_found"] and p["coordination_number"] == d["coordination_number"]
        assert math.isnan(d["band_overlap_with_strain"])  # the strain reading against itself: none
    # each band reading's overlap with the strain band is a Jaccard index; the final band carried
    # back is the strain band itself where that band was accepted
    for reading in (displacement, final, in_lambda):
        overlaps = np.array([r["band_overlap_with_strain"] for r in reading["snapshots"]], dtype=float)
        assert np.all((overlaps[np.isfinite(overlaps)] >= 0) & (overlaps[np.isfinite(overlaps)] <= 1))
    last = final["snapshots"][-1]
    if default["snapshots"][-1]["band_found"]:
        assert last["band_overlap_with_strain"] == 1.0
    # the displacement map always has a two-block split after the first snapshot: its grains are known
    assert all(r["band_members_known"] for r in displacement["snapshots"])
    # the final band carried back: the same grains at every snapshot where the band is known
    known = [r for r in final["snapshots"] if r["band_members_known"]]
    if known:
        assert len({r["band_from_strain"] for r in known}) == 1
        assert known[0]["band_from_strain"] == max(r["axial_strain"] for r in default["snapshots"]
                                                  if r["band_found"])
    # the strata of the band-against-rest comparison add up to the grains with >= 2 contacts
    peak = default["snapshots"][default["peak_snapshot"]]
    if peak.get("band_members_known"):
        inside = sum(peak[f"stratum_{k}_n_inside"] for k in ("2", "3", "4", "5+"))
        bearing = peak["inside_n_grains"] * (1.0 - peak["inside_fraction_0"] - peak["inside_fraction_1"])
        assert inside == pytest.approx(bearing, abs=1e-6)
        assert 0.0 <= peak["auc_contacts"] <= 1.0 and math.isfinite(peak["auc_gain_lambda"])
    assert np.isfinite([r["mean_lambda"] for r in nearest["snapshots"]]).all()


def test_a_packing_study_is_measured_again_under_a_reading_on_its_stored_packings(tmp_path):
    from grainlab.analysis import StabilityIndex
    from grainlab.reproduction.measures import measure_study, read_study_rows
    from grainlab.study import make_run, run_campaign
    from grainlab.study.packing import read_packing

    small = {"width": 0.02, "height": 0.04}
    runs = [make_run(f"{kind}_{porosity}", "packing", {**small, "kind": kind, "porosity": porosity}, 3, {"kind": kind})
            for kind, porosity in (("hexagonal", 0.12), ("irregular", 0.18))]
    run_campaign(runs, tmp_path, workers=1, progress=False)
    folder = tmp_path / "runs"
    default = read_study_rows(folder)
    assert read_study_rows(folder, {}) == default
    per_contact = read_study_rows(folder, {"lambda_deviation": "per_contact"})
    for d, p in zip(default, per_contact, strict=True):
        snap = read_packing(folder / d["name"])
        expected = StabilityIndex(deviation="per_contact").compute(snap)
        assert p["mean_stability_index"] == expected.mean and p["mean_stability_index_all"] == expected.mean_all
        # D / (n - 1) <= D grain by grain; nothing but lambda changes
        assert p["mean_stability_index"] <= d["mean_stability_index"] + 1e-12
        assert {k: v for k, v in p.items() if "stability" not in k} == {
            k: v for k, v in d.items() if "stability" not in k}
    irregular = next(p for p, d in zip(per_contact, default, strict=True) if d["kind"] == "irregular")
    assert irregular["mean_stability_index"] < next(d for d in default if d["kind"] == "irregular")[
        "mean_stability_index"]  # grains with 3+ contacts exist
    assert measure_study(per_contact)["n_rows"] == 2
    from grainlab.reproduction.measures import read_study_rows_each

    assert read_study_rows_each(folder, [{}, {"lambda_deviation": "per_contact"}]) == [default, per_contact]
    with pytest.raises(ValueError, match="only under a reading of lambda"):
        read_study_rows(folder, {"band": "final"})
