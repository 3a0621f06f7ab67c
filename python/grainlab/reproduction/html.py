"""``reproduction.html``: the verdict on every claim, one self-contained page
(the report's building blocks, :mod:`grainlab._html`: figures as PNG
``data:`` URIs, no scripts, no network)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import grainlab
from grainlab._html import (
    EmbeddedFigure,
    Markup,
    code_block,
    definition_table,
    escape,
    figures,
    fmt,
    footer,
    page,
    paragraph,
    section,
    table,
)
from grainlab.io.results import write_text_atomic
from grainlab.reproduction.runs import ReproductionPlan, variant_folder
from grainlab.reproduction.verdicts import VERDICTS

__all__ = ["claims_table", "write_html"]

_FIGURE_CAPTIONS = {
    "macro": "Stress ratio and volumetric strain against axial strain: each seed (grey), the mean over seeds "
             "and its 95 % interval.",
    "fabric": "Contact-normal and normal-force anisotropy, coordination number and mean lambda at the snapshots, "
              "recomputed with this grainlab; crosses and the shaded range: the paper's values.",
    "band": "The band-resolved fabric: at each snapshot the shear-band detector's band (found in the local strain "
            "since 0 %; snapshots without an accepted band are left out) against the other grains; last panel: "
            "how well lambda alone ranks band grains above the others (0.5: not at all).",
    "study": "The packing study's mean lambda against Z, porosity and anisotropy for every seed.",
    "rates": "Peak and end-window stress ratios against the strain rate (mean and 95 % interval over seeds).",
    "strata": "At the peak: mean lambda of the band's grains and of the rest among grains with the same number "
              "of contacts (mean over seeds, 95 % interval), and what tells band grains from the rest: lambda, "
              "lambda within contact numbers, the contact number alone and with lambda (out-of-sample ROC AUCs; "
              "0.5: nothing).",
    "bandreadings": "The readings of the band over the first seed's displacement map, near the peak and at the "
                    "end: the two-block split of the displacements (the paper's Fig. 11), the band accepted in "
                    "the local strain and the zone of lambda > 0.5 (Fig. 12) where one is accepted.",
}


def _value(v: Any, digits: int = 3) -> str:
    return "n/a" if v is None else fmt(float(v), digits)


def claims_table(rows: Sequence[Mapping[str, Any]], *, detail: bool = True) -> Markup:
    """One row per claim: the paper's statement and value, the ensemble's measure and the verdict."""
    headers = ["claim", "the paper", "where", "paper's value", "measured per seed", "mean", "95 % interval", "n",
               "verdict"]
    if detail:
        headers.insert(5, "per seed")
        headers.append("test and reason")
    body, classes = [], []
    for r in rows:
        ci = r["ci95"]
        cells: list[Any] = [
            Markup(f"<code>{escape(r['id'])}</code>"), r["statement"], r["source"], _value(r["paper_value"]),
            r["measure"], _value(r["mean"], 4),
            "n/a" if ci[0] is None else f"[{fmt(ci[0], 3)}, {fmt(ci[1], 3)}]", str(r["n"]), r["verdict"],
        ]
        if detail:
            cells.insert(5, ", ".join(_value(v) for v in r["per_seed"]))
            cells.append(f"{r['test']}; {r['reason']}")
        body.append(cells)
        classes.append("verdict-" + r["verdict"].replace(" ", "-"))
    return table(headers, body, css_class="wide", row_classes=classes,
                 cell_classes={headers.index("verdict"): "verdict"})


def _counts_table(blocks: Sequence[Mapping[str, Any]]) -> Markup:
    rows = []
    for b in blocks:
        counts = b["verdict_counts"]
        wall = b.get("wall_time_s", {}) or {}
        rows.append([b["variant"], b["description"], *[str(counts[v]) for v in VERDICTS],
                     _value(wall.get("mean"), 3) if wall else "", _value(wall.get("total"), 3) if wall else ""])
    return table(["variant", "what it is", *VERDICTS, "wall time per seed (s)", "wall time, all seeds (s)"], rows,
                 numeric=(2, 3, 4, 5, 6))


def _rate_table(entries: Sequence[Mapping[str, Any]]) -> Markup:
    rows = []
    for e in entries:
        for name, q in e["quantities"].items():
            rows.append([e["rate"], e["half_rate"], name, _value(q.get("at_rate"), 4), _value(q.get("at_half_rate"), 4),
                         _value(q.get("tolerance"), 3), "n/a" if q.get("within") is None else fmt(q["within"]),
                         fmt(e["converged"])])
    return table(["rate r", "r/2", "quantity", "mean at r", "mean at r/2", "tolerance", "within", "r converged"],
                 rows, numeric=(3, 4, 5))


def _comparison_table(entries: Sequence[Mapping[str, Any]]) -> Markup:
    rows = []
    for c in entries:
        for name, q in c["quantities"].items():
            ci = q.get("ci95") or [None, None]
            rows.append([c["variant"], c["reference"], name, _value(q.get("mean"), 4),
                         _value(q.get("reference_mean"), 4), _value(q.get("difference"), 3),
                         f"[{_value(ci[0], 3)}, {_value(ci[1], 3)}]", str(q.get("n", 0)), _value(q.get("tolerance"), 3),
                         "n/a" if q.get("within") is None else fmt(q["within"])])
    return table(["variant", "reference", "quantity", "mean", "reference mean", "difference", "95 % interval",
                  "n", "tolerance", "within"], rows, numeric=(3, 4, 5, 7, 8))


def _figure(name: str, path: Path) -> EmbeddedFigure:
    kind = name.split("_", 1)[0]
    return EmbeddedFigure(name, name.replace("_", " "), _FIGURE_CAPTIONS.get(kind, ""), path.read_bytes(),
                          f"figures/{path.name}")


def write_html(path: str | Path, plan: ReproductionPlan, document: Mapping[str, Any],
               drawn: Mapping[str, Path]) -> Path:
    """Writes the page to ``path`` atomically; returns ``path``."""
    blocks = document["variants"]
    main = document["variant"].split("+")
    out_dir = Path(path).parent
    header = Markup(
        "<h1>Does the paper's finding hold?</h1>"
        f"<p>grainlab reproduce of <code>{escape(out_dir)}</code>: seeds {escape(', '.join(map(str, plan.seeds)))}"
        f"{' (quick: small samples)' if plan.quick else ''}; variants {escape(', '.join(v.name for v in plan.variants))}"
        f"; grainlab {escape(grainlab.__version__)}</p>"
        "<p>Every number below is recomputed from the stored runs by this grainlab; the rules were fixed before "
        "any run (docs/reproduction.md).</p>"
    )
    counts = document["verdict_counts"]
    glance = Markup('<div class="glance">' + "".join(
        f'<div><span class="v">{counts[v]}</span><span class="k">{escape(v)}</span></div>' for v in VERDICTS)
        + "</div>")
    sections = [
        section("verdicts", "Verdicts", paragraph(f"The paper's claims ({document['variant']}):"), glance,
                _counts_table(blocks)),
        section("claims", "The paper's claims", claims_table(document["claims"])),
    ]
    for b in blocks:
        if b["variant"] in main:
            continue
        notes = [paragraph(n, "note") for n in b.get("notes", [])]
        sections.append(section(f"variant-{variant_folder(b['variant'])}", f"Variant {b['variant']}",
                                paragraph(b["description"]), *notes, claims_table(b["claims"], detail=False)))
    if document.get("rate_convergence"):
        sections.append(section("rates", "Rate convergence", paragraph(
            "For each rate r with a run at r/2: is each quantity's mean over seeds at r within 3 % (or the seed "
            "standard deviation at r/2, whichever is larger) of its mean at r/2?"),
            _rate_table(document["rate_convergence"])))
    if document.get("comparisons"):
        sections.append(section("comparisons", "Variants against their reference", paragraph(
            "Each variant against the variant whose configuration differs from it in the fewest keys, paired "
            "per seed; within: the rate convergence's tolerance."), _comparison_table(document["comparisons"])))
    by_variant: dict[str, list[EmbeddedFigure]] = {}
    for name, file in drawn.items():
        stem = name.split("_", 1)[1] if "_" in name else name
        by_variant.setdefault(stem, []).append(_figure(name, file))
    for stem, figs in by_variant.items():
        sections.append(section(f"figures-{stem}", f"Figures: {stem}", figures(figs)))
    sections.append(section("method", "Method and files", definition_table([
        ("ensemble", f"seeds {', '.join(map(str, plan.seeds))}: seed k is the sample seed of every biaxial "
                     "variant (paired comparisons pair them)"),
        ("runs", "runs/<variant>/seed-<k>/ (biaxial: biaxial/run.h5; study: one folder per packing)"),
        ("claims", "claims.json, claims.csv (one row per variant and claim); measures.json (every number measured)"),
        ("notes", "; ".join(document.get("notes", [])) or "none"),
    ]), code_block(f"grainlab reproduce --out {out_dir} --claims-only   # recompute from the runs")))
    text = page("grainlab reproduce: does the paper's finding hold?", header, sections, footer())
    return write_text_atomic(path, text)
