"""``claims.md``: the verdicts of a reproduction as Markdown tables, from the
``claims.json`` document alone (so a stored ``claims.json`` gives the same tables
again: docs/reproduction.md quotes them and a test keeps them equal).

Sections: the main claims (id, the paper's value, mean, 95 % interval, n,
verdict), the verdicts of every claim in every variant side by side, the rate
convergence, the paired comparisons of variants and the wall times.
"""

from __future__ import annotations

import functools
import json
import re
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path
from typing import Any

from grainlab._html import fmt

__all__ = ["CLAIM_SETS", "SENSITIVITY_CLAIMS", "claims_markdown", "generated_blocks", "named_sensitivity_markdown",
           "sensitivity_blocks", "sensitivity_markdown", "update_generated_blocks"]

#: Rate-convergence and comparison quantities, as the tables name them.
QUANTITY_LABELS = {
    "peak_stress_ratio": "peak σ1/σ3",
    "residual_stress_ratio": "end-window σ1/σ3",
    "final_volumetric_strain": "final εv",
    "band_minus_rest_lambda": "band − rest λ (peak)",
}
#: Short verdicts for the side-by-side table.
SHORT = {"reproduced": "yes", "not reproduced": "**no**", "inconclusive": "?"}


#: A number in a table: :func:`grainlab._html.fmt` without trailing zeros (``4.6``, ``n/a``).
_num = functools.partial(fmt, trailing_zeros=False)


def _interval(ci: Sequence[Any]) -> str:
    if not ci or ci[0] is None or ci[1] is None:
        return "n/a"
    return f"[{_num(ci[0])}, {_num(ci[1])}]"


def _table(header: Sequence[str], rows: Iterable[Sequence[str]]) -> list[str]:
    lines = ["| " + " | ".join(header) + " |", "| " + " | ".join("---" for _ in header) + " |"]
    lines += ["| " + " | ".join(str(c).replace("|", "\\|") for c in row) + " |" for row in rows]
    return lines


def _paper_value(row: dict[str, Any]) -> str:
    value = row.get("paper_value")
    return "–" if value is None else _num(value)


def claims_markdown(document: dict[str, Any], level: int = 1) -> str:
    """The Markdown text of ``claims.md`` for a ``claims.json`` document; ``level``:
    the heading level of its title (sections one below)."""
    counts = document.get("verdict_counts", {})
    h1, h2 = "#" * level, "#" * (level + 1)
    out = [
        f"{h1} Claims: {document['variant']}",
        "",
        f"Seeds {', '.join(str(s) for s in document['seeds'])}; grainlab {document['grainlab_version']}"
        + ("; quick mode" if document.get("quick") else "") + ". "
        + ", ".join(f"{n} {v}" for v, n in counts.items()) + ".",
        "",
        f"{h2} The paper's claims",
        "",
    ]
    out += _table(
        ["id", "paper", "mean", "95 % interval", "n", "verdict"],
        ([f"`{r['id']}`", _paper_value(r), _num(r["mean"]), _interval(r["ci95"]), str(r["n"]), r["verdict"]]
         for r in document["claims"]),
    )
    blocks = [b for b in document.get("variants", []) if b.get("kind") != "rate"]
    if len(blocks) > 1:
        out += ["", f"{h2} Every variant", "",
                "Verdict (yes = reproduced, **no** = not reproduced, ? = inconclusive) and seed mean.", ""]
        ids: list[str] = []
        for b in blocks:
            ids += [r["id"] for r in b["claims"] if r["id"] not in ids]
        by = {b["variant"]: {r["id"]: r for r in b["claims"]} for b in blocks}
        rows = []
        for claim in ids:
            cells = [f"`{claim}`"]
            for b in blocks:
                r = by[b["variant"]].get(claim)
                cells.append("" if r is None else f"{SHORT.get(r['verdict'], r['verdict'])} {_num(r['mean'])}")
            rows.append(cells)
        out += _table(["claim"] + [f"`{b['variant']}`" for b in blocks], rows)
        out += ["", "Counts: " + "; ".join(
            f"`{b['variant']}` " + ", ".join(f"{n} {v}" for v, n in b["verdict_counts"].items()) for b in blocks) + "."]
    for b in document.get("variants", []):
        if b.get("kind") == "rate":
            out += ["", f"{h2} {b['variant']}", "", b["description"] + ".", ""]
            out += _table(["id", "mean", "95 % interval", "n", "verdict"],
                          ([f"`{r['id']}`", _num(r["mean"]), _interval(r["ci95"]), str(r["n"]), r["verdict"]]
                           for r in b["claims"]))
    if document.get("rate_convergence"):
        out += ["", f"{h2} Rate convergence", "",
                "Seed means at r and r/2; within: |difference| ≤ max(3 % of the value at r/2, its seed "
                "standard deviation).", ""]
        rows = []
        for e in document["rate_convergence"]:
            for name, q in e["quantities"].items():
                rows.append([e["rate"], e["half_rate"], QUANTITY_LABELS.get(name, name), _num(q["at_rate"]),
                             _num(q["at_half_rate"]), _num(q["tolerance"], 2), _num(q["within"]),
                             "**converged**" if e["converged"] else "not converged"])
        out += _table(["r", "r/2", "quantity", "at r", "at r/2", "tolerance", "within", "r"], rows)
        fastest = document.get("fastest_converged_rate_per_s")
        out += ["", "Fastest converged rate (it and every slower rate converged): "
                + ("none: the slowest comparison already differs" if fastest is None
                   else f"{fastest * 6000:g} %/min ({fastest:.4g} 1/s)") + "."]
    if document.get("comparisons"):
        out += ["", f"{h2} Variants against their reference", "",
                "Paired per seed: the variant's mean minus its reference's, with the 95 % interval of the "
                "paired differences; within: as the rate convergence.", ""]
        rows = []
        for c in document["comparisons"]:
            for name, q in c["quantities"].items():
                rows.append([f"`{c['variant']}`", f"`{c['reference']}`", QUANTITY_LABELS.get(name, name),
                             _num(q["mean"]), _num(q["reference_mean"]), _num(q["difference"], 2),
                             _interval(q["ci95"]), str(q["n"]), _num(q["tolerance"], 2), _num(q["within"])])
        out += _table(["variant", "reference", "quantity", "mean", "reference", "difference", "95 % interval",
                       "n", "tolerance", "within"], rows)
    walls = [b for b in document.get("variants", []) if b.get("wall_time_s", {}).get("mean") is not None]
    if walls:
        out += ["", f"{h2} Wall time", ""]
        out += _table(["variant", "runs of", "mean per seed (s)", "total (s)"],
                      ([f"`{b['variant']}`", f"`{b['runs_of']}`", _num(b["wall_time_s"]["mean"], 4),
                        _num(b["wall_time_s"]["total"], 4)] for b in walls))
    return "\n".join(out) + "\n"


#: A block of a Markdown page generated from a stored ``claims.json`` (path relative
#: to the repository root): :func:`update_generated_blocks` rewrites its body.
GENERATED_BLOCK = re.compile(
    r"(<!-- generated from (?P<path>\S+) by claims_markdown\(level=(?P<level>\d)\) -->\n)(?P<body>.*?)"
    r"(<!-- end of generated block -->)",
    re.S,
)


#: The rows of the verdict-sensitivity table: the claims about the band and lambda, and
#: the initial state's, in the order docs/reproduction.md discusses them.
SENSITIVITY_CLAIMS: tuple[str, ...] = (
    "band_lambda_above_rest",
    "band_lambda_above_rest_all",
    "band_lambda_above_rest_at_end",
    "band_lambda_above_rest_all_at_end",
    "band_lambda_above_rest_at_equal_contacts",
    "lambda_locates_band_at_equal_contacts",
    "lambda_adds_to_contacts",
    "band_lambda_0.34",
    "rest_lambda_0.31",
    "band_lambda_0.34_all",
    "rest_lambda_0.31_all",
    "band_lambda_above_half",
    "lambda_locates_band",
    "lambda_field_locates_band",
    "band_at_peak",
    "band_readings_agree",
    "band_readings_agree_at_end",
    "band_z_below_rest",
    "lambda_tracks_coordination",
    "z_initial",
    "z_initial_mechanical",
    "a_isotropic",
)


def _study_claims() -> tuple[str, ...]:
    from grainlab.reproduction.claims import STUDY_CLAIMS

    return tuple(c.id for c in STUDY_CLAIMS)


#: The claim sets a sensitivity block may name: ``sensitivity_markdown()`` the band and
#: lambda claims (a row per claim), ``sensitivity_markdown(study)`` the packing study's (a
#: row per variant: the readings of lambda on one study's packings).
CLAIM_SETS: dict[str, Callable[[], tuple[str, ...]]] = {"": lambda: SENSITIVITY_CLAIMS, "study": _study_claims}


def sensitivity_markdown(documents: Sequence[dict[str, Any]], claims: Sequence[str] = SENSITIVITY_CLAIMS,
                         *, rows_are_variants: bool = False) -> str:
    """The verdict-sensitivity table: one row per claim of ``claims``, one column per
    variant block (rate families left out) of each document in turn, a variant that an
    earlier document has already shown left out (``rows_are_variants``: a row per
    variant, a column per claim); each cell the
    verdict (yes / **no** / ?) and the seed mean, with n when it is not the block's
    seed count; empty where the variant has no such claim."""
    blocks: list[dict[str, Any]] = []
    for d in documents:  # a variant shown by an earlier document (its reference, re-run there) once
        blocks += [b for b in d.get("variants", []) if b.get("kind") != "rate"
                   and b["variant"] not in {x["variant"] for x in blocks}]
    by = [{r["id"]: r for r in b["claims"]} for b in blocks]

    def cell(b: dict[str, Any], rows_of: dict[str, Any], claim: str) -> str:
        r = rows_of.get(claim)
        if r is None:
            return ""
        n = "" if r["n"] == len(b.get("seeds", [])) else f" (n {r['n']})"
        return f"{SHORT.get(r['verdict'], r['verdict'])} {_num(r['mean'])}{n}"

    if rows_are_variants:
        header = ["variant"] + [f"`{c}`" for c in claims]
        rows = [[f"`{b['variant']}` ({len(b.get('seeds', []))})"] + [cell(b, rows_of, c) for c in claims]
                for b, rows_of in zip(blocks, by, strict=True)]
    else:
        header = ["claim"] + [f"`{b['variant']}` ({len(b.get('seeds', []))})" for b in blocks]
        rows = [[f"`{c}`"] + [cell(b, rows_of, c) for b, rows_of in zip(blocks, by, strict=True)] for c in claims]
    return "\n".join(_table(header, rows)) + "\n"


def named_sensitivity_markdown(documents: Sequence[dict[str, Any]], claim_set: str = "") -> str:
    """The table a sensitivity block names by its claim set (:data:`CLAIM_SETS`)."""
    if claim_set not in CLAIM_SETS:
        raise ValueError(f"claim set: expected one of {sorted(CLAIM_SETS)}, got {claim_set!r}")
    return sensitivity_markdown(documents, CLAIM_SETS[claim_set](), rows_are_variants=bool(claim_set))


#: A verdict-sensitivity table generated from stored ``claims.json`` documents (paths
#: relative to the repository root, separated by spaces).
SENSITIVITY_BLOCK = re.compile(
    r"(?P<head><!-- generated from (?P<paths>[^>]+?) by sensitivity_markdown\((?P<set>\w*)\) -->\n)(?P<body>.*?)"
    r"(?P<end><!-- end of generated block -->)",
    re.S,
)


def sensitivity_blocks(text: str) -> list[tuple[list[str], str, str]]:
    """(paths, claim set, body) of every verdict-sensitivity block of ``text``."""
    return [(m["paths"].split(), m["set"], m["body"]) for m in SENSITIVITY_BLOCK.finditer(text)]


def generated_blocks(text: str) -> list[tuple[str, int, str]]:
    """(path, level, body) of every generated block of ``text``."""
    return [(m["path"], int(m["level"]), m["body"]) for m in GENERATED_BLOCK.finditer(text)]


def update_generated_blocks(page: str | Path, root: str | Path) -> int:
    """Rewrites every generated block of the Markdown ``page`` from its stored
    ``claims.json`` (paths relative to ``root``); returns how many it rewrote."""
    page = Path(page)
    text = page.read_text(encoding="utf-8")

    def body(m: re.Match[str]) -> str:
        document = json.loads((Path(root) / m["path"]).read_text(encoding="utf-8"))
        return m.group(1) + claims_markdown(document, int(m["level"])) + m.group(5)

    def table(m: re.Match[str]) -> str:
        documents = [json.loads((Path(root) / p).read_text(encoding="utf-8")) for p in m["paths"].split()]
        return m["head"] + named_sensitivity_markdown(documents, m["set"]) + m["end"]

    new, count = GENERATED_BLOCK.subn(body, text)
    new, tables = SENSITIVITY_BLOCK.subn(table, new)
    page.write_text(new, encoding="utf-8")
    return count + tables


if __name__ == "__main__":  # python -m grainlab.reproduction.markdown docs/reproduction.md
    import sys

    for name in sys.argv[1:]:
        print(f"{name}: {update_generated_blocks(name, Path.cwd())} generated blocks rewritten")
