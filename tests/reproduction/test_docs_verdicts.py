"""The paper-scale verdicts quoted in docs/reproduction.md are the stored campaign's:
every generated block equals claims_markdown of the claims.json it names."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from grainlab.reproduction.markdown import (
    claims_markdown,
    generated_blocks,
    named_sensitivity_markdown,
    sensitivity_blocks,
    sensitivity_markdown,
    update_generated_blocks,
)

ROOT = Path(__file__).resolve().parents[2]


def test_generated_blocks_match_their_stored_claims():
    blocks = generated_blocks((ROOT / "docs" / "reproduction.md").read_text(encoding="utf-8"))
    assert len(blocks) >= 3  # the main ensemble, the rates, the slowest rate
    for path, level, body in blocks:
        document = json.loads((ROOT / path).read_text(encoding="utf-8"))
        assert body == claims_markdown(document, level), f"{path}: rerun python -m grainlab.reproduction.markdown"


def test_sensitivity_tables_match_their_stored_claims():
    blocks = sensitivity_blocks((ROOT / "docs" / "reproduction.md").read_text(encoding="utf-8"))
    assert {claim_set for _, claim_set, _ in blocks} == {"", "study"}
    for paths, claim_set, body in blocks:
        documents = [json.loads((ROOT / p).read_text(encoding="utf-8")) for p in paths]
        assert body == named_sensitivity_markdown(documents, claim_set), "rerun python -m grainlab.reproduction.markdown"


def test_a_sensitivity_table_has_a_column_per_variant_and_marks_partial_counts(tmp_path):
    def block(variant, rows):
        return {"variant": variant, "kind": "biaxial", "seeds": [1, 2, 3], "claims": rows}

    row = {"id": "band_lambda_above_rest", "mean": 0.012, "n": 3, "verdict": "reproduced"}
    partial = {"id": "band_lambda_above_rest", "mean": -0.5, "n": 2, "verdict": "not reproduced"}
    docs = [{"variants": [block("paper", [row]), {"variant": "rates", "kind": "rate", "claims": []}]},
            {"variants": [block("paper", [partial]), block("band:final", [partial])]}]
    text = sensitivity_markdown(docs, ["band_lambda_above_rest", "z_initial"])
    lines = text.splitlines()
    assert lines[0] == "| claim | `paper` (3) | `band:final` (3) |"
    assert lines[2] == "| `band_lambda_above_rest` | yes 0.012 | **no** -0.5 (n 2) |"
    assert lines[3] == "| `z_initial` |  |  |"
    by_variant = sensitivity_markdown(docs, ["band_lambda_above_rest"], rows_are_variants=True).splitlines()
    assert by_variant[0] == "| variant | `band_lambda_above_rest` |"
    assert by_variant[2:] == ["| `paper` (3) | yes 0.012 |", "| `band:final` (3) | **no** -0.5 (n 2) |"]
    with pytest.raises(ValueError, match="claim set"):
        named_sensitivity_markdown(docs, "nope")
    (tmp_path / "a.json").write_text(json.dumps(docs[0]))
    (tmp_path / "b.json").write_text(json.dumps(docs[1]))
    page = tmp_path / "page.md"
    page.write_text("<!-- generated from a.json b.json by sensitivity_markdown() -->\nstale\n"
                    "<!-- end of generated block -->\n")
    assert update_generated_blocks(page, tmp_path) == 1
    assert "stale" not in page.read_text() and "| `band_lambda_0.34` |" in page.read_text()


def test_a_stale_block_is_rewritten(tmp_path):
    doc = {"variant": "paper", "seeds": [1, 2], "grainlab_version": "x", "verdict_counts": {"reproduced": 1},
           "claims": [{"id": "c", "paper_value": 1.0, "mean": 1.0, "ci95": [0.9, 1.1], "n": 2,
                       "verdict": "reproduced"}]}
    (tmp_path / "c.json").write_text(json.dumps(doc))
    page = tmp_path / "page.md"
    page.write_text("intro\n<!-- generated from c.json by claims_markdown(level=3) -->\nold\n"
                    "<!-- end of generated block -->\noutro\n")
    assert update_generated_blocks(page, tmp_path) == 1
    text = page.read_text()
    assert text.startswith("intro\n") and text.endswith("outro\n") and "old" not in text
    assert "### Claims: paper" in text and "| `c` | 1 | 1 | [0.9, 1.1] | 2 | reproduced |" in text


def test_the_default_run_quoted_in_biaxial_md_is_the_campaign_seed_1():
    # docs/biaxial.md quotes the default run, which is seed 1 of the stored main ensemble
    document = json.loads((ROOT / "python/grainlab/reproduction/paper_scale/main.json").read_text(encoding="utf-8"))
    rows = {row["id"]: row for row in document["claims"]}
    seed_1 = document["seeds"].index(1)
    page = (ROOT / "docs" / "biaxial.md").read_text(encoding="utf-8")
    z0 = rows["z_initial"]["per_seed"][seed_1]
    peak_strain = rows["peak_near_1.5"]["per_seed"][seed_1]
    assert f"| coordination number, initial | {z0:.2f} |" in page
    assert f"at {100 * peak_strain:.2f} % axial strain |" in page


#: The numbers the page's short verdict quotes: (variant, claim id), as "mean [low, high]".
QUOTED = [
    ("paper", "band_lambda_above_rest_all"), ("paper", "band_lambda_above_rest"), ("paper", "lambda_locates_band"),
    ("paper", "band_lambda_above_rest_at_equal_contacts"), ("paper", "band_lambda_above_rest_n2"),
    ("paper", "band_lambda_above_rest_n3"), ("paper", "band_lambda_above_rest_n4"),
    ("paper", "band_lambda_above_rest_n5plus"), ("paper", "lambda_adds_to_contacts"),
    ("paper", "contacts_locate_band"), ("paper", "z_initial_mechanical"), ("paper", "lambda_tracks_coordination"),
    ("lambda:deviation=per_contact", "lambda_tracks_coordination"), ("band:displacement", "band_lambda_above_rest_all"),
    ("band:final", "band_lambda_above_rest_all"),
]


def test_the_short_verdict_quotes_the_stored_ensemble():
    document = json.loads((ROOT / "python/grainlab/reproduction/paper_scale/main.json").read_text(encoding="utf-8"))
    page = (ROOT / "docs" / "reproduction.md").read_text(encoding="utf-8")
    short = page[page.index("## The verdict, in short"):page.index("### Verdict sensitivity")]
    blocks = {b["variant"]: {r["id"]: r for r in b["claims"]} for b in document["variants"]}
    for variant, claim in QUOTED:
        row = blocks[variant][claim]
        low, high = row["ci95"]
        assert f"{row['mean']:+.3f} [{low:.3f}, {high:.3f}]" in short, (variant, claim)
    # the events: a two-block split accepted at the peak in 1 of 20 seeds, the lambda > 0.5 zone in none
    assert round(20 * blocks["band:displacement"]["band_at_peak"]["mean"]) == 1 and "in 1 of 20" in short
    assert blocks["band:lambda"]["band_at_peak"]["mean"] == 0.0 and "0 of 20 seeds" in short
    assert len(document["seeds"]) == 20 and "**20 seeds**" in short
