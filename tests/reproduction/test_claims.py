"""Claims on constructed measures: the paper's behaviour is reproduced, its opposite is
not; claims.json, claims.csv and reproduction.html have the documented form."""

from __future__ import annotations

import csv
import json
import math

import pytest
from reproduction_factories import paper_like, study_like

from grainlab.reproduction import outputs
from grainlab.reproduction.claims import BIAXIAL_CLAIMS, STUDY_CLAIMS, evaluate
from grainlab.reproduction.runs import ReproductionPlan
from grainlab.reproduction.verdicts import NOT_REPRODUCED, REPRODUCED

SEEDS = (1, 2, 3, 4, 5)
ROW_KEYS = {"id", "statement", "source", "paper_value", "mean", "ci95", "n", "per_seed", "test", "verdict"}


def _rows(claims, measures):
    return {r["id"]: r for r in evaluate(claims, measures, SEEDS, "paper")}


def test_a_run_that_behaves_as_the_paper_reproduces_its_claims():
    rows = _rows(BIAXIAL_CLAIMS, [paper_like(s) for s in SEEDS])
    for key in ("peak_near_1.5", "softening_after_peak", "contraction_first", "dilation_after", "a_at_0.5",
                "z_initial", "z_at_peak", "band_at_0.5", "band_at_peak", "band_lambda_above_rest",
                "band_lambda_0.34", "rest_lambda_0.31", "band_mostly_two_contacts", "rest_three_or_more",
                "band_z_below_rest", "band_rotation_larger", "lambda_locates_band", "lambda_rises_to_peak",
                "lambda_falls_after_peak", "lambda_tracks_stress_ratio", "initial_lambda_random",
                "stress_ratio_linear_to_0.5", "a_largest_at_peak"):
        assert rows[key]["verdict"] == REPRODUCED, (key, rows[key])
    peak = rows["peak_near_1.5"]
    assert peak["n"] == 5 and peak["ci95"][0] <= peak["mean"] <= peak["ci95"][1]
    assert peak["mean"] == pytest.approx(0.015, abs=1e-9)


def test_a_band_more_stable_than_the_rest_is_not_reproduced():
    rows = _rows(BIAXIAL_CLAIMS, [paper_like(s, band_sign=-1.0) for s in SEEDS])
    assert rows["band_lambda_above_rest"]["verdict"] == NOT_REPRODUCED
    assert rows["band_lambda_0.34"]["verdict"] == NOT_REPRODUCED
    assert all(v < 0 for v in rows["band_lambda_above_rest"]["per_seed"])


def test_a_seed_without_a_run_counts_as_missing():
    measures = [paper_like(s) for s in SEEDS[:4]] + [None]
    rows = _rows(BIAXIAL_CLAIMS, measures)
    assert rows["peak_near_1.5"]["n"] == 4 and rows["peak_near_1.5"]["per_seed"][-1] is None


def test_study_claims_on_constructed_packings():
    rows = _rows(STUDY_CLAIMS, [study_like(s) for s in SEEDS])
    assert rows["lambda_falls_with_z_irregular"]["verdict"] == REPRODUCED
    assert rows["lambda_falls_with_z_hexagonal"]["verdict"] == REPRODUCED
    assert rows["hexagonal_more_stable"]["verdict"] == REPRODUCED
    assert rows["hexagonal_more_stable_at_porosity"]["verdict"] == REPRODUCED
    # the two series' Z ranges do not overlap: no value, no verdict
    assert rows["hexagonal_more_stable_at_z"]["n"] == 0


def _write(plan, folder, monkeypatch, figures):
    fake = {}
    for v in plan.variants:
        for s in plan.seeds:
            kind = "study" if v.kind == "study" else "biaxial"
            fake[(v.name, str(s), kind)] = study_like(s) if kind == "study" else paper_like(s)
    monkeypatch.setattr(outputs, "_compute", lambda tasks, workers, progress: (fake, []))
    return outputs.write_outputs(plan, folder, progress=False, figures=figures)


def test_claims_files_have_the_documented_form(tmp_path, monkeypatch):
    plan = ReproductionPlan.build(5, ["paper", "lambda_raw", "study", "rate=1%/min"])
    written = _write(plan, tmp_path, monkeypatch, figures=False)
    doc = json.loads((tmp_path / "claims.json").read_text())
    assert doc == written.document
    assert {"claims", "seeds", "variant", "grainlab_version", "variants", "rate_convergence"} <= set(doc)
    assert doc["seeds"] == list(SEEDS) and doc["variant"] == "paper+study"
    assert len(doc["claims"]) == len(BIAXIAL_CLAIMS) + len(STUDY_CLAIMS) >= 15
    for row in doc["claims"]:
        assert ROW_KEYS <= set(row), row["id"]
        assert len(row["per_seed"]) == 5 and len(row["ci95"]) == 2
        assert row["verdict"] in ("reproduced", "not reproduced", "inconclusive")
    names = [b["variant"] for b in doc["variants"]]
    assert names[:4] == ["paper", "lambda_raw", "study", "rate=1%/min"] and names[4].startswith("rates ")
    paper = doc["variants"][0]
    assert paper["wall_time_s"]["mean"] == pytest.approx(103.0)
    # 2 %/min against 1 %/min: the same measures, so every quantity is within
    (entry,) = doc["rate_convergence"]
    assert entry["rate"] == "2%/min" and entry["half_rate"] == "1%/min" and entry["converged"]
    with open(tmp_path / "claims.csv") as f:
        table = list(csv.DictReader(f))
    assert len(table) == sum(len(b["claims"]) for b in doc["variants"])
    assert {r["variant"] for r in table} >= {"paper", "study", "lambda_raw"}
    for row in doc["claims"]:
        if row["mean"] is not None:
            assert math.isfinite(row["mean"])
    assert "paper/seed-1" in json.loads((tmp_path / "measures.json").read_text())


def test_the_page_is_self_contained_with_every_figure_embedded(tmp_path, monkeypatch):
    plan = ReproductionPlan.build(3, ["paper", "boundary_b"])
    written = _write(plan, tmp_path, monkeypatch, figures=True)
    html = (tmp_path / "reproduction.html").read_text()
    comparisons = html.split('id="comparisons"')[1].split("</section>")[0]
    assert "boundary_b" in comparisons and "peak_stress_ratio" in comparisons
    assert "<script" not in html and "http://" not in html and "https://" not in html
    pngs = [p for p in written.files if p.suffix == ".png"]
    assert {p.stem for p in pngs} >= {"macro_paper", "fabric_paper", "band_paper"}
    assert html.count("data:image/png;base64,") == len(pngs)
    assert (tmp_path / "reproduction.html").stat().st_size < 1_500_000
    for row in written.document["claims"]:
        assert row["id"] in html


def test_each_variant_is_compared_with_the_variant_nearest_in_configuration():
    plan = ReproductionPlan.build(3, ["paper", "boundary_b", "rate=8%/min",
                                      "set:shear.strain_rate=8%/min,run.time_step_safety=0.5", "lambda_raw"])
    pairs = {v.name: (ref.name, keys) for v, ref, keys in outputs.comparison_pairs(plan)}
    assert pairs["boundary_b"] == ("paper", ["boundary.kind"])
    assert pairs["rate=8%/min"] == ("paper", ["shear.strain_rate"])
    # one key from the 8 %/min run, two from paper's: compared with the 8 %/min run
    assert pairs["set:shear.strain_rate=8%/min,run.time_step_safety=0.5"] == (
        "rate=8%/min", ["run.time_step_safety"])
    assert "paper" not in pairs and "lambda_raw" not in pairs  # the reference itself; analysis only


def test_a_paired_comparison_finds_a_shift_beyond_the_tolerance_and_not_noise():
    base = [paper_like(s) for s in SEEDS]
    same = variant_comparison_of(base, base)
    assert same["all_within"] and same["quantities"]["peak_stress_ratio"]["difference"] == 0.0
    shifted = []
    for m in base:
        m = json.loads(json.dumps(m))
        m["macro"]["peak_stress_ratio"] *= 1.10  # 10 % higher peak, every seed
        shifted.append(m)
    result = variant_comparison_of(shifted, base)
    peak = result["quantities"]["peak_stress_ratio"]
    assert not peak["within"] and not result["all_within"]
    assert peak["difference"] == pytest.approx(0.10 * peak["reference_mean"], rel=1e-9)
    assert peak["ci95"][0] > 0.0 and peak["n"] == 5
    assert result["quantities"]["final_volumetric_strain"]["within"]


def variant_comparison_of(measures, reference):
    return outputs.variant_comparison(measures, reference)


def test_claims_md_is_the_verdict_tables_of_claims_json(tmp_path, monkeypatch):
    from grainlab.reproduction.markdown import claims_markdown

    plan = ReproductionPlan.build(5, ["paper", "boundary_b", "rate=1%/min"])
    _write(plan, tmp_path, monkeypatch, figures=False)
    doc = json.loads((tmp_path / "claims.json").read_text())
    text = (tmp_path / "claims.md").read_text()
    assert text == claims_markdown(doc)
    lines = text.splitlines()
    for row in doc["claims"]:  # one table line per claim, with its verdict
        (line,) = [ln for ln in lines if ln.startswith(f"| `{row['id']}` |") and row["verdict"] in ln]
        assert f"| {row['n']} |" in line
    assert "## Rate convergence" in text and "| 2%/min | 1%/min | peak σ1/σ3 |" in text
    assert "| `boundary_b` | `paper` | peak σ1/σ3 |" in text


def test_band_grains_before_the_detector_accepts_the_band_are_those_of_the_first_accepted_band():
    from types import SimpleNamespace

    import numpy as np

    from grainlab.reproduction.measures import _band_members

    def snap(ids):
        ids = np.asarray(ids)
        return SimpleNamespace(ids=ids, is_sample=ids < 100)  # id 100: a membrane disk

    snaps = [snap([0, 1, 2, 3, 100]), snap([3, 2, 1, 0, 100]), snap([1, 0, 3, 2, 100]), snap([0, 1, 2, 3, 100])]
    none = np.zeros(5, np.int32)
    labels = [None, none, np.array([1, 0, 2, 0, 0], np.int32), none]  # band: ids 1 and 3
    members = _band_members(snaps, labels)
    assert members[3] is None  # nothing accepted at or after the last snapshot
    for k in (0, 1, 2):
        inside, source = members[k]
        assert source == 2
        assert set(np.asarray(snaps[k].ids)[inside]) == {1, 3}


def test_the_fastest_converged_rate_is_the_top_of_an_unbroken_chain():
    entry = lambda rate, ok: {"rate_per_s": rate, "converged": ok}  # noqa: E731
    assert outputs.fastest_converged_rate([entry(2, True), entry(4, True), entry(8, False)]) == 4.0
    assert outputs.fastest_converged_rate([entry(8, True), entry(2, False), entry(4, True)]) is None
    assert outputs.fastest_converged_rate([]) is None
