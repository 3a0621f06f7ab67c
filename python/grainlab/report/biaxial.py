"""Everything the report of a biaxial run shows, gathered from its results folder.

:func:`gather_biaxial` reads ``run.h5`` (configuration, time series, summary,
phase times, versions), ``summary.json`` (the fabric numbers the figures were
drawn with) and the figure files, draws what is missing with the functions
that drew them in the first place, and computes the report's own numbers:
the friction and dilation angles and the classical band angles
(:mod:`grainlab.report.angles`). No HTML here (:mod:`grainlab.report.render`).
"""

from __future__ import annotations

import json
import math
import shlex
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np

import grainlab
from grainlab._html import EmbeddedFigure, fmt, is_usable_png, number
from grainlab._mapping import flatten_keys
from grainlab.analysis.peak import peak_record
from grainlab.columns import AXIAL_STRAIN, STRESS_RATIO, VOLUMETRIC_STRAIN
from grainlab.io.hdf5 import Results, read_results
from grainlab.paper import BIAXIAL_CLAIMS, STRAIN_RATE_PER_S, TABLE1
from grainlab.postprocess.band import BandNumbers
from grainlab.postprocess.products import store_run_products
from grainlab.protocols.biaxial.config import FIELDS
from grainlab.protocols.biaxial.outputs import is_constant_volume
from grainlab.protocols.config import QUICK
from grainlab.report.angles import (
    DEFAULT_DILATION_WINDOW,
    ClassicalAngles,
    DilationFit,
    fit_dilation,
    mobilised_friction_angle,
)
from grainlab.report.band import band_from_numbers
from grainlab.report.figures import embedded_png, grading_figure, macro_figure
from grainlab.report.run_page import CRACKS
from grainlab.samples import PAPER_GRADING, UniformByMass, UniformByNumber
from grainlab.samples.grading import Grading, GradingCurve

__all__ = [
    "CURVE_FIGURES",
    "REQUIRED_COLUMNS",
    "BiaxialReport",
    "ConfigRow",
    "Rerun",
    "config_toml",
    "gather_biaxial",
    "rerun_command",
]

#: Time-series columns without which there is no report.
REQUIRED_COLUMNS: tuple[str, ...] = (AXIAL_STRAIN, STRESS_RATIO, VOLUMETRIC_STRAIN)

#: The macro-curve figures of the folder (drawn by :func:`grainlab.plot.biaxial_curves`).
CURVE_FIGURES: tuple[str, ...] = ("fig08_stress_ratio", "fig10_volumetric_strain", "fig18_coordination_number")

#: SI unit of each configuration kind.
_SI_UNIT = {
    "length": "m",
    "stress": "Pa",
    "strain_rate": "1/s",
    "strain": "-",
    "strain_list": "- (fractions)",
    "length_list": "m",
    "percent_list": "%",
    "stiffness": "N/m",
    "density": "kg/m^3",
    "time": "s",
}

#: Phases of the protocol in order, and what they are.
PHASES: dict[str, str] = {
    "generate": "sample generation (radius expansion)",
    "consolidate": "isotropic consolidation",
    "boundary": "flexible boundary, re-equilibration",
    "shear": "shearing",
}


@dataclass(frozen=True)
class ConfigRow:
    """One configuration key as the report lists it."""

    key: str
    #: The value as written in ``run.h5`` (SI).
    value: Any
    #: The value for a reader (SI, with a readable unit in brackets).
    shown: str
    unit: str
    default: str
    #: Table 1 (or Sec. 6) value, "" when the paper gives none.
    paper: str
    help: str
    #: Differs from grainlab's default.
    differs: bool


@dataclass(frozen=True)
class Rerun:
    """How to run the same test again."""

    #: The shell command (``--quick`` / ``--set`` for every key that differs from the defaults).
    command: str
    #: The whole resolved configuration as a TOML file for ``--config``.
    toml: str
    #: The command with that file.
    command_with_file: str
    notes: tuple[str, ...]


@dataclass
class BiaxialReport:
    """The content of a biaxial report; numbers are SI / fractions, angles in radians."""

    folder: Path
    results: Results
    #: run.h5's summary with summary.json's additions (``fabric``).
    summary: dict[str, Any]
    generated: str
    config_rows: list[ConfigRow]
    rerun: Rerun
    threads: int | None
    n_grains: int
    n_membrane: int
    #: Grain diameters of the first snapshot (m).
    diameters: np.ndarray
    grading: Grading | None
    grading_name: str
    peak_row: int
    peak_ratio: float
    peak_strain: float
    phi: float
    dilation: DilationFit
    angles: ClassicalAngles
    #: Fabric numbers (FabricNumbers.summary() form) and where they come from.
    fabric: dict[str, Any] | None
    fabric_source: str
    #: The band measured by the report at the snapshot nearest the peak and at the
    #: end of shearing (None with a single snapshot); the end one is compared with
    #: the classical angles.
    band_peak: BandNumbers | None
    band_end: BandNumbers | None
    #: Figures of the folder in report order, and the report's own.
    figures: dict[str, EmbeddedFigure]
    grading_png: bytes
    macro_png: bytes
    #: (quantity, paper, run, where) rows.
    paper_rows: list[tuple[str, str, str, str]]
    #: The reproduction's claims on this one run (:func:`grainlab.reproduction.claims.single_run_rows`).
    claim_rows: list[dict[str, Any]]
    #: (phase, description, seconds) and the recorded total.
    wall_times: list[tuple[str, str, float]]
    wall_total: float
    regenerated: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    @property
    def timeseries(self) -> dict[str, np.ndarray]:
        return self.results.timeseries


# ----------------------------------------------------------------------------- configuration
def _readable(key: str, value: Any, summary: dict[str, Any], threads: int | None) -> str:
    field_ = FIELDS.get(key)
    kind = field_.kind if field_ else ""
    if value == "auto":
        if key == "shear.strain_rate" and summary.get("strain_rate") is not None:
            return f"auto ({summary['strain_rate']:.4g} 1/s used)"
        if key == "run.threads" and threads is not None:
            return f"auto ({threads} used)"
        return "auto"
    if isinstance(value, bool) or not isinstance(value, int | float | list):
        return str(value)
    if isinstance(value, list):
        if not value:
            return "none"
        if kind == "strain_list":
            return ", ".join(f"{100 * v:g}" for v in value) + " %"
        if kind == "length_list":
            return ", ".join(f"{v:g}" for v in value) + " (" + ", ".join(f"{1e3 * v:g}" for v in value) + " mm)"
        return ", ".join(f"{v:g}" if isinstance(v, float) else str(v) for v in value)
    if kind == "length":
        return f"{value:g} ({1e3 * value:g} mm)"
    if kind == "stress":
        return f"{value:g} ({value / 1e3:g} kPa)"
    if kind == "strain_rate":
        return f"{value:g} ({6000 * value:g} %/min)"
    if kind == "strain" and key != "sample.porosity":
        return f"{value:g} ({100 * value:g} %)"
    return f"{value:g}" if isinstance(value, float) else str(value)


def _paper_text(key: str) -> str:
    value = TABLE1.get(key)
    return f"{value.text} ({value.where})" if value else ""


def config_rows(config: dict[str, Any], summary: dict[str, Any], threads: int | None) -> list[ConfigRow]:
    """The resolved configuration, one row per key, in the file's order."""
    rows = []
    for key, value in flatten_keys(config).items():
        field_ = FIELDS.get(key)
        default = field_.default if field_ else None
        rows.append(
            ConfigRow(
                key=key,
                value=value,
                shown=_readable(key, value, summary, threads),
                unit=_SI_UNIT.get(field_.kind, "-") if field_ else "",
                default=_readable(key, default, {}, None) if field_ else "(unknown key)",
                paper=_paper_text(key),
                help=field_.help if field_ else "",
                differs=field_ is None or value != default,
            )
        )
    return rows


def _toml_value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int | float):
        return repr(value)
    if isinstance(value, list):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    return json.dumps(str(value))


def config_toml(config: dict[str, Any]) -> str:
    """The nested configuration as a TOML file that ``--config`` reads back to the same values."""
    lines = ["# the resolved configuration of this run (SI units), for grainlab biaxial --config"]
    for section, values in config.items():
        lines.append("")
        lines.append(f"[{section}]")
        for name, value in values.items():
            lines.append(f"{name} = {_toml_value(value)}")
    return "\n".join(lines) + "\n"


def rerun_command(config: dict[str, Any], out: str, threads: int | None = None) -> Rerun:
    """The ``grainlab biaxial`` command that runs ``config`` again into ``out``.

    Keys equal to the defaults are left out; ``--quick`` stands for its sample
    size; ``threads`` pins ``run.threads`` when the run used ``auto`` (the
    same configuration, seed and thread count give bitwise the same results).
    """
    flat = flatten_keys(config)
    args = ["grainlab", "biaxial", "--out", out]
    quick = all(flat.get(k) == v for k, v in QUICK.items())
    if quick:
        args.append("--quick")
    notes = []
    for key, value in flat.items():
        field_ = FIELDS.get(key)
        if quick and key in QUICK:
            continue
        if key == "run.threads" and value == "auto" and threads is not None:
            args += ["--set", f"run.threads={threads}"]
            notes.append(
                f"run.threads={threads} pins the thread count the run used (it was 'auto'): the same "
                "configuration, seed and thread count give bitwise the same results."
            )
            continue
        if field_ is not None and value == field_.default:
            continue
        args += ["--set", f"{key}={_toml_value(value)}"]
    if flat.get("run.threads") == "auto" and threads is None:
        notes.append(
            "The run used run.threads = auto and did not record the count; the same configuration, seed "
            "and thread count give bitwise the same results, so set run.threads to the original count "
            "for an exact repeat."
        )
    command = shlex.join(args)
    with_file = shlex.join(["grainlab", "biaxial", "--out", out, "--config", "config.toml"])
    if threads is not None and flat.get("run.threads") == "auto":
        with_file += f" --set run.threads={threads}"
    return Rerun(command, config_toml(config), with_file, tuple(notes))


def requested_grading(config: dict[str, Any]) -> tuple[Grading | None, str]:
    """The grading the configuration asked for, and its name."""
    sample = config.get("sample", {})
    kind, d_min, d_max = sample.get("grading"), sample.get("d_min"), sample.get("d_max")
    try:
        if kind == "uniform_by_number":
            g: Grading = UniformByNumber(d_min, d_max)
        elif kind == "uniform_by_mass":
            g = UniformByMass(d_min, d_max)
        elif kind == "curve":
            g = GradingCurve(sample.get("sieve_sizes"), sample.get("percent_passing"))
        elif kind == "paper" and (d_min, d_max) == (PAPER_GRADING.d_min, PAPER_GRADING.d_max):
            g = PAPER_GRADING
        else:
            return None, f"{kind} (no curve: unknown grading or range)"
    except (TypeError, ValueError) as error:
        return None, f"{kind} (no curve: {error})"
    return g, g.name


# ----------------------------------------------------------------------------- gathering
def _read_summary_json(folder: Path) -> dict[str, Any]:
    path = folder / "summary.json"
    if not path.exists():
        return {}
    try:
        value = json.loads(path.read_text())
    except (OSError, ValueError):
        return {}
    return value if isinstance(value, dict) else {}


def check_biaxial_folder(folder: Path) -> Results:
    """Reads ``run.h5`` and checks it is a finished biaxial run with the columns needed."""
    results = read_results(folder)
    if results.kind != "biaxial":
        raise ValueError(f"{results.path}: a {results.kind!r} run, not a biaxial test; no report for it")
    missing = [c for c in REQUIRED_COLUMNS if c not in results.timeseries]
    if missing:
        raise ValueError(
            f"{results.path}: the time series lacks {missing} (needed for the macro curves and the angles)"
        )
    if len(results.timeseries[AXIAL_STRAIN]) == 0:
        raise ValueError(f"{results.path}: the time series is empty")
    if not results.snapshot_names:
        raise ValueError(f"{results.path}: the run has no snapshots")
    return results


def _peak_row(ts: dict[str, np.ndarray]) -> int:
    return peak_record(ts[AXIAL_STRAIN], ts[STRESS_RATIO])


def _file_figure(path: Path, key: str, title: str, caption: str) -> EmbeddedFigure | None:
    png = path.with_suffix(".png")
    if not is_usable_png(png):
        return None
    return EmbeddedFigure(key, title, caption, embedded_png(png.read_bytes()), f"{png.name} in the results folder")


def _val(d: dict[str, Any] | None, *keys: str) -> Any:
    for k in keys:
        if not isinstance(d, dict):
            return None
        d = d.get(k)
    return d


def _band_text(band: BandNumbers | None) -> str:
    if band is None:
        return "not available (a single snapshot, or no fabric numbers)"
    if band.found:
        return (
            f"found at {band.snapshot}: inclination {fmt(band.inclination_deg, 3)} deg to σ₃, "
            f"{fmt(band.thickness_diameters, 3)} mean diameters thick"
        )
    return f"not found at {band.snapshot}: {band.reason}"


def _paper_rows(r: BiaxialReport) -> list[tuple[str, str, str, str]]:
    s, ts, fab = r.summary, r.timeseries, r.fabric or {}
    states = fab.get("states", {}) if isinstance(fab, dict) else {}
    run: dict[str, str] = {}
    run["porosity"] = (
        f"{fmt(number(s.get('porosity_generated')), 3)} nominal / "
        f"{fmt(number(s.get('porosity_generated_overlap_corrected')), 3)} overlap-corrected after generation; "
        f"{fmt(number(s.get('porosity_initial')), 3)} at the start of shearing"
    )
    run["min_radius"] = f"{fmt(1e3 * float(r.diameters.min()) / 2, 3)} mm"
    rate = number(s.get("strain_rate"))
    run["strain_rate"] = (
        f"{fmt(rate, 3)} 1/s ({fmt(6000 * rate, 3)} %/min, {fmt(rate / STRAIN_RATE_PER_S, 3)} x the paper's)"
        if math.isfinite(rate)
        else "n/a"
    )
    p_y = number((r.results.config.get("material") or {}).get("limiting_contact_pressure"))
    run["density_scaling"] = f"{fmt(number(s.get('density_scaling_factor')), 3)} " + (
        f"(Eq. 16 with p_y = {fmt(p_y / 1e6, 3)} MPa)" if math.isfinite(p_y)
        else "(Eq. 16 with p = σ₃: a run from before material.limiting_contact_pressure)"
    )
    run["a_initial"] = fmt(number(_val(states, "initial", "a")), 3)
    run["a_n_initial"] = fmt(number(_val(states, "initial", "a_n")), 3)
    eps = ts[AXIAL_STRAIN]
    if "anisotropy" in ts and np.nanmax(eps) >= 0.005:
        run["a_at_0.5"] = fmt(float(np.interp(0.005, eps, ts["anisotropy"])), 3)
    else:
        run["a_at_0.5"] = "n/a"
    run["z_initial"] = fmt(number(s.get("coordination_number_initial")), 3)
    run["z_peak"] = fmt(number(s.get("coordination_number_at_peak")), 3)
    run["strain_at_peak"] = fmt(r.peak_strain, percent=True)
    run["peak_ratio"] = fmt(r.peak_ratio, 3)
    ev = ts[VOLUMETRIC_STRAIN]
    run["volumetric"] = (
        f"largest contraction {fmt(float(np.nanmax(ev)), percent=True)}, "
        f"{fmt(float(ev[-1]), percent=True)} at {fmt(float(eps[-1]), percent=True)} "
        f"({'dilation' if ev[-1] < 0 else 'contraction'})"
    )
    run["band_at_peak"] = _band_text(r.band_peak)
    end = r.band_end
    run["band_inclination"] = (
        f"{fmt(end.inclination_deg, 3)} deg at {end.snapshot}" if end and end.found else "n/a (no band found)"
    )
    lam_peak = number(_val(states, "peak", "mean_lambda"))
    peak = r.band_peak
    if peak and peak.found:
        run["lambda_in_band"] = f"{fmt(peak.mean_lambda_inside, 3)} (band at {peak.snapshot})"
        run["lambda_outside"] = f"{fmt(peak.mean_lambda_outside, 3)} (band at {peak.snapshot})"
    else:
        run["lambda_in_band"] = f"n/a (no band at the peak); all grains {fmt(lam_peak, 3)}"
        run["lambda_outside"] = f"n/a (no band at the peak); all grains {fmt(lam_peak, 3)}"
    run["lambda_trend"] = (
        f"{fmt(number(_val(states, 'initial', 'mean_lambda')), 3)} initial, {fmt(lam_peak, 3)} at the peak "
        f"snapshot, {fmt(number(_val(states, 'final', 'mean_lambda')), 3)} final (grains with 2 or more contacts)"
    )
    if "mean_stability_index_all" in ts:
        lam_all = np.asarray(ts["mean_stability_index_all"], dtype=np.float64)
        run["lambda_trend"] += (
            f"; counting the 0- and 1-contact grains at λ = 1 (Sec. 5's convention): {fmt(lam_all[0], 3)} "
            f"initial, {fmt(lam_all[r.peak_row], 3)} at the peak, {fmt(lam_all[-1], 3)} final"
        )
    return [(c.quantity, c.text, run.get(c.key, "n/a"), c.where) for c in BIAXIAL_CLAIMS]


def _caption_numbers(fab: dict[str, Any] | None) -> dict[str, str]:
    states = (fab or {}).get("states", {})

    def pair(key: str) -> str:
        a, b = number(_val(states, "initial", key)), number(_val(states, "peak", key))
        return f"{fmt(a, 3)} initial, {fmt(b, 3)} at {_val(states, 'peak', 'snapshot') or 'the peak'}"

    return {"a": pair("a"), "a_n": pair("a_n"), "lambda": pair("mean_lambda")}


def _figure_specs(fab: dict[str, Any] | None, peak_strain: float) -> list[tuple[str, str, str]]:
    c = _caption_numbers(fab)
    peak = fmt(peak_strain, percent=True)
    return [
        ("fig08_stress_ratio", "Fig. 8: stress ratio",
         f"σ₁/σ₃ against axial strain (compression positive); peak at {peak}."),
        ("fig18_coordination_number", "Fig. 10: coordination number",
         "Z = 2 Nc / N of the grains (grain-grain contacts) against axial strain. The paper's Fig. 10 "
         "(this folder's file is named fig18)."),
        ("fig10_volumetric_strain", "Fig. 18: volumetric strain",
         "Area strain (A0 - A)/A0 inside the membrane against axial strain, compression positive. The "
         "paper's Fig. 18 (this folder's file is named fig10)."),
        ("fig19_stress_path", "Stress path at constant volume",
         "q = (σ₁′ − σ₃′)/2 against p′ = (σ₁′ + σ₃′)/2, and the pore-pressure analogue u = σ₀ − σ₃′ against "
         "axial strain: the rigid side walls hold the sample's area and measure the effective lateral stress."),
        CRACKS,
        ("fig06_contact_normals", "Fig. 6: contact normals",
         f"Polar histogram of contact normals (18 bins of 20 deg) with Eq. 6; a = {c['a']}."),
        ("fig07_normal_forces", "Fig. 7: normal forces",
         f"Polar distribution of normal contact forces; a_n = {c['a_n']}."),
        ("fig09_anisotropy", "Fig. 9: fabric anisotropy",
         "Contact-normal anisotropy a and force anisotropy a_n (Eq. 7) against axial strain."),
        ("fig11_displacement", "Fig. 11: displacements",
         "Displacement magnitude of the grains since the first snapshot, at the snapshots; the band is "
         "outlined where one was found."),
        ("fig12_stability_index", "Fig. 12: geometrical stability index",
         f"λ of each grain (Sec. 5) at the snapshots; mean λ {c['lambda']}."),
        ("fig13_contact_count", "Fig. 13: contacts per grain",
         "Number of contacts of each grain (boundary contacts included) at the snapshots."),
        ("fig14_mean_stability_index", "Fig. 14: mean stability index",
         "Mean λ of the grains with at least 2 contacts against axial strain."),
    ]


def gather_biaxial(
    folder: str | Path,
    *,
    redraw: bool = False,
    dilation_window: float = DEFAULT_DILATION_WINDOW,
) -> BiaxialReport:
    """Collects the report of the biaxial run in ``folder``.

    Figures missing from the folder are drawn into it (all of them with
    ``redraw``), with :func:`grainlab.plot.biaxial_curves` and
    :func:`grainlab.postprocess.fabric_figures`. The fabric and
    shear-band numbers are ``summary.json``'s (those the figures show) unless
    the fabric figures are drawn here, in which case they are the new ones.
    """
    from grainlab.plot.workers import figure_pool

    folder = Path(folder)
    results = check_biaxial_folder(folder)
    notes: list[str] = []
    # the bands and lambda fields that the figures and the claims read: a run of this
    # grainlab stored them; an older file gets them now, in worker processes
    with figure_pool(tasks=len(results.snapshot_names)) as pool:
        try:
            results = store_run_products(results, pool)
        except OSError as exc:  # a read-only folder: every reader makes them anew
            notes.append(f"the analysis products could not be stored in run.h5 ({exc}): made anew for this report")
    report = _gather(folder, results, redraw, dilation_window)
    report.notes[:0] = notes
    report.claim_rows = _claim_rows(folder, report.notes)
    return report


def _draw_missing(folder: Path, results: Results, saved: dict[str, Any],
                  redraw: bool) -> tuple[dict[str, Any] | None, str, list[str], list[str]]:
    """The folder's figures missing (all with ``redraw``) drawn with the functions that
    drew them with the run; ``(fabric numbers, where they come from, drawn, notes)``."""
    from grainlab.plot import biaxial_curves
    from grainlab.postprocess import FIGURES, fabric_figures, fabric_numbers

    ts = results.timeseries
    notes: list[str] = []
    regenerated: list[str] = []
    curves = CURVE_FIGURES + (("fig19_stress_path",) if is_constant_volume(results.config) else ())
    missing_curves = [n for n in curves if not is_usable_png(folder / f"{n}.png")]
    if redraw or missing_curves:
        if "coordination_number" in ts:
            biaxial_curves(ts, folder, stress_path=is_constant_volume(results.config))
            regenerated += list(curves)
        else:
            notes.append("no coordination_number column: Figs. 8, 10 and 18 could not be drawn")
    expected = [n for n in FIGURES if not (n == "fig11_displacement" and len(results.snapshot_names) < 2)]
    missing_fabric = [n for n in expected if not is_usable_png(folder / f"{n}.png")]
    fabric: dict[str, Any] | None = saved.get("fabric") if isinstance(saved.get("fabric"), dict) else None
    fabric_source = "summary.json (computed with the run, as the figures show them)"
    try:
        if redraw or missing_fabric:
            drawn = fabric_figures(folder)
            regenerated += list(drawn)
            fabric = drawn.numbers.summary()
            fabric_source = f"computed by this report (grainlab {grainlab.__version__}) while drawing the figures"
        elif fabric is None:
            fabric = fabric_numbers(folder).summary()
            fabric_source = f"computed by this report (grainlab {grainlab.__version__}); summary.json has none"
    except ValueError as error:
        notes.append(f"fabric figures and numbers not available: {error}")
        fabric, fabric_source = None, "not available"
    if regenerated:
        notes.append("drawn by this report (missing from the folder or --redraw): " + ", ".join(regenerated))
    return fabric, fabric_source, regenerated, notes


def _wall_times(results: Results, summary: dict[str, Any]) -> tuple[list[tuple[str, str, float]], float]:
    """Each phase's (name, what, wall time) and the run's total, s."""
    phases = dict(results.phases) or dict(summary.get("wall_time_by_phase_s") or {})
    wall = [(name, PHASES.get(name, ""), float(t)) for name, t in phases.items()]
    total = number(summary.get("wall_time_s"))
    if not math.isfinite(total):
        total = float(sum(t for _, _, t in wall))
    return wall, total


def _gather(folder: Path, results: Results, redraw: bool, dilation_window: float) -> BiaxialReport:
    """:func:`gather_biaxial` but the claims."""
    ts = results.timeseries
    summary = dict(results.summary)
    saved = _read_summary_json(folder)
    for key, value in saved.items():
        summary.setdefault(key, value)
    threads = summary.get("threads") if isinstance(summary.get("threads"), int) else None

    fabric, fabric_source, regenerated, notes = _draw_missing(folder, results, saved, redraw)

    # the macro numbers and the angles
    k = _peak_row(ts)
    eps, q, ev = ts[AXIAL_STRAIN], ts[STRESS_RATIO], ts[VOLUMETRIC_STRAIN]
    phi = mobilised_friction_angle(float(q[k]))
    dilation = fit_dilation(eps, ev, k, dilation_window)
    if dilation.reason:
        notes.append(f"no dilation angle: {dilation.reason}")
    if k == len(eps) - 1:
        notes.append("the stress ratio is largest at the last record: the peak may lie beyond the test")
    angles = ClassicalAngles.from_angles(phi, dilation.angle)
    # the bands the figures show: nearest the peak and at the end of shearing
    band_peak = band_from_numbers(fabric.get("band")) if fabric else None
    band_end = (band_from_numbers(fabric.get("band_final")) if fabric else None) or band_peak

    # the sample
    first = results.snapshot(0)
    grains = first.is_sample
    diameters = 2.0 * np.asarray(first.radii)[grains]
    n_grains = int(summary.get("n_particles") or int(grains.sum()))
    n_membrane = int(summary.get("n_membrane_disks") or int((~grains).sum()))
    grading, grading_name = requested_grading(results.config)

    wall, total = _wall_times(results, summary)

    figures: dict[str, EmbeddedFigure] = {}
    for key, title, caption in _figure_specs(fabric, float(eps[k])):
        fig = _file_figure(folder / key, key, title, caption)
        if fig is not None:
            figures[key] = fig

    report = BiaxialReport(
        folder=folder,
        results=results,
        summary=summary,
        generated=datetime.now(UTC).isoformat(timespec="seconds"),
        config_rows=config_rows(results.config, summary, threads),
        rerun=rerun_command(results.config, f"{folder.resolve()}-rerun", threads),
        threads=threads,
        n_grains=n_grains,
        n_membrane=n_membrane,
        diameters=diameters,
        grading=grading,
        grading_name=grading_name,
        peak_row=k,
        peak_ratio=float(q[k]),
        peak_strain=float(eps[k]),
        phi=phi,
        dilation=dilation,
        angles=angles,
        fabric=fabric,
        fabric_source=fabric_source,
        band_peak=band_peak,
        band_end=band_end,
        figures=figures,
        grading_png=grading_figure(diameters, grading, "requested"),
        macro_png=macro_figure(eps, q, ev, k, dilation, phi),
        paper_rows=[],
        claim_rows=[],
        wall_times=wall,
        wall_total=total,
        regenerated=regenerated,
        notes=notes + [f"fabric figures: {n}" for n in (fabric or {}).get("notes", [])],
    )
    report.paper_rows = _paper_rows(report)
    return report


def _claim_rows(path: Path, notes: list[str]) -> list[dict[str, Any]]:
    """The reproduction's claims measured on this run (empty, with a note, when it cannot be measured)."""
    from grainlab.reproduction.claims import single_run_rows
    from grainlab.reproduction.measures import measure_biaxial

    try:
        return single_run_rows(measure_biaxial(path))
    except (ValueError, KeyError, IndexError, OSError) as error:
        notes.append(f"the paper's claims could not be measured on this run ({type(error).__name__}: {error})")
        return []
