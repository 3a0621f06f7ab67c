"""CEGEO's shape benchmark of trimers (docs/shapes-benchmark.md): a resumable
campaign of biaxial tests, one results folder per (size, eta, seed), and its
summary against the published values (benchmarks/data/cegeo_trimers.json).

    PYTHONPATH=python nohup nice -n 10 python benchmarks/cegeo_shapes.py run /work/campaigns/cegeo &
    PYTHONPATH=python python benchmarks/cegeo_shapes.py summarize /work/campaigns/cegeo \
        --data benchmarks/data --figures docs/images

``run`` goes through the plan one run at a time (``python -m grainlab biaxial``
subprocesses, one engine thread): a finished run (``summary.json`` written) is
skipped, an unfinished one continues with ``--resume`` (grainlab starts it over
when it stopped before its first checkpoint). After each run it measures the
run (``cegeo.json`` in its folder) and rewrites the summary. ``summarize``
measures whatever is finished and writes ``cegeo_results.json``,
``cegeo_results.csv`` and the two figures. ``plan`` prints the plan and the
state of each run.

The per-grain measures (packing fraction, Z, Z_c) come from the snapshots,
because the run's own records count pebbles in this version; the stresses come
from the walls.
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

PAPER = ROOT / "benchmarks" / "data" / "cegeo_trimers.json"
ETAS = (0.0, 0.1, 0.2, 0.3, 0.4, 0.5)
D_MIN_MM = 0.5
D_MAX_MM = 1.5
GENERATION_POROSITY = 0.2
ASPECT = 2.0  # height / width
WINDOW = (0.2, 0.4)  # steady-state window of axial strain
STEADY_CHANGE = 0.03  # largest change of the window's linear fit of sin(phi)
SNAPSHOTS = "[0, 0.2, 0.3, 0.4]"

#: The protocol's keys (docs/shapes-benchmark.md, "The protocol in grainlab").
BASE = {
    "sample.grading": "uniform_by_mass",
    "sample.d_min": f"{D_MIN_MM} mm",
    "sample.d_max": f"{D_MAX_MM} mm",
    "sample.porosity": str(GENERATION_POROSITY),
    "sample.generation_friction": "0",
    "consolidation.friction": "0",
    "consolidation.pressure": "50 kPa",
    "material.friction": "0.5",
    "material.platen_friction": "0",
    "boundary.kind": "walls",
    "shear.volume": "free",
    "shear.strain_rate": "auto",
    "shear.inertial_number": "1e-3",
    "shear.final_strain": str(WINDOW[1]),
    "shear.snapshot_strains": SNAPSHOTS,
    "run.threads": "1",
}


#: A quarter and a sixteenth of the campaign's rate (docs/shapes-benchmark.md, "Why the
#: strength is too high: the rate").
SLOW = {"shear.inertial_number": "2.5e-4"}
SLOWER = {"shear.inertial_number": "6.25e-5"}
#: A sixty-fourth of the rate, and a quarter of it with the local damping halved (0.4): the
#: runs that ask whether size 900 converges in rate and whether the damping keeps it from it
#: (docs/shapes-benchmark.md, "What the rate family gave").
SLOWEST = {"shear.inertial_number": "1.5625e-5"}
SLOW_DAMPED = {**SLOW, "material.local_damping": "0.4"}
#: Half the local damping at the quarter-rate run's own strain rate (eta 0, size 900): the
#: ``auto`` rate of SLOW_DAMPED counts the damping's effective mass and came out 1.7x faster,
#: so that run could not tell the damping from the rate.
SLOW_DAMPED_SAME_RATE = {"shear.strain_rate": "0.0011785113019775792", "material.local_damping": "0.4"}


def plan() -> list[dict]:
    """The runs in the order they are made: the small size (900 grains) for
    seed 1, a rate check (eta 0.3 at a quarter of the rate), the large size
    (3,600 grains) for seed 1, seeds 2 and 3 of the small size, the rate checks
    of the large size (eta 0 and 0.3 at a quarter of the rate), the small size's
    rate family (every eta at a quarter, eta 0 and 0.3 at a sixteenth), its follow-up
    (eta 0 at a quarter with half the local damping, eta 0 and 0.3 at a sixty-fourth),
    then the paper's size (5,000 grains) for seed 1."""
    runs = [dict(n=900, eta=e, seed=1) for e in ETAS]
    runs.append(dict(n=900, eta=0.3, seed=1, tag="slow", extra=SLOW))
    runs += [dict(n=3600, eta=e, seed=1) for e in ETAS]
    runs += [dict(n=900, eta=e, seed=s) for s in (2, 3) for e in ETAS]
    runs += [dict(n=3600, eta=e, seed=1, tag="slow", extra=SLOW) for e in (0.0, 0.3)]
    # the rate family of size 900: every eta at a quarter of the rate, eta 0 and 0.3 at a sixteenth
    runs += [dict(n=900, eta=e, seed=1, tag="slow", extra=SLOW) for e in ETAS if e != 0.3]
    runs += [dict(n=900, eta=e, seed=1, tag="slower", extra=SLOWER) for e in (0.0, 0.3)]
    # what the rate family left open, before the paper's size's trimers
    runs += [dict(n=900, eta=0.0, seed=1, tag="slow_damped", extra=SLOW_DAMPED)]
    runs += [dict(n=900, eta=e, seed=1, tag="slowest", extra=SLOWEST) for e in (0.0, 0.3)]
    runs += [dict(n=900, eta=0.0, seed=1, tag="slow_damped_same_rate", extra=SLOW_DAMPED_SAME_RATE)]
    runs += [dict(n=5000, eta=e, seed=1) for e in ETAS]
    return runs


def run_name(r: dict) -> str:
    tag = f"_{r['tag']}" if r.get("tag") else ""
    return f"n{r['n']}_eta{r['eta']:.1f}_s{r['seed']}{tag}"


def area_fraction(eta: float) -> float:
    """A grain's area over its circumscribed disk's (1 for a disk)."""
    if eta == 0:
        return 1.0
    from grainlab.shapes import shape_template

    return shape_template("trimer", eta).area / math.pi


def box_mm(n: int, eta: float) -> tuple[float, float]:
    """Width and height (mm) that hold about ``n`` grains at the generation
    porosity: with diameters uniform by area over [a, 3a] the mean squared
    circumscribed diameter is 3 a^2."""
    grain_area = area_fraction(eta) * math.pi / 4 * 3 * D_MIN_MM**2
    width = math.sqrt(n * grain_area / (1 - GENERATION_POROSITY) / ASPECT)
    if width < 10 * D_MAX_MM:
        raise ValueError(f"{n} grains at eta {eta}: the box ({width:.1f} mm) is narrower than 10 d_max")
    return round(width, 3), round(ASPECT * width, 3)


def overrides(r: dict) -> dict[str, str]:
    width, height = box_mm(r["n"], r["eta"])
    keys = dict(BASE)
    keys["sample.shape"] = "disk" if r["eta"] == 0 else "trimer"
    keys["sample.shape_parameter"] = str(r["eta"])
    keys["sample.seed"] = str(r["seed"])
    keys["sample.width"] = f"{width} mm"
    keys["sample.height"] = f"{height} mm"
    keys.update(r.get("extra", {}))
    return keys


def finished(folder: Path) -> bool:
    return (folder / "summary.json").is_file() and (folder / "run.h5").is_file()


def execute(campaign: Path, r: dict) -> bool:
    """Makes (or continues) one run; True when it finished."""
    folder = campaign / "runs" / run_name(r)
    command = [sys.executable, "-m", "grainlab", "biaxial", "--out", str(folder), "--no-report", "--quiet"]
    started = folder.is_dir() and any(folder.iterdir())
    if started:
        command.append("--resume")
    for key, value in overrides(r).items():
        command += ["--set", f"{key}={value}"]
    folder.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ)
    env["PYTHONPATH"] = str(ROOT / "python") + os.pathsep + env.get("PYTHONPATH", "")
    log(campaign, f"{'resume' if started else 'start'} {folder.name}")
    start = time.perf_counter()
    with open(folder / "run.log", "a") as out:
        out.write(" ".join(command) + "\n")
        out.flush()
        code = subprocess.call(command, stdout=out, stderr=subprocess.STDOUT, env=env, cwd=ROOT)
    log(campaign, f"{folder.name}: exit {code} after {time.perf_counter() - start:.0f} s")
    return code == 0 and finished(folder)


# ---------------------------------------------------------------- measures


def _box(walls) -> tuple[float, float, float, float]:
    """(x0, y0, x1, y1) between the four active walls."""
    active = np.flatnonzero(walls.active)
    xs = [walls.a[i][0] for i in active if abs(walls.inward_normal[i][0]) > 0.5]
    ys = [walls.a[i][1] for i in active if abs(walls.inward_normal[i][1]) > 0.5]
    return float(min(xs)), float(min(ys)), float(max(xs)), float(max(ys))


def grain_measures(results, name: str) -> dict:
    """Packing fraction (each clump's union once), Z and Z_c per grain of one snapshot."""
    from grainlab.samples import overlap_corrected_porosity

    snap = results.snapshot(name)
    grain = np.asarray(snap.grains())
    box = _box(results.walls(name))
    rho = 1.0 - overlap_corrected_porosity(snap.positions, snap.radii, box, grain=grain)
    ci, cj = np.asarray(snap.contact_i), np.asarray(snap.contact_j)
    loaded = np.asarray(snap.normal_force) > 0
    n_grains = int(grain.max()) + 1
    count = np.zeros(n_grains, dtype=int)  # force-bearing contacts, walls included
    np.add.at(count, grain[ci[loaded]], 1)
    pair = loaded & (cj >= 0)
    gi, gj = grain[ci[pair]], grain[cj[pair]]
    np.add.at(count, gj, 1)
    keep = count >= 2
    both = keep[gi] & keep[gj] & (gi != gj)
    gi, gj = gi[both], gj[both]
    n_keep = int(keep.sum())
    pairs = {(min(a, b), max(a, b)) for a, b in zip(gi.tolist(), gj.tolist(), strict=True)}
    return {
        "strain": float(snap.scalars.get("axial_strain", 0.0)),
        "rho": float(rho),
        "Z": 2 * len(pairs) / max(n_keep, 1),
        "Z_c": 2 * len(gi) / max(n_keep, 1),
        "floating_fraction": 1 - n_keep / n_grains,
        "n_grains": n_grains,
    }


def measure(folder: Path) -> dict:
    """The run's steady-state strength, isotropic packing and coordination (cegeo.json)."""
    from grainlab.io.hdf5 import read_results

    rows = list(csv.DictReader(open(folder / "timeseries.csv")))
    strain = np.array([float(r["axial_strain"]) for r in rows])
    s1 = np.array([float(r["axial_stress_pa"]) for r in rows])
    s2 = np.array([float(r["confining_stress_felt_pa"]) for r in rows])
    sin_phi = (s1 - s2) / (s1 + s2)
    window = (strain >= WINDOW[0] - 1e-9) & (strain <= WINDOW[1] + 1e-9)
    slope = float(np.polyfit(strain[window], sin_phi[window], 1)[0])
    change = slope * (WINDOW[1] - WINDOW[0])
    results = read_results(folder / "run.h5")
    snaps = {name: grain_measures(results, name) for name in results.snapshot_names}
    iso = snaps[min(snaps, key=lambda k: snaps[k]["strain"])]
    steady = [m for m in snaps.values() if WINDOW[0] - 1e-6 <= m["strain"] <= WINDOW[1] + 1e-6]
    summary = json.load(open(folder / "summary.json"))
    sample = results.config.get("sample", {})
    return {
        "run": folder.name,
        "n_grains": iso["n_grains"],
        "eta": float(sample.get("shape_parameter", float("nan"))),
        "seed": int(sample.get("seed", -1)),
        "sin_phi_star": float(sin_phi[window].mean()),
        "sin_phi_star_std": float(sin_phi[window].std()),
        "sin_phi_peak": float(sin_phi.max()),
        "steady_change": change,
        "steady": abs(change) <= STEADY_CHANGE,
        "rho_iso": iso["rho"],
        "Z_iso": iso["Z"],
        "Zc_iso": iso["Z_c"],
        "rho_steady": float(np.mean([m["rho"] for m in steady])),
        "Z_steady": float(np.mean([m["Z"] for m in steady])),
        "Zc_steady": float(np.mean([m["Z_c"] for m in steady])),
        "volumetric_strain_final": float(summary["final_volumetric_strain"]),
        "strain_rate": summary["strain_rate"],
        "inertial_number": summary["inertial_number"],
        "inertial_number_mean_diameter": summary["inertial_number_mean_diameter"],
        "time_step_s": summary["time_step_s"],
        "wall_time_s": summary["wall_time_s"],
        "wall_time_by_phase_s": summary["wall_time_by_phase_s"],
        "snapshots": snaps,
    }


def measured(folder: Path) -> dict | None:
    """cegeo.json of a finished run (made if missing or older than the run)."""
    if not finished(folder):
        return None
    out = folder / "cegeo.json"
    if not out.is_file() or out.stat().st_mtime < (folder / "summary.json").stat().st_mtime:
        out.write_text(json.dumps(measure(folder), indent=1))
    return json.loads(out.read_text())


# ---------------------------------------------------------------- verdict


def _spearman(x, y) -> float:
    rx = np.argsort(np.argsort(x)).astype(float)
    ry = np.argsort(np.argsort(y)).astype(float)
    return float(np.corrcoef(rx, ry)[0, 1])


def verdict(table: dict[float, dict], paper: dict) -> dict:
    """The rule of docs/shapes-benchmark.md applied to one size's seed means."""
    sp = np.array([table[e]["sin_phi_star"] for e in ETAS])
    rho = np.array([table[e]["rho_iso"] for e in ETAS])
    pa, pb = np.array(paper["sin_phi_star"]["A"]), np.array(paper["sin_phi_star"]["A_prime"])
    ra, rb = np.array(paper["rho_iso"]["A"]), np.array(paper["rho_iso"]["A_prime"])
    eta = np.array(ETAS)

    def within(value, a, b, tol):
        return (value >= np.minimum(a, b) - tol - 1e-12) & (value <= np.maximum(a, b) + tol + 1e-12)

    slope = float(np.polyfit(eta, sp, 1)[0])
    paper_slope = 0.5 * (np.polyfit(eta, pa, 1)[0] + np.polyfit(eta, pb, 1)[0])
    peak = int(np.argmax(rho))
    norm, na, nb = rho / rho[0] - 1, ra / ra[0] - 1, rb / rb[0] - 1
    zc_iso = np.array([table[e]["Zc_iso"] for e in ETAS])
    z_st = np.array([table[e]["Z_steady"] for e in ETAS])
    zc_st = np.array([table[e]["Zc_steady"] for e in ETAS])
    claims = {
        "S1": _spearman(eta, sp) >= 0.9 and sp[-1] > sp[0],
        "S2": int(within(sp, pa, pb, 0.03).sum()) >= 5,
        "S3": abs(slope - paper_slope) <= 0.3 * paper_slope,
        "P1": 0 < peak < len(ETAS) - 1 and rho[peak] - rho[0] >= 0.01 and rho[peak] - rho[-1] >= 0.005,
        "P2": int(within(norm, na, nb, 0.01).sum()) >= 5,
        "P3_informative": int(within(rho, ra, rb, 0.015).sum()) >= 5,
        "Z_informative": bool(
            np.all(np.abs(zc_iso[1:] - 6) <= 0.5) and abs(zc_iso[0] - 4) <= 0.3
            and np.all((z_st >= 2.75) & (z_st <= 4.25)) and np.all((zc_st >= 3.75) & (zc_st <= 5.25))
        ),
    }
    claims = {k: bool(v) for k, v in claims.items()}
    if all(claims[k] for k in ("S1", "S2", "S3", "P1", "P2")):
        overall = "reproduced"
    elif claims["S1"] and claims["P1"]:
        overall = "partly reproduced"
    else:
        overall = "not reproduced"
    return {
        "claims": claims,
        "verdict": overall,
        "spearman": _spearman(eta, sp),
        "slope": slope,
        "paper_slope": float(paper_slope),
        "sin_phi_within_band": within(sp, pa, pb, 0.03).tolist(),
        "rho_norm": norm.tolist(),
        "rho_norm_within_band": within(norm, na, nb, 0.01).tolist(),
        "peak_eta": ETAS[peak],
        "not_steady": [table[e]["runs"] for e in ETAS if not table[e]["all_steady"]],
    }


# ---------------------------------------------------------------- summary


KEYS = ("sin_phi_star", "rho_iso", "Z_iso", "Zc_iso", "rho_steady", "Z_steady", "Zc_steady", "wall_time_s")


def summarize(campaign: Path, data_dir: Path, figure_dir: Path) -> dict:
    paper = json.loads(PAPER.read_text())
    runs = [m for r in plan() if (m := measured(campaign / "runs" / run_name(r))) is not None]
    by_run = {m["run"]: m for m in runs}
    groups: dict[tuple[int, float, str], list[dict]] = {}
    for r in plan():
        m = by_run.get(run_name(r))
        if m is not None:
            groups.setdefault((r["n"], r["eta"], r.get("tag", "")), []).append(m)
    rows = []
    for (n, eta, tag), ms in sorted(groups.items()):
        row = {"n_target": n, "eta": eta, "tag": tag, "seeds": len(ms), "n_grains": int(np.mean([m["n_grains"] for m in ms]))}
        for k in KEYS:
            values = [m[k] for m in ms]
            row[k] = float(np.mean(values))
            row[k + "_spread"] = float(np.std(values)) if len(values) > 1 else None
        row["all_steady"] = all(m["steady"] for m in ms)
        row["runs"] = [m["run"] for m in ms]
        row["strain_rate"] = ms[0]["strain_rate"]
        row["inertial_number_mean_diameter"] = ms[0]["inertial_number_mean_diameter"]
        rows.append(row)
    verdicts = {}  # by size, and by size and rate ("900 slow") for a rate family with all six eta
    for n, tag in sorted({(r["n_target"], r["tag"]) for r in rows}):
        table = {r["eta"]: r for r in rows if r["n_target"] == n and r["tag"] == tag}
        if all(e in table for e in ETAS):
            verdicts[f"{n} {tag}".strip()] = verdict(table, paper)
    complete = [int(n) for n in verdicts if n.isdigit()]
    out = {
        "made_by": "PYTHONPATH=python python benchmarks/cegeo_shapes.py summarize /work/campaigns/cegeo "
                   "--data benchmarks/data --figures docs/images",
        "protocol": {"keys": BASE, "steady_window": WINDOW, "box_aspect": ASPECT},
        "finished_runs": len(runs),
        "planned_runs": len(plan()),
        "rows": rows,
        "verdicts": verdicts,
        "verdict_size": max(complete) if complete else None,
        "runs": [{k: v for k, v in m.items() if k != "snapshots"} for m in runs],
    }
    data_dir.mkdir(parents=True, exist_ok=True)
    (data_dir / "cegeo_results.json").write_text(json.dumps(out, indent=1))
    with open(data_dir / "cegeo_results.csv", "w", newline="") as f:
        fields = ["n_target", "eta", "tag", "seeds", "n_grains", *KEYS, "all_steady"]
        w = csv.DictWriter(f, fieldnames=fields, extrasaction="ignore")
        w.writeheader()
        for row in rows:
            w.writerow({k: (round(v, 4) if isinstance(v, float) else v) for k, v in row.items()})
    figures(rows, paper, figure_dir)
    return out


def figures(rows: list[dict], paper: dict, figure_dir: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure_dir.mkdir(parents=True, exist_ok=True)
    for key, label, name in (("sin_phi_star", r"$\sin\varphi^*$ (steady state)", "cegeo_sin_phi_star.png"),
                             ("rho_iso", r"$\rho_{iso}$ (isotropic state, per grain)", "cegeo_rho_iso.png")):
        fig, ax = plt.subplots(figsize=(5, 3.6))
        ax.plot(paper["eta"], paper[key]["A"], "ko--", mfc="none", label="CEGEO A (contact dynamics)")
        ax.plot(paper["eta"], paper[key]["A_prime"], "rs--", mfc="none", label="CEGEO A' (molecular dynamics)")
        for n, colour in zip(sorted({r["n_target"] for r in rows}), ("C0", "C2", "C4"), strict=False):
            sel = sorted((r for r in rows if r["n_target"] == n and not r["tag"]), key=lambda r: r["eta"])
            if not sel:
                continue
            yerr = [r[key + "_spread"] or 0.0 for r in sel]
            seeds = max(r["seeds"] for r in sel)
            ax.errorbar([r["eta"] for r in sel], [r[key] for r in sel], yerr=yerr, fmt="o-", color=colour,
                        label=f"grainlab, size {n} ({seeds} seed{'s' if seeds > 1 else ''})")
        ax.set_xlabel(r"$\eta$")
        ax.set_ylabel(label)
        ax.legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(figure_dir / name, dpi=120)
        plt.close(fig)


# ---------------------------------------------------------------- command line


def main(argv: list[str] | None = None) -> int:
    args = arguments(__doc__.splitlines()[0], argv)
    campaign, data_dir, figure_dir = args.campaign, args.data, args.figures
    if args.command == "plan":
        for r in plan():
            folder = campaign / "runs" / run_name(r)
            state = "finished" if finished(folder) else ("started" if folder.is_dir() else "to do")
            print(f"{run_name(r):24s} box {box_mm(r['n'], r['eta'])} mm  {state}")
        return 0
    if args.command == "summarize":
        out = summarize(campaign, data_dir, figure_dir)
        print(f"{out['finished_runs']} of {out['planned_runs']} runs finished; verdicts: "
              + json.dumps({n: v["verdict"] for n, v in out["verdicts"].items()}))
        return 0
    log(campaign, f"campaign: {len(plan())} runs planned (pid {os.getpid()})")
    failed = 0
    for r in plan():
        folder = campaign / "runs" / run_name(r)
        if finished(folder):
            continue
        if not execute(campaign, r):
            failed += 1
            log(campaign, f"{folder.name} did not finish (see its run.log); going on")
            continue
        try:
            summarize(campaign, data_dir, figure_dir)
        except Exception as error:  # the summary must not stop the campaign
            log(campaign, f"summary failed: {error!r}")
    log(campaign, f"campaign: done, {failed} run(s) not finished")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
