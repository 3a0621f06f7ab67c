"""docs/shapes-benchmark.md quotes the CEGEO campaign's results: its table and its
verdict are those of benchmarks/data/cegeo_results.json (the summary that
``benchmarks/cegeo_shapes.py summarize`` writes), so a new summary that changes
a number fails here until the page is written again."""

from __future__ import annotations

import json
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PAGE = (ROOT / "docs" / "shapes-benchmark.md").read_text()
RESULTS = json.loads((ROOT / "benchmarks" / "data" / "cegeo_results.json").read_text())


def _table_rows() -> dict[tuple[int, str, float], list[str]]:
    section = PAGE[PAGE.index("| size | eta | seeds |"):]
    rows = {}
    for line in section.splitlines()[2:]:
        if not line.startswith("|"):
            break
        cells = [c.strip() for c in line.strip("|").split("|")]
        size = re.match(r"[\d,]+", cells[0])
        assert size is not None, line
        words = {"at the same strain rate": "slow_damped_same_rate", "half the local damping": "slow_damped",
                 "quarter": "slow", "sixteenth": "slower",
                 "sixty-fourth": "slowest"}
        tag = next((t for w, t in words.items() if w in cells[0]), "")
        rows[(int(size.group(0).replace(",", "")), tag, float(cells[1]))] = cells
    return rows


def test_the_pages_results_table_is_the_stored_summary():
    rows = _table_rows()
    stored = {(r["n_target"], r["tag"], r["eta"]): r for r in RESULTS["rows"]}
    assert set(rows) == set(stored)
    for key, cells in rows.items():
        r = stored[key]
        assert int(cells[2]) == r["seeds"] and int(cells[3]) == r["n_grains"], key
        assert cells[4].split(" ")[0] == f"{r['sin_phi_star']:.3f}", key
        assert cells[5] == f"{r['rho_iso']:.3f}" and cells[6] == f"{r['Zc_iso']:.2f}", key
        assert cells[7] == f"{r['Z_steady']:.2f}, {r['Zc_steady']:.2f}", key
        assert cells[8] == ("yes" if r["all_steady"] else "no"), key


def test_the_pages_verdict_is_the_stored_summarys():
    size = RESULTS["verdict_size"]
    verdict = RESULTS["verdicts"][str(size)]
    match = re.search(r"\*\*The verdict, at size ([\d,]+) \(seed 1\)[^:]*:\s+([a-z ]+)\.\*\*", PAGE)
    assert match is not None
    assert int(match.group(1).replace(",", "")) == size and match.group(2) == verdict["verdict"]
    assert f"the slope, {verdict['slope']:.3f}" in PAGE


def test_the_rolling_proxy_table_is_the_stored_summary():
    stored = json.loads((ROOT / "benchmarks" / "data" / "rolling_proxy.json").read_text())
    section = PAGE[PAGE.index("| eta | mu_r* |"):]
    lines = [line for line in section.splitlines()[2:] if line.startswith("|")]
    assert len(lines) == len(stored["etas"])
    for line, (eta, entry) in zip(lines, stored["etas"].items(), strict=True):
        cells = [c.strip() for c in line.strip("|").split("|")]
        trimers, disks, rule = entry["trimers"], entry["disks"], entry["rule"]
        assert float(cells[0]) == float(eta) and cells[1] == f"{entry['mu_r_star']:.4f}"
        assert cells[2] == f"{trimers['sin_phi_star']:.3f} / {disks['sin_phi_star']:.3f}"
        for cell, key in ((cells[3], "a"), (cells[4], "a_n")):
            agrees = "yes" if rule[f"{key}_agrees"] else "no"
            assert cell == f"{trimers[key]:.3f} / {disks[key]:.3f} ({agrees})"
        assert cells[7] == f"{trimers['mean_lambda']:.3f} / {disks['mean_lambda']:.3f}"
    assert f"({stored['verdict']})" in PAGE
