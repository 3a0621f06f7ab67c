"""The calibration of bonded samples: E, nu, q_u and sigma_t against the micro parameters.

The campaign and its rules are docs/cemented.md's ("Calibration"), written before
its runs. One parameter at a time from the base point, five seeds a point on each
test's quick sample, and the base point on the default sample (three seeds) for the
size effect; every run is a ``grainlab sweep`` of ``grainlab run ucs`` or
``grainlab run brazilian`` (resumable: a sweep skips its finished runs and resumes
a stopped one from its checkpoint).

Usage::

    python benchmarks/cement_calibration.py run CAMPAIGN          # resumable
    python benchmarks/cement_calibration.py summarize CAMPAIGN [--data DIR] [--figures DIR]
"""

from __future__ import annotations

import csv
import json
import math
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
from campaign import arguments, log  # noqa: E402

TESTS = ("ucs", "brazilian")
SEEDS = (1, 2, 3, 4, 5)
DEFAULT_SIZE_SEEDS = (1, 2, 3)
KPA = 1e3
BASE = {"cement.tensile_strength": 500 * KPA, "cement.cohesion": 500 * KPA, "cement.radius_multiplier": 1.0,
        "cement.normal_stiffness": "auto", "cement.shear_stiffness": "auto"}
FIXED = {"cement.bonds": "parallel", "cement.strength_scatter": 0.2, "cement.strength_distribution": "normal",
         "run.threads": 1}
#: kn_bar = ks_bar of the stiffness family, Pa/m (7e10: about auto's for the mean smaller radius).
STIFFNESSES = (1.75e10, 7e10, 2.8e11)
#: The laboratory granite's q_u / sigma_t (docs/cemented.md, rule 3) and the rules' bounds.
GRANITE_RATIO = 22.0
SLOPE_RANGE = (0.8, 1.2)
STIFFNESS_SPREAD = 1.25


def points() -> list[tuple[str, str, dict[str, object]]]:
    """(family, label, the point's keys) of every point, the base point once."""
    out: list[tuple[str, str, dict[str, object]]] = [("base", "base", dict(BASE))]
    for level in (250, 1000, 2000):
        out.append(("strength", f"sigma_c = c = {level} kPa",
                    {**BASE, "cement.tensile_strength": level * KPA, "cement.cohesion": level * KPA}))
    for ratio in (0.5, 2.0, 4.0):
        out.append(("cohesion_ratio", f"c / sigma_c = {ratio:g}", {**BASE, "cement.cohesion": ratio * 500 * KPA}))
    for multiplier in (0.5, 0.75):
        out.append(("radius_multiplier", f"lambda_b = {multiplier:g}",
                    {**BASE, "cement.radius_multiplier": multiplier}))
    for stiffness in STIFFNESSES:
        out.append(("stiffness", f"kn_bar = ks_bar = {stiffness:.3g} Pa/m",
                    {**BASE, "cement.normal_stiffness": stiffness, "cement.shear_stiffness": stiffness}))
    return out


def _toml(value: object) -> str:
    if isinstance(value, str):
        return json.dumps(value)
    return repr(value)


def plan_text(test: str, quick: bool) -> str:
    """A zip-mode sweep plan of ``test`` over every point and seed (quick), or of the
    base point over the default-size seeds."""
    rows = [(keys, seed) for _, _, keys in points() for seed in SEEDS] if quick else \
        [(dict(BASE), seed) for seed in DEFAULT_SIZE_SEEDS]
    lines = [f'base = "{test}"', 'mode = "zip"', f"quick = {'true' if quick else 'false'}", "", "[fixed]"]
    lines += [f'"{key}" = {_toml(value)}' for key, value in FIXED.items()]
    lines += ["", "[vary]"]
    for key in BASE:
        lines.append(f'"{key}" = [{", ".join(_toml(keys[key]) for keys, _ in rows)}]')
    lines.append(f'"sample.seed" = [{", ".join(str(seed) for _, seed in rows)}]')
    return "\n".join(lines) + "\n"


def sweeps() -> list[tuple[str, str, bool]]:
    """(folder name, test, quick) of the campaign's sweeps, in the order they run."""
    return [(test, test, True) for test in TESTS] + [(f"{test}_default_size", test, False) for test in TESTS]


def run(campaign: Path) -> int:
    env = dict(os.environ)
    env["PYTHONPATH"] = str(ROOT / "python") + os.pathsep + env.get("PYTHONPATH", "")
    failed = 0
    for name, test, quick in sweeps():
        folder = campaign / name
        folder.mkdir(parents=True, exist_ok=True)
        plan = folder / "calibration_plan.toml"
        plan.write_text(plan_text(test, quick))
        log(campaign, f"sweep {name}")
        start = time.perf_counter()
        command = [sys.executable, "-m", "grainlab", "sweep", str(plan), "--out", str(folder / "sweep"),
                   "--workers", "1", "--no-progress"]
        with open(folder / "sweep.log", "a") as out:
            code = subprocess.call(command, stdout=out, stderr=subprocess.STDOUT, env=env, cwd=ROOT)
        log(campaign, f"{name}: exit {code} after {time.perf_counter() - start:.0f} s")
        failed += code != 0
    return 1 if failed else 0


# ---------------------------------------------------------------- summary


def _number(text: str) -> float:
    """A sweep.csv cell of a stress or stiffness key as a float ("500 kPa", "7e10", "auto": nan)."""
    text = text.strip()
    if text == "auto":
        return math.nan
    value, _, unit = text.partition(" ")
    return float(value) * {"": 1.0, "Pa": 1.0, "kPa": 1e3, "MPa": 1e6}[unit]


def _key_of(keys: dict[str, object]) -> tuple[float, ...]:
    return tuple(math.nan if keys[k] == "auto" else float(keys[k]) for k in BASE)  # type: ignore[arg-type]


def _same(a: tuple[float, ...], b: tuple[float, ...]) -> bool:
    return all((math.isnan(x) and math.isnan(y)) or math.isclose(x, y, rel_tol=1e-9) for x, y in zip(a, b, strict=True))


def read_sweep(folder: Path) -> list[dict[str, str]]:
    path = folder / "sweep" / "sweep.csv"
    if not path.is_file():
        return []
    with open(path, newline="") as f:
        return [row for row in csv.DictReader(f) if row["status"] == "ok"]


def mean_bond_area(run_h5: Path, radius_multiplier: float) -> float:
    """The bonds' mean area 2 lambda_b min(R_i, R_j) over the grains' touching pairs of
    the run's first snapshot (the cemented pairs of a gap of 0), m^2 per m."""
    from grainlab.cement import pairs_within_gap
    from grainlab.io.hdf5 import read_results

    first = read_results(run_h5).snapshot(0)
    grains = np.asarray(first.is_sample)
    x, r = np.asarray(first.positions)[grains], np.asarray(first.radii)[grains]
    i, j = pairs_within_gap(x, r, 0.0)
    return float(np.mean(2.0 * radius_multiplier * np.minimum(r[i], r[j])))


def _stats(values: list[float]) -> dict[str, float]:
    a = np.asarray(values, dtype=np.float64)
    return {"mean": float(a.mean()), "sd": float(a.std(ddof=1)) if len(a) > 1 else 0.0, "n": int(len(a))}


def _slope(x: list[float], y: list[float]) -> float:
    return float(np.polyfit(np.log(x), np.log(y), 1)[0])


def summarize(campaign: Path, data_dir: Path, figure_dir: Path) -> dict:
    from grainlab.paper import NORMAL_STIFFNESS_N_PER_M

    measures = {"ucs": ("unconfined_strength_pa", "youngs_modulus_pa", "poisson_ratio"),
                "brazilian": ("tensile_strength_pa",)}
    table: list[dict] = []
    for family, label, keys in points():
        row: dict = {"family": family, "label": label, "keys": keys}
        for test in TESTS:
            rows = [r for r in read_sweep(campaign / test)
                    if _same(tuple(_number(r[k]) for k in BASE), _key_of(keys))]
            for name in measures[test]:
                values = [float(r[name]) for r in rows if r.get(name) not in (None, "", "None")]
                if values:
                    row[name] = _stats(values)
            if test == "ucs" and family == "stiffness" and rows:
                areas = [mean_bond_area(campaign / test / "sweep" / "runs" / r["name"] / "ucs" / "run.h5",
                                        float(keys["cement.radius_multiplier"]))  # type: ignore[arg-type]
                         for r in rows]
                row["mean_bond_area_m2"] = float(np.mean(areas))
        table.append(row)
    default_size = {}
    for test in TESTS:
        rows = read_sweep(campaign / f"{test}_default_size")
        for name in measures[test]:
            values = [float(r[name]) for r in rows if r.get(name) not in (None, "", "None")]
            if values:
                default_size[name] = _stats(values)
    verdicts = rules(table, NORMAL_STIFFNESS_N_PER_M)
    out = {"made_by": "benchmarks/cement_calibration.py", "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
           "seeds": list(SEEDS), "points": table, "default_size_base": default_size, "rules": verdicts}
    data_dir.mkdir(parents=True, exist_ok=True)
    (data_dir / "cement_calibration.json").write_text(json.dumps(out, indent=1) + "\n")
    if all(name in row for row in table for name in ("unconfined_strength_pa", "tensile_strength_pa")):
        figure(table, figure_dir / "cement_calibration.png")
    return out


def rules(table: list[dict], contact_stiffness: float) -> dict:
    """The three rules of docs/cemented.md, each yes, no or not yet (points missing)."""
    out: dict = {}
    strength = [r for r in table if r["family"] in ("base", "strength")]
    for name in ("unconfined_strength_pa", "tensile_strength_pa"):
        if all(name in r for r in strength):
            level = [float(r["keys"]["cement.tensile_strength"]) for r in strength]
            slope = _slope(level, [r[name]["mean"] for r in strength])
            out[f"rule 1 ({name})"] = {"slope": slope, "holds": SLOPE_RANGE[0] <= slope <= SLOPE_RANGE[1]}
        else:
            out[f"rule 1 ({name})"] = "not yet"
    stiff = [r for r in table if r["family"] == "stiffness"]
    if all("youngs_modulus_pa" in r and "mean_bond_area_m2" in r for r in stiff):
        scaled = [r["youngs_modulus_pa"]["mean"] / (contact_stiffness + float(r["keys"]["cement.normal_stiffness"])
                                                    * r["mean_bond_area_m2"]) for r in stiff]
        out["rule 2"] = {"E_over_parallel_stiffness": scaled, "spread": max(scaled) / min(scaled),
                         "holds": max(scaled) / min(scaled) <= STIFFNESS_SPREAD}
    else:
        out["rule 2"] = "not yet"
    base = next(r for r in table if r["family"] == "base")
    if "unconfined_strength_pa" in base and "tensile_strength_pa" in base:
        ratio = base["unconfined_strength_pa"]["mean"] / base["tensile_strength_pa"]["mean"]
        out["rule 3"] = {"ratio": ratio, "granite_ratio": GRANITE_RATIO, "shortfall": ratio < 0.5 * GRANITE_RATIO}
    else:
        out["rule 3"] = "not yet"
    return out


def figure(table: list[dict], path: Path) -> None:
    import matplotlib
    import matplotlib.ticker

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 4, figsize=(16, 3.8))
    families = [("strength", "cement.tensile_strength", "sigma_c = c (kPa)", 1e-3, True),
                ("cohesion_ratio", "cement.cohesion", "c / sigma_c", 1 / (500 * KPA), False),
                ("radius_multiplier", "cement.radius_multiplier", "lambda_b", 1.0, False),
                ("stiffness", "cement.normal_stiffness", "kn_bar = ks_bar (Pa/m)", 1.0, True)]
    base = next(r for r in table if r["family"] == "base")
    for ax, (family, key, xlabel, scale, logx) in zip(axes, families, strict=True):
        rows = [r for r in table if r["family"] == family] + ([base] if family != "stiffness" else [])
        rows.sort(key=lambda r: float(r["keys"][key]))
        x = [float(r["keys"][key]) * scale for r in rows]
        for name, label, marker in (("unconfined_strength_pa", "q_u", "o"), ("tensile_strength_pa", "sigma_t", "s")):
            y = [r[name]["mean"] / 1e3 for r in rows]
            e = [r[name]["sd"] / 1e3 for r in rows]
            ax.errorbar(x, y, yerr=e, marker=marker, capsize=3, label=label)
        ax.set_xlabel(xlabel)
        ax.set_ylabel("strength (kPa)")
        if logx:
            # the points' own values as the only ticks (log axes' minor labels overlap)
            ax.set_xscale("log")
            ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
            ax.set_xticks(x, [f"{v:.3g}" for v in x])
        handles, labels = ax.get_legend_handles_labels()
        if family == "stiffness":
            twin = ax.twinx()
            twin.errorbar(x, [r["youngs_modulus_pa"]["mean"] / 1e6 for r in rows],
                          yerr=[r["youngs_modulus_pa"]["sd"] / 1e6 for r in rows], color="k", marker="^",
                          capsize=3, label="E")
            twin.set_ylabel("E (MPa)")
            more = twin.get_legend_handles_labels()
            handles, labels = handles + more[0], labels + more[1]
        ax.legend(handles, labels, fontsize=8, loc="upper center" if family == "stiffness" else "best")
    fig.suptitle("Bonded samples: strength and stiffness against the micro parameters (mean +- sd over 5 seeds)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    args = arguments(__doc__.splitlines()[0], argv)
    if args.command == "plan":
        for name, test, quick in sweeps():
            print(f"# {name}\n{plan_text(test, quick)}")
        return 0
    if args.command == "summarize":
        out = summarize(args.campaign, args.data, args.figures)
        print(json.dumps(out["rules"], indent=1))
        return 0
    return run(args.campaign)


if __name__ == "__main__":
    sys.exit(main())
