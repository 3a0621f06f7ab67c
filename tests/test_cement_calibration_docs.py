"""docs/cemented.md's calibration numbers are the stored campaign summary's
(benchmarks/data/cement_calibration.json, made by benchmarks/cement_calibration.py)."""

from __future__ import annotations

import json
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PAGE = " ".join((ROOT / "docs" / "cemented.md").read_text().split())
SUMMARY = json.loads((ROOT / "benchmarks" / "data" / "cement_calibration.json").read_text())


def test_the_pages_calibration_table_is_the_stored_summary():
    for point in SUMMARY["points"]:
        u, e = point.get("unconfined_strength_pa"), point.get("youngs_modulus_pa")
        if u is None:
            continue
        cells = f"| {u['mean'] / 1e3:.0f} ± {u['sd'] / 1e3:.0f} | {e['mean'] / 1e6:.0f} ± {e['sd'] / 1e6:.0f} |"
        assert cells in PAGE, (point["label"], cells)


def test_the_pages_rule_readings_are_the_stored_summarys():
    rules = SUMMARY["rules"]
    strength = rules["rule 1 (unconfined_strength_pa)"]
    assert strength["holds"] and f"ln sigma_c is {strength['slope']:.2f}" in PAGE
    stiffness = rules["rule 2"]
    assert not stiffness["holds"] and f"a spread of {stiffness['spread']:.2f}" in PAGE
    assert ", ".join(f"{v:.2f}" for v in stiffness["E_over_parallel_stiffness"][:2]) in PAGE


def test_the_pages_tensile_strengths_and_ratios_are_the_stored_summarys():
    for point in SUMMARY["points"]:
        t, u = point["tensile_strength_pa"], point["unconfined_strength_pa"]
        cells = f"| {t['mean'] / 1e3:.0f} ± {t['sd'] / 1e3:.0f} | {u['mean'] / t['mean']:.2f} |"
        assert t["n"] == 5 and cells in PAGE, (point["label"], cells)
    rules = SUMMARY["rules"]
    tensile = rules["rule 1 (tensile_strength_pa)"]
    assert tensile["holds"] and f"ln sigma_t against ln sigma_c is {tensile['slope']:.2f}" in PAGE
    ratio = rules["rule 3"]
    assert ratio["shortfall"] and f"base point is {ratio['ratio']:.2f}, below half of granite's" in PAGE


def test_the_pages_size_effect_is_the_stored_summarys():
    big = SUMMARY["default_size_base"]
    u, e, t = big["unconfined_strength_pa"], big["youngs_modulus_pa"], big["tensile_strength_pa"]
    assert u["n"] == e["n"] == t["n"] == 3
    assert f"q_u {u['mean'] / 1e3:.0f} ± {u['sd'] / 1e3:.0f} kPa, E {e['mean'] / 1e6:.0f} ± {e['sd'] / 1e6:.0f} MPa" in PAGE
    assert f"sigma_t {t['mean'] / 1e3:.0f} ± {t['sd'] / 1e3:.0f} kPa" in PAGE
    assert f"to {u['mean'] / t['mean']:.2f}" in PAGE
    # every point's ratio lies in the range the page gives
    ratios = [p["unconfined_strength_pa"]["mean"] / p["tensile_strength_pa"]["mean"] for p in SUMMARY["points"]]
    assert f"between {min(ratios):.2f} and {max(ratios):.2f}" in PAGE
