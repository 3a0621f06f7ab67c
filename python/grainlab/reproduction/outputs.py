"""From the runs of a reproduction to ``claims.json``, ``claims.csv``, ``measures.json``,
the figures and ``reproduction.html``, all recomputed from the stored runs.

The files and their fields: docs/reproduction.md, "Outputs".
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

import grainlab
from grainlab.io.results import write_json_atomic, write_text_atomic
from grainlab.reproduction.claims import BIAXIAL_CLAIMS, RATE_CLAIMS, STUDY_CLAIMS, evaluate
from grainlab.reproduction.markdown import claims_markdown
from grainlab.reproduction.measures import (
    measure_biaxial_each,
    measure_study,
    read_study_rows,
    read_study_rows_each,
)
from grainlab.reproduction.runs import ReproductionPlan, Variant, main_variant, rate_family
from grainlab.reproduction.verdicts import VERDICTS, t_interval

__all__ = ["CLAIMS_CSV", "CLAIMS_JSON", "CLAIMS_MD", "MEASURES_JSON", "Outputs", "comparison_pairs", "rate_convergence",
           "fastest_converged_rate", "variant_comparison", "write_outputs"]

CLAIMS_JSON = "claims.json"
CLAIMS_CSV = "claims.csv"
CLAIMS_MD = "claims.md"
MEASURES_JSON = "measures.json"
HTML_FILE = "reproduction.html"

#: Rate convergence: relative tolerance (or the seed scatter, whichever is larger).
RATE_TOLERANCE = 0.03

#: claims.csv columns.
CSV_COLUMNS = ("variant", "id", "verdict", "mean", "ci95_low", "ci95_high", "n", "paper_value", "statement",
               "source", "measure", "test", "reason", "p_value", "per_seed")


def _measure_task(kind: str, path: str, options: list[dict[str, Any]]) -> tuple[list[dict[str, Any] | None], str]:
    """The measures of one run under each of ``options`` (a study: one), and a note when it fails."""
    try:
        if kind == "biaxial":
            return list(measure_biaxial_each(path, options)), ""
        return [measure_study(rows) for rows in read_study_rows_each(path, options)], ""
    except Exception as error:  # noqa: BLE001 - one unreadable run must not stop the claims
        return [None] * len(options), f"{path}: {type(error).__name__}: {error}"


#: A run to measure, by (variant, seed, kind), and what to measure: (kind, path, options).
TaskKey = tuple[str, str, str]
Task = tuple[str, str, dict[str, Any]]


def _tasks(plan: ReproductionPlan, out: Path) -> dict[TaskKey, Task]:
    """(variant, seed, kind) -> (kind, path, options) of every run that has finished."""
    tasks: dict[TaskKey, Task] = {}
    for v in plan.variants:
        source = plan.variant(v.runs_variant)
        for seed in plan.seeds:
            if plan.reads(v) == "study":
                folder = plan.study_folder(out, source, seed)
                if any(folder.glob("*/result.json")):
                    tasks[(v.name, str(seed), "study")] = ("study", str(folder), dict(v.analysis))
            else:
                folder = plan.biaxial_folder(out, source, seed)
                if (folder / "run.h5").exists():
                    tasks[(v.name, str(seed), "biaxial")] = ("biaxial", str(folder), dict(v.analysis))
    return tasks


def _compute(
    tasks: dict[TaskKey, Task], workers: int | None, progress: bool
) -> tuple[dict[TaskKey, dict[str, Any] | None], list[str]]:
    """Measures every run once (a biaxial run under every analysis option its variants ask
    for), in ``workers`` local processes; returns the measures by task key and notes."""
    from grainlab._progress import progress_bar

    results: dict[TaskKey, dict[str, Any] | None] = {}
    notes: list[str] = []
    jobs: dict[tuple[str, str], dict[str, list[TaskKey]]] = {}  # (kind, path) -> options text -> task keys
    for key, (kind, path, options) in tasks.items():
        jobs.setdefault((kind, path), {}).setdefault(json.dumps(options, sort_keys=True), []).append(key)

    def collect(job: tuple[str, str], values: list[dict[str, Any] | None], note: str) -> None:
        for keys, value in zip(jobs[job].values(), values, strict=True):
            for key in keys:
                results[key] = value
        if note:
            notes.append(note)
        bar.update(1)

    n_workers = max(1, min(int(workers or (os.cpu_count() or 1)), len(jobs) or 1))
    bar = progress_bar(len(jobs), "claims", enabled=progress, unit="run")
    try:
        if n_workers == 1:
            for job, by_options in jobs.items():
                collect(job, *_measure_task(*job, [json.loads(t) for t in by_options]))
        else:
            import multiprocessing
            from concurrent.futures import ProcessPoolExecutor, as_completed

            context = multiprocessing.get_context("spawn")
            with ProcessPoolExecutor(max_workers=n_workers, mp_context=context) as pool:
                futures = {pool.submit(_measure_task, *job, [json.loads(t) for t in by_options]): job
                           for job, by_options in jobs.items()}
                for future in as_completed(futures):
                    collect(futures[future], *future.result())
    finally:
        bar.close()
    return results, notes


def _block(variant: Variant, plan: ReproductionPlan, measures: list[dict[str, Any] | None], out: Path
           ) -> dict[str, Any]:
    study = plan.reads(variant) == "study"
    claims = STUDY_CLAIMS if study else BIAXIAL_CLAIMS
    rows = evaluate(claims, measures, plan.seeds, variant.name)
    source = plan.variant(variant.runs_variant)
    walls = [] if study else [m.get("wall_time_s") if m else None for m in measures]
    if study:
        runs = [str(plan.study_folder(out, source, s).relative_to(out)) for s in plan.seeds]
        walls = [_study_wall_time(plan.study_folder(out, source, s)) for s in plan.seeds]
    else:
        runs = [str(plan.biaxial_folder(out, source, s).relative_to(out)) for s in plan.seeds]
    finite = [w for w in walls if w is not None and math.isfinite(w)]
    missing = [s for s, m in zip(plan.seeds, measures, strict=True) if m is None]
    notes = [f"seed {s}: no finished run to measure" for s in missing]
    return {
        "variant": variant.name,
        "kind": variant.kind,
        "description": variant.description,
        "runs_of": variant.runs_variant,
        "analysis": dict(variant.analysis),
        "seeds": list(plan.seeds),
        "runs": runs,
        "wall_time_s": {"per_seed": walls, "mean": float(np.mean(finite)) if finite else None,
                        "total": float(np.sum(finite)) if finite else None},
        "claims": rows,
        "verdict_counts": _counts(rows),
        "notes": notes,
    }


def _study_wall_time(folder: Path) -> float | None:
    rows = read_study_rows(folder)
    return float(sum(float(r.get("wall_time_s") or 0.0) for r in rows)) if rows else None


def _counts(rows: Sequence[dict[str, Any]]) -> dict[str, int]:
    return {v: sum(r["verdict"] == v for r in rows) for v in VERDICTS}


# ----------------------------------------------------------------------------- rates
def _band_difference(m: dict[str, Any] | None) -> float:
    """Band minus rest mean lambda (grains with >= 2 contacts) at the peak snapshot,
    the band's grains as the claims take them (:func:`~grainlab.reproduction.claims.band_measure`)."""
    from grainlab.reproduction.claims import band_measure

    if m is None:
        return math.nan
    row = m["snapshots"][m["peak_snapshot"]]
    return band_measure(row, "inside_mean_lambda") - band_measure(row, "outside_mean_lambda")


_RATE_QUANTITIES = {
    "peak_stress_ratio": lambda m: m["macro"]["peak_stress_ratio"] if m else math.nan,
    "residual_stress_ratio": lambda m: m["macro"]["residual_stress_ratio"] if m else math.nan,
    "final_volumetric_strain": lambda m: m["macro"]["final_volumetric_strain"] if m else math.nan,
    "band_minus_rest_lambda": _band_difference,
}


def _tolerance(reference: np.ndarray) -> float:
    """max(3 % of the reference's seed mean, its seed standard deviation): how far a
    mean may differ from it and still count as the same."""
    scatter = float(np.std(reference, ddof=1)) if reference.size > 1 else 0.0
    return max(RATE_TOLERANCE * abs(float(reference.mean())), scatter)


def rate_convergence(family: Sequence[tuple[float, list[dict[str, Any] | None]]]) -> list[dict[str, Any]]:
    """For each rate r with a run at r/2: is each quantity's seed mean at r within
    max(3 % of its value at r/2, the seed standard deviation at r/2) of the mean at r/2?

    ``family``: (rate, per-seed measures) pairs. One entry per such rate, with
    ``converged`` true when every quantity is within.
    """
    out = []
    rates = [r for r, _ in family]
    for rate, measures in family:
        half = [k for k, r in enumerate(rates) if math.isclose(r, rate / 2, rel_tol=1e-6)]
        if not half:
            continue
        slow = family[half[0]][1]
        quantities: dict[str, dict[str, float | bool | None]] = {}
        for name, get in _RATE_QUANTITIES.items():
            a = np.array([float(get(m)) for m in measures], dtype=np.float64)
            b = np.array([float(get(m)) for m in slow], dtype=np.float64)
            a, b = a[np.isfinite(a)], b[np.isfinite(b)]
            if a.size == 0 or b.size == 0:
                quantities[name] = {"at_rate": None, "at_half_rate": None, "tolerance": None, "within": None}
                continue
            tolerance = _tolerance(b)
            quantities[name] = {
                "at_rate": float(a.mean()), "at_half_rate": float(b.mean()),
                "difference": float(a.mean() - b.mean()), "tolerance": tolerance,
                "within": bool(abs(a.mean() - b.mean()) <= tolerance),
            }
        known = [q["within"] for q in quantities.values() if q["within"] is not None]
        out.append({"rate_per_s": rate, "half_rate_per_s": rates[half[0]],
                    "rate": f"{rate * 6000:g}%/min", "half_rate": f"{rates[half[0]] * 6000:g}%/min",
                    "quantities": quantities,
                    "converged": bool(known) and all(known) and len(known) == len(quantities)})
    return out


def fastest_converged_rate(convergence: Sequence[dict[str, Any]]) -> float | None:
    """The fastest rate r (1/s) such that r and every slower rate of the family that
    has a run at half of it are converged (:func:`rate_convergence`): a chain from
    the slowest comparison up. None when the slowest comparison already fails (or
    there is none)."""
    fastest = None
    for entry in sorted(convergence, key=lambda e: e["rate_per_s"]):
        if not entry["converged"]:
            break
        fastest = float(entry["rate_per_s"])
    return fastest


# ----------------------------------------------------------------------------- variant pairs
def _config_leaves(plan: ReproductionPlan, v: Variant) -> dict[str, Any]:
    config = plan.biaxial_config(plan.variant(v.runs_variant), plan.seeds[0]).to_dict()
    return {f"{section}.{key}": value for section, keys in config.items() if isinstance(keys, dict)
            for key, value in keys.items()}


def comparison_pairs(plan: ReproductionPlan) -> list[tuple[Variant, Variant, list[str]]]:
    """Each biaxial variant that runs its own configuration, other than the main one,
    with its reference: the biaxial variant whose configuration differs from it in the
    fewest keys (the main variant on a tie), and those keys."""
    main = main_variant(plan, "biaxial")
    own = [v for v in plan.variants if v.kind == "biaxial" and not v.source]
    if main is None or len(own) < 2:
        return []
    leaves = {v.name: _config_leaves(plan, v) for v in own}
    pairs = []
    for v in own:
        if v.name == main.name:
            continue

        def differing(other: Variant, v: Variant = v) -> list[str]:
            a, b = leaves[v.name], leaves[other.name]
            return sorted(k for k in set(a) | set(b) if a.get(k) != b.get(k))

        others = sorted((o for o in own if o.name != v.name),
                        key=lambda o: (len(differing(o)), o.name != main.name))
        pairs.append((v, others[0], differing(others[0])))
    return pairs


def variant_comparison(measures: Sequence[dict[str, Any] | None], reference: Sequence[dict[str, Any] | None]
                       ) -> dict[str, Any]:
    """Paired per seed, for the quantities of the rate convergence: the mean of
    ``measures`` minus ``reference``, its 95 % t-interval, and whether the difference
    is within max(3 % of the reference mean, the reference's seed standard deviation),
    the rate convergence's tolerance."""
    quantities: dict[str, Any] = {}
    for name, get in _RATE_QUANTITIES.items():
        a = np.array([float(get(m)) for m in measures], dtype=np.float64)
        b = np.array([float(get(m)) for m in reference], dtype=np.float64)
        both = np.isfinite(a) & np.isfinite(b)
        if not both.any():
            quantities[name] = {"mean": None, "reference_mean": None, "difference": None, "ci95": [None, None],
                                "n": 0, "tolerance": None, "within": None}
            continue
        d = a[both] - b[both]
        tolerance = _tolerance(b[both])
        low, high = t_interval(d) if d.size > 1 else (math.nan, math.nan)
        quantities[name] = {
            "mean": float(a[both].mean()), "reference_mean": float(b[both].mean()),
            "difference": float(d.mean()), "ci95": [low, high], "n": int(d.size),
            "tolerance": tolerance, "within": bool(abs(d.mean()) <= tolerance),
        }
    known = [q["within"] for q in quantities.values() if q["within"] is not None]
    return {"quantities": quantities, "all_within": bool(known) and all(known) and len(known) == len(quantities)}


# ----------------------------------------------------------------------------- writing
def _csv_text(blocks: Sequence[dict[str, Any]]) -> str:
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(CSV_COLUMNS)
    for block in blocks:
        for row in block["claims"]:
            values = {**row, "ci95_low": row["ci95"][0], "ci95_high": row["ci95"][1],
                      "per_seed": " ".join("nan" if v is None else repr(v) for v in row["per_seed"])}
            writer.writerow(["" if values.get(c) is None else values.get(c) for c in CSV_COLUMNS])
    return buffer.getvalue()


@dataclass
class Outputs:
    """What :func:`write_outputs` wrote, and the document it wrote as ``claims.json``."""

    out_dir: Path
    document: dict[str, Any]
    files: list[Path] = field(default_factory=list)
    wall_time_s: float = 0.0

    def lines(self) -> list[str]:
        """The verdict table and the files, for the terminal."""
        doc = self.document
        lines = [f"claims ({doc['variant']}): " + ", ".join(f"{n} {v}" for v, n in doc["verdict_counts"].items())]
        width = max((len(r["id"]) for r in doc["claims"]), default=10)
        for r in doc["claims"]:
            ci = r["ci95"]
            ci_text = "n/a" if ci[0] is None else f"[{ci[0]:.4g}, {ci[1]:.4g}]"
            mean = "n/a" if r["mean"] is None else f"{r['mean']:.4g}"
            lines.append(f"  {r['id']:<{width}}  {r['verdict']:<15} mean {mean:>9}  CI {ci_text}  n={r['n']}")
        for block in doc["variants"]:
            if block["variant"] in doc["variant"].split("+"):
                continue
            lines.append(f"variant {block['variant']}: " + ", ".join(
                f"{n} {v}" for v, n in block["verdict_counts"].items()))
        for entry in doc["rate_convergence"]:
            lines.append(f"rate {entry['rate']} vs {entry['half_rate']}: "
                         + ("converged" if entry["converged"] else "not converged"))
        lines.append(f"grainlab reproduce: {len(self.files)} files in {self.wall_time_s:.1f} s -> "
                     + ", ".join(str(p) for p in self.files if p.suffix in (".json", ".csv", ".html")))
        return lines


def write_outputs(plan: ReproductionPlan, out_dir: str | os.PathLike[str], *, workers: int | None = None,
                  progress: bool = False, figures: bool = True) -> Outputs:
    """Measures every finished run of ``plan`` in ``out_dir`` and writes ``claims.json``,
    ``claims.csv``, ``measures.json``, the figures and ``reproduction.html``."""
    started = time.perf_counter()
    out = Path(out_dir)
    tasks = _tasks(plan, out)
    results, notes = _compute(tasks, workers, progress)

    def per_seed(v: Variant) -> list[dict[str, Any] | None]:
        return [results.get((v.name, str(s), plan.reads(v))) for s in plan.seeds]

    blocks = [_block(v, plan, per_seed(v), out) for v in plan.variants]
    family = rate_family(plan)
    convergence = rate_convergence([(rate, per_seed(v)) for rate, v in family])
    if len(family) >= 2:
        (slow_rate, slow), (fast_rate, fast) = family[0], family[-1]
        pairs = [None if a is None or b is None else {"fast": a, "slow": b}
                 for a, b in zip(per_seed(fast), per_seed(slow), strict=True)]
        name = f"rates {fast.name} vs {slow.name}"
        rows = evaluate(RATE_CLAIMS, pairs, plan.seeds, name)
        blocks.append({"variant": name, "kind": "rate", "description": (
            f"paired per seed: the fastest rate of the family ({fast_rate * 6000:g} %/min) against the slowest "
            f"({slow_rate * 6000:g} %/min)"), "seeds": list(plan.seeds), "claims": rows,
            "verdict_counts": _counts(rows), "notes": []})

    comparisons = [{"variant": v.name, "reference": ref.name, "differs_in": keys,
                    **variant_comparison(per_seed(v), per_seed(ref))}
                   for v, ref, keys in comparison_pairs(plan)]

    main_biaxial, main_study = main_variant(plan, "biaxial"), main_variant(plan, "study")
    top = [b for b in blocks if b["variant"] in {v.name for v in (main_biaxial, main_study) if v}]
    top_claims = [row for b in top for row in b["claims"]]
    document = {
        "claims": top_claims,
        "seeds": list(plan.seeds),
        "variant": "+".join(b["variant"] for b in top),
        "grainlab_version": grainlab.__version__,
        "quick": plan.quick,
        "verdict_counts": _counts(top_claims),
        "variants": blocks,
        "rate_convergence": convergence,
        "fastest_converged_rate_per_s": fastest_converged_rate(convergence),
        "comparisons": comparisons,
        "notes": notes,
    }
    files = [write_json_atomic(out / CLAIMS_JSON, document)]
    document = json.loads(files[0].read_text())  # NaN as null, as the file has it
    files.append(write_text_atomic(out / CLAIMS_CSV, _csv_text(document["variants"])))
    files.append(write_text_atomic(out / CLAIMS_MD, claims_markdown(document)))
    measures_doc = {f"{v}/seed-{s}": m for (v, s, _), m in results.items() if m is not None}
    files.append(write_json_atomic(out / MEASURES_JSON, measures_doc, indent=None))
    if figures:
        from grainlab.reproduction.figures import draw_figures
        from grainlab.reproduction.html import write_html

        drawn = draw_figures(plan, results, out / "figures", runs_root=out)
        files += [p for p in drawn.values()]
        files.append(write_html(out / HTML_FILE, plan, document, drawn))
    return Outputs(out, document, files, time.perf_counter() - started)
