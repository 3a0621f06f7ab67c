"""The runs of a reproduction: variants, seeds, the run configuration, the folder layout.

The layout ``DIR/runs/<variant>/seed-<k>/...`` and the variants
(:func:`parse_variant`): docs/reproduction.md.
"""

from __future__ import annotations

import json
import math
import os
import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

from grainlab.analysis.stability import LAMBDA_ANCHORS, LAMBDA_DEVIATIONS, LAMBDA_SLOTS
from grainlab.io.results import write_json_atomic
from grainlab.study.campaign import CampaignResult, Run, make_run

if TYPE_CHECKING:
    from grainlab.protocols.biaxial.config import BiaxialConfig

__all__ = [
    "DEFAULT_SEEDS",
    "DEFAULT_VARIANTS",
    "PLAN_FILE",
    "QUICK_BIAXIAL",
    "QUICK_SEEDS",
    "QUICK_STUDY",
    "RUNS_TABLE",
    "ReproductionPlan",
    "Variant",
    "main_variant",
    "parse_variant",
    "rate_family",
    "snapshot_strains",
]

#: Seeds of the default ensemble (``--seeds 5`` means seeds 1 ... 5), and of ``--quick``'s.
DEFAULT_SEEDS = 5
QUICK_SEEDS = 3
#: Variants run when none are named (``--quick``: without the analysis-only ``lambda_raw``).
DEFAULT_VARIANTS: tuple[str, ...] = ("paper", "lambda_raw", "study")
QUICK_VARIANTS: tuple[str, ...] = ("paper", "study")
#: The reproduction's own record of what it was asked to run.
PLAN_FILE = "reproduction.json"
#: One row per run.
RUNS_TABLE = "runs.csv"

#: The paper's axial strain rate (Table 1: 2 %/min), 1/s: every biaxial variant that does not
#: set its own rate runs at it (``--quick``'s at :data:`QUICK_BIAXIAL`'s), whatever the default
#: of ``shear.strain_rate``.
PAPER_STRAIN_RATE = 0.02 / 60.0
#: ``--quick``: the biaxial --quick sample (30 x 60 mm, about 560 grains), a faster rate and a
#: shorter test. 5 %/min is 2.5 times the paper's rate and a quarter of the "auto" rate.
QUICK_BIAXIAL: dict[str, Any] = {"shear.final_strain": 0.05, "shear.strain_rate": 0.05 / 60.0}
#: ``--quick``: the packing study in the quick sample's box.
QUICK_STUDY: dict[str, Any] = {"width": 0.03, "height": 0.06}

Kind = Literal["biaxial", "study", "analysis"]

#: The readings of Eqs. 9-11 an analysis variant ``lambda:<key>=<value>,...`` may choose
#: (:class:`~grainlab.analysis.StabilityIndex`'s options; the first of each is the default).
LAMBDA_READINGS: dict[str, tuple[str, ...]] = {
    "slots": LAMBDA_SLOTS, "anchor": LAMBDA_ANCHORS, "deviation": LAMBDA_DEVIATIONS
}
_BAND_TEXT = {
    "displacement": "the zone separating the two moving blocks of the displacement map (Fig. 11), "
                    "the best two-block split whether or not it passes the acceptance test",
    "lambda": "the zone of lambda > 0.5 (Fig. 12)",
    "final": "the band accepted last (10 %) carried back by id",
}


def snapshot_strains(final_strain: float) -> list[float]:
    """Snapshot strains of a reproduction run: every 0.25 % to 2 % (with the paper's
    0.7 and 0.9 %), then every 1 % to ``final_strain``."""
    dense = [0.0025 * k for k in range(9)] + [0.007, 0.009]
    coarse = [0.01 * k for k in range(3, int(math.floor(final_strain * 100 + 1e-9)) + 1)]
    strains = sorted({round(s, 6) for s in dense + coarse if s <= final_strain + 1e-12})
    if not math.isclose(strains[-1], final_strain, abs_tol=1e-9):
        strains.append(round(final_strain, 6))
    return strains


@dataclass(frozen=True)
class Variant:
    """One variant of the reproduction: what runs (or which runs are re-read) and how
    they are analysed."""

    name: str
    kind: Kind
    #: Biaxial configuration keys (``biaxial``) or packing parameters (``study``).
    overrides: dict[str, Any] = field(default_factory=dict)
    #: Analysis options of the claims (``{"boundary_contacts": "raw"}``).
    analysis: dict[str, Any] = field(default_factory=dict)
    #: The variant whose runs this one reads (itself, unless analysis-only or an alias).
    source: str = ""
    description: str = ""

    @property
    def runs_variant(self) -> str:
        return self.source or self.name

    @property
    def folder(self) -> str:
        """The folder name of the variant's runs under ``DIR/runs``."""
        return variant_folder(self.runs_variant)


def variant_folder(name: str) -> str:
    """A file-system-safe folder name: ``rate=1%/min`` -> ``rate=1pct_per_min``."""
    text = name.replace("%", "pct").replace("/", "_per_")
    return re.sub(r"[^A-Za-z0-9=.,_+-]+", "_", text)


def _assignments(name: str, text: str) -> list[tuple[str, str]]:
    pairs = []
    for part in text.split(","):
        if "=" not in part or not part.split("=", 1)[0].strip():
            raise ValueError(f"--variants: {name!r}: expected key=value pairs separated by commas, got {part!r}")
        key, value = (p.strip() for p in part.split("=", 1))
        pairs.append((key, value))
    return pairs


def _biaxial_value(name: str, key: str, raw: Any) -> Any:
    from grainlab.protocols.biaxial.config import coerce
    from grainlab.protocols.config import ConfigError, parse_override

    value = parse_override(f"{key}={raw}")[1] if isinstance(raw, str) else raw
    try:
        return coerce(key, value)
    except ConfigError as error:
        raise ValueError(f"--variants: {name!r}: {error}") from None


def _study_value(name: str, key: str, raw: str) -> Any:
    from grainlab.study.packing import PackingParams

    try:
        value: Any = json.loads(raw)
    except json.JSONDecodeError:
        value = raw
    try:
        checked = PackingParams.from_mapping({key: value})
    except ValueError as error:
        raise ValueError(f"--variants: {name!r}: {error}") from None
    return getattr(checked, key)


def parse_variant(text: str) -> Variant:
    """The :class:`Variant` named by ``text`` (docs/reproduction.md); ``ValueError`` naming it."""
    name = text.strip()
    if name == "paper":
        return Variant("paper", "biaxial", description="the paper's test: Table 1 (2 %/min), membrane boundary")
    if name == "boundary_b":
        return Variant(
            "boundary_b", "biaxial", {"boundary.kind": "outer_particles"},
            description="the outermost grains as the lateral boundary (boundary.kind = outer_particles)",
        )
    if name == "lambda_raw" or name.startswith("lambda_raw:"):
        source = parse_variant(name[len("lambda_raw:"):]) if name != "lambda_raw" else parse_variant("paper")
        if source.kind != "biaxial":
            raise ValueError(f"--variants: {name!r}: lambda_raw reads a biaxial variant's runs, not {source.name!r}")
        return Variant(
            name if name == "lambda_raw" else f"lambda_raw:{source.name}", "analysis",
            analysis={"boundary_contacts": "raw"}, source=source.name,
            description=f"{source.name}'s runs; lambda with every membrane disk a grain touches counted",
        )
    if name.startswith("lambda:"):
        readings, _, source_name = name[len("lambda:"):].partition(":")
        source = parse_variant(source_name) if source_name else parse_variant("paper")
        if source.kind == "analysis":
            raise ValueError(f"--variants: {name!r}: lambda reads a biaxial or study variant's runs, "
                             f"not {source.name!r}")
        pairs = _assignments(name, readings)
        analysis = {}
        for key, value in pairs:
            if key not in LAMBDA_READINGS:
                raise ValueError(f"--variants: {name!r}: unknown lambda option {key!r}; known: "
                                 + ", ".join(LAMBDA_READINGS))
            if value not in LAMBDA_READINGS[key]:
                raise ValueError(f"--variants: {name!r}: {key} must be one of "
                                 f"{', '.join(LAMBDA_READINGS[key])}, got {value!r}")
            analysis[f"lambda_{key}"] = value
        what = ", ".join(f"{k} = {v}" for k, v in pairs)
        canonical = f"lambda:{','.join(f'{k}={v}' for k, v in pairs)}"
        if source.name != "paper":
            canonical += f":{source.name}"
        runs = "stored packings" if source.kind == "study" else "runs"
        return Variant(canonical, "analysis", analysis=analysis, source=source.name,
                       description=f"{source.name}'s {runs}; lambda read with {what} (Eqs. 9-11)")
    if name.startswith("band:"):
        from grainlab.reproduction.measures import BAND_READINGS

        reading = name[len("band:"):].strip()
        if reading not in BAND_READINGS or reading == "strain":
            raise ValueError(f"--variants: {name!r}: expected band:displacement, band:lambda or band:final")
        return Variant(name, "analysis", analysis={"band": reading}, source="paper",
                       description=f"paper's runs; the band's grains from {_BAND_TEXT[reading]}")
    if name.startswith("rate="):
        rate = _biaxial_value(name, "shear.strain_rate", name[len("rate="):])
        if rate == "auto":
            raise ValueError(f"--variants: {name!r}: give a rate with a unit, e.g. rate=1%/min")
        return Variant(
            f"rate={_rate_text(rate)}", "biaxial", {"shear.strain_rate": rate},
            description=f"the paper's test at {_rate_text(rate)} ({rate:.4g} 1/s)",
        )
    if name.startswith("set:"):
        pairs = _assignments(name, name[len("set:"):])
        overrides = {key: _biaxial_value(name, key, raw) for key, raw in pairs}
        return Variant(name, "biaxial", overrides, description="the paper's test with " + ", ".join(
            f"{k} = {v}" for k, v in pairs))
    if name == "study" or name.startswith("study:"):
        pairs = _assignments(name, name[len("study:"):]) if name != "study" else []
        overrides = {key: _study_value(name, key, raw) for key, raw in pairs}
        what = ", ".join(f"{k} = {v}" for k, v in overrides.items())
        return Variant(name, "study", overrides,
                       description="the Sec. 7 packing study" + (f" with {what}" if what else " (Tables 2-3)"))
    raise ValueError(
        f"--variants: unknown variant {name!r}; known: paper, boundary_b, lambda_raw, rate=<rate> "
        "(e.g. rate=1%/min), set:<key>=<value>, lambda:<key>=<value>, band:<reading>, study, "
        "study:<field>=<value>"
    )


def _rate_text(rate: float) -> str:
    """The shortest plain decimal (no exponent) that round-trips, in percent per minute.

    >>> _rate_text(0.02 / 60), _rate_text(0.2 / 60), _rate_text(0.015 / 60)
    ('2%/min', '20%/min', '1.5%/min')
    """
    per_min = rate * 6000.0
    for digits in range(1, 12):
        text = f"{per_min:.{digits}g}"
        if "e" not in text and math.isclose(float(text), per_min, rel_tol=1e-9):
            return f"{text}%/min"
    return f"{per_min:f}".rstrip("0").rstrip(".") + "%/min"


@dataclass(frozen=True)
class ReproductionPlan:
    """Seeds, variants and mode of a reproduction, and the runs they make."""

    seeds: tuple[int, ...]
    variants: tuple[Variant, ...]
    quick: bool = False

    def __post_init__(self) -> None:
        if len(self.seeds) < 2:
            raise ValueError(f"--seeds: a confidence interval needs at least 2 seeds, got {len(self.seeds)}")
        names = [v.name for v in self.variants]
        if len(set(names)) != len(names):
            raise ValueError(f"--variants: given twice: {sorted({n for n in names if names.count(n) > 1})}")

    @classmethod
    def build(cls, seeds: int | Iterable[int], variants: Iterable[str | Variant], quick: bool = False
              ) -> ReproductionPlan:
        """Parses the variants, adds the runs an analysis-only variant reads, aliases a
        biaxial variant whose configuration is the paper variant's."""
        if isinstance(seeds, int):
            if isinstance(seeds, bool) or seeds < 2:
                raise ValueError(f"--seeds: expected an integer >= 2, got {seeds!r}")
            seed_list = tuple(range(1, seeds + 1))
        else:
            seed_list = tuple(sorted({int(s) for s in seeds}))
        parsed = [v if isinstance(v, Variant) else parse_variant(v) for v in variants]
        if not parsed:
            raise ValueError("--variants: none given")
        plan = cls(seed_list, tuple(parsed), quick)
        return plan._with_aliases()

    def _with_aliases(self) -> ReproductionPlan:
        variants = list(self.variants)
        names = {v.name for v in variants}
        for v in list(variants):  # an analysis-only variant needs the runs it reads
            if v.kind == "analysis" and v.source not in names:
                variants.insert(0, parse_variant(v.source))
                names.add(v.source)
        out: list[Variant] = []
        first: dict[str, str] = {}  # configuration -> the first variant that runs it
        for v in variants:
            if v.kind == "biaxial" and not v.source:
                key = json.dumps(self.biaxial_config(v, 0).to_dict(), sort_keys=True)
                if key in first:
                    v = replace(v, source=first[key],
                                description=f"{v.description} (the configuration of {first[key]}: its runs)")
                else:
                    first[key] = v.name
            out.append(v)
        return ReproductionPlan(self.seeds, tuple(out), self.quick)

    def reads(self, variant: Variant) -> Literal["biaxial", "study"]:
        """The kind of runs ``variant`` measures: biaxial runs or a packing study's."""
        return "study" if self.variant(variant.runs_variant).kind == "study" else "biaxial"

    def variant(self, name: str) -> Variant:
        for v in self.variants:
            if v.name == name:
                return v
        raise KeyError(name)

    # ---- run parameters ----------------------------------------------------------
    def biaxial_params(self, variant: Variant, seed: int) -> dict[str, Any]:
        """The biaxial configuration overrides of ``variant``'s run for ``seed``."""
        params: dict[str, Any] = dict(QUICK_BIAXIAL) if self.quick else {"shear.strain_rate": PAPER_STRAIN_RATE}
        params.update(variant.overrides)
        final = params.get("shear.final_strain", 0.10)
        params.setdefault("shear.snapshot_strains", snapshot_strains(final))
        params["sample.seed"] = int(seed)
        if self.quick:
            params["quick"] = True
        return params

    def biaxial_config(self, variant: Variant, seed: int) -> BiaxialConfig:
        """The resolved :class:`~grainlab.protocols.config.BiaxialConfig` of a biaxial run."""
        from grainlab.protocols.biaxial.config import resolve

        params = self.biaxial_params(variant, seed)
        quick = bool(params.pop("quick", False))
        return resolve(overrides=params, quick=quick)

    def study_overrides(self, variant: Variant) -> dict[str, Any]:
        return {**(QUICK_STUDY if self.quick else {}), **variant.overrides}

    def runs(self) -> list[Run]:
        """Every run of the plan (each once, however many variants read it), biaxial
        runs first (the longest), then the packings."""
        from grainlab.study.paper import study_runs

        biaxial: list[Run] = []
        packings: list[Run] = []
        seen: set[str] = set()
        for v in self.variants:
            if v.kind == "analysis" or v.source or v.folder in seen:
                continue
            seen.add(v.folder)
            for seed in self.seeds:
                where = f"{v.folder}/seed-{seed}"
                labels = {"variant": v.name, "seed_index": seed}
                if v.kind == "biaxial":
                    biaxial.append(make_run(where, "biaxial", self.biaxial_params(v, seed), seed, labels))
                else:
                    for run in study_runs(seed, self.study_overrides(v)):
                        packings.append(replace(run, name=f"{where}/{run.name}", labels={**labels, **run.labels}))
        return biaxial + packings

    def biaxial_folder(self, out_dir: str | os.PathLike[str], variant: Variant, seed: int) -> Path:
        """Where ``variant``'s biaxial run of ``seed`` writes (its ``run.h5``)."""
        return Path(out_dir) / "runs" / variant.folder / f"seed-{seed}" / "biaxial"

    def study_folder(self, out_dir: str | os.PathLike[str], variant: Variant, seed: int) -> Path:
        return Path(out_dir) / "runs" / variant.folder / f"seed-{seed}"

    # ---- the record in DIR -------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        return {"seeds": list(self.seeds), "variants": [v.name for v in self.variants], "quick": self.quick}

    def save(self, out_dir: str | os.PathLike[str]) -> Path:
        Path(out_dir).mkdir(parents=True, exist_ok=True)
        return write_json_atomic(Path(out_dir) / PLAN_FILE, self.to_dict())


def load_plan(out_dir: str | os.PathLike[str]) -> ReproductionPlan:
    """The plan recorded in ``out_dir`` (``ValueError`` when there is none)."""
    path = Path(out_dir) / PLAN_FILE
    if not path.exists():
        raise ValueError(f"--out: {out_dir} holds no reproduction ({PLAN_FILE} not found)")
    saved = json.loads(path.read_text())
    return ReproductionPlan.build(saved["seeds"], saved["variants"], bool(saved.get("quick")))


def run_reproduction(
    plan: ReproductionPlan,
    out_dir: str | os.PathLike[str],
    *,
    workers: int | None = None,
    scheduler: Any = None,
    progress: bool = False,
) -> CampaignResult:
    """Runs (or resumes) every run of ``plan`` into ``out_dir``; one row per run in
    ``runs.csv``. Returns the :class:`~grainlab.study.campaign.CampaignResult`."""
    from grainlab.study.campaign import run_campaign

    plan.save(out_dir)
    columns = ["name", "variant", "seed_index", "kind", "status", "wall_time_s", "seed", "error"]
    return run_campaign(plan.runs(), out_dir, workers=workers, scheduler=scheduler, progress=progress,
                        table_name=RUNS_TABLE, columns=columns)


def describe(plan: ReproductionPlan) -> list[str]:
    """One line per variant: what it is and what it runs."""
    lines = []
    for v in plan.variants:
        if v.kind == "analysis" or v.source:
            runs = f"reads {v.source}'s runs"
        elif v.kind == "biaxial":
            config = plan.biaxial_config(v, plan.seeds[0])
            runs = (f"{len(plan.seeds)} biaxial runs at {config['shear.strain_rate'] * 6000:g} %/min to "
                    f"{100 * config['shear.final_strain']:g} %")
        else:
            runs = f"{len(plan.seeds)} x 19 packings"
        lines.append(f"{v.name}: {v.description}; {runs}")
    return lines


def plan_from_args(seeds: int | None, variants: Sequence[str] | None, quick: bool | None,
                   out_dir: str | os.PathLike[str] | None = None) -> ReproductionPlan:
    """The plan of a ``grainlab reproduce`` call. A folder that already holds a
    reproduction keeps its variants, seeds and mode; those given are added (a mode
    given must be the folder's). Otherwise: the given variants (default
    :data:`DEFAULT_VARIANTS`, :data:`QUICK_VARIANTS` with ``quick``), ``seeds`` (default :data:`DEFAULT_SEEDS`,
    :data:`QUICK_SEEDS` with ``quick``)."""
    if out_dir is not None and (Path(out_dir) / PLAN_FILE).exists():
        saved = load_plan(out_dir)
        if quick is not None and bool(quick) != saved.quick:
            was = "with" if saved.quick else "without"
            raise ValueError(f"--quick: {out_dir} was started {was} --quick; use the same mode or another --out")
        names = [v.name for v in saved.variants]
        names += [v.name for v in (parse_variant(t) for t in variants or ()) if v.name not in names]
        all_seeds = sorted(set(saved.seeds) | set(range(1, (seeds or 0) + 1)))
        if seeds is not None and seeds < 2:
            raise ValueError(f"--seeds: expected an integer >= 2, got {seeds!r}")
        return ReproductionPlan.build(all_seeds, names, saved.quick)
    quick = bool(quick)
    if seeds is None:
        seeds = QUICK_SEEDS if quick else DEFAULT_SEEDS
    return ReproductionPlan.build(seeds, variants or (QUICK_VARIANTS if quick else DEFAULT_VARIANTS), quick)


def main_variant(plan: ReproductionPlan, kind: str) -> Variant | None:
    """The variant a kind's figures and tables lead with: the paper's (biaxial) or the
    study's by name, else the first of its kind."""
    preferred = "paper" if kind == "biaxial" else "study"
    kinds = ("biaxial",) if kind == "biaxial" else ("study",)
    for v in plan.variants:
        if v.name == preferred:
            return v
    return next((v for v in plan.variants if v.kind in kinds), None)


def rate_family(plan: ReproductionPlan) -> list[tuple[float, Variant]]:
    """Biaxial variants that differ from the main one only in the strain rate, by rate."""
    base = main_variant(plan, "biaxial")
    if base is None:
        return []

    def without_rate(v: Variant) -> tuple[str, float]:
        config = plan.biaxial_config(plan.variant(v.runs_variant), plan.seeds[0]).to_dict()
        rate = config["shear"].pop("strain_rate")
        return json.dumps(config, sort_keys=True), float(rate)

    key, _ = without_rate(base)
    family: dict[float, Variant] = {}
    for v in plan.variants:
        if v.kind != "biaxial":
            continue
        k, rate = without_rate(v)
        if k == key:
            family.setdefault(rate, v)
    return sorted(family.items())
