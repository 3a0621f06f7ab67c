"""Rolling resistance as a shape proxy (docs/shapes-benchmark.md, "Rolling
resistance as a shape proxy"): disks with rolling friction mu_r under the CEGEO
protocol, the mu_r that gives them the trimers' steady strength at each eta, and
whether their fabric and force anisotropies then agree with the trimers'.

    PYTHONPATH=python nohup nice -n 10 python benchmarks/rolling_proxy.py run /work/campaigns/rolling \\
        --trimers /work/campaigns/cegeo &
    PYTHONPATH=python python benchmarks/rolling_proxy.py summarize /work/campaigns/rolling \\
        --trimers /work/campaigns/cegeo --data benchmarks/data --figures docs/images

``run`` makes the grid (disks at each mu_r of :data:`MU_R_GRID`, seeds
:data:`SEEDS`, size :data:`SIZE`), then, for each eta whose trimers (the CEGEO
campaign's runs of that size and those seeds) are finished, the disks at the
matched mu_r*; it goes on until nothing is left that it can run, and a later
call continues (finished runs are skipped, an unfinished one resumes). Runs go
through ``cegeo_shapes.execute``: the same keys, one engine thread.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import cegeo_shapes as cegeo  # noqa: E402

#: Rolling friction of the grid's disks (mu_r = 0 is the CEGEO campaign's disks).
MU_R_GRID = (0.025, 0.05, 0.1, 0.2, 0.4)
SEEDS = (1, 2, 3)
SIZE = 900
SHAPED = tuple(e for e in cegeo.ETAS if e > 0)
#: The rule's tolerances (docs/shapes-benchmark.md): an anisotropy agrees within
#: max(ANISOTROPY_ABS, ANISOTROPY_REL x the trimers' value); Z within Z_ABS.
ANISOTROPY_ABS, ANISOTROPY_REL, Z_ABS = 0.02, 0.15, 0.25
#: Largest |sin(phi*) disks at mu_r* - trimers'| for the match itself to count.
MATCH_TOLERANCE = 0.015


def rolling_run(mu_r: float, seed: int, tag: str = "") -> dict:
    """A disk run of the CEGEO protocol with rolling friction ``mu_r``."""
    return dict(n=SIZE, eta=0.0, seed=seed, tag=f"mur{mu_r:.4f}{tag}",
                extra={"material.rolling_friction": f"{mu_r:.4f}"})


def trimer_run(eta: float, seed: int) -> dict:
    return dict(n=SIZE, eta=eta, seed=seed)


def fabric(folder: Path) -> dict | None:
    """Steady-state fabric of a finished run (fabric.json in its folder): the means
    over the window's snapshots of the contact-normal and force anisotropies and the
    coordination numbers, per grain (a clump is one body: grainlab.analysis.fabric_summary)."""
    if not cegeo.finished(folder):
        return None
    out = folder / "fabric.json"
    if out.is_file() and out.stat().st_mtime >= (folder / "summary.json").stat().st_mtime:
        return json.loads(out.read_text())
    from grainlab.analysis import fabric_summary
    from grainlab.io.hdf5 import read_results, snapshot_strain

    results = read_results(folder / "run.h5")
    rows = []
    for info in results.snapshots:
        strain = snapshot_strain(info)
        if cegeo.WINDOW[0] - 1e-6 <= strain <= cegeo.WINDOW[1] + 1e-6:
            s = fabric_summary(results.snapshot(info.name))
            rows.append({"strain": strain, "a": s["anisotropy"], "a_n": s["force_anisotropy"],
                         "mechanical_Z": s["mechanical_coordination_number"],
                         "mean_lambda": s["mean_stability_index"]})
    keys = ("a", "a_n", "mechanical_Z", "mean_lambda")
    value = {"run": folder.name, "snapshots": rows, **{k: float(np.mean([r[k] for r in rows])) for k in keys}}
    out.write_text(json.dumps(value, indent=1))
    return value


def _mean(values: list[float]) -> float:
    return float(np.mean(values)) if values else math.nan


def ensemble(campaign: Path, runs: list[dict]) -> dict | None:
    """Seed means of the CEGEO measures and the fabric of ``runs``, if all are finished."""
    folders = [campaign / "runs" / cegeo.run_name(r) for r in runs]
    measured = [cegeo.measured(f) for f in folders]
    fabrics = [fabric(f) for f in folders]
    if any(m is None for m in measured) or any(f is None for f in fabrics):
        return None
    row = {k: _mean([m[k] for m in measured]) for k in ("sin_phi_star", "rho_steady", "Z_steady", "Zc_steady")}
    row["sin_phi_star_spread"] = float(np.std([m["sin_phi_star"] for m in measured]))
    row.update({k: _mean([f[k] for f in fabrics]) for k in ("a", "a_n", "mechanical_Z", "mean_lambda")})
    row["runs"] = [f.name for f in folders]
    return row


def matched_mu_r(grid: dict[float, float], target: float) -> float | None:
    """The mu_r at which the disks' seed-mean sin(phi*) (``grid``: mu_r -> value, mu_r 0
    included) first reaches ``target``, by linear interpolation between grid points;
    None when no grid point reaches it."""
    mus = sorted(grid)
    for lo, hi in zip(mus, mus[1:], strict=False):
        a, b = grid[lo], grid[hi]
        if a <= target <= b and b > a:
            return lo + (target - a) * (hi - lo) / (b - a)
        if a >= target:
            return lo
    return None


def rule(trimers: dict, disks: dict) -> dict:
    """The agreement of the matched disks with the trimers of one eta (docs/shapes-benchmark.md)."""
    def agrees(key: str) -> bool:
        return abs(disks[key] - trimers[key]) <= max(ANISOTROPY_ABS, ANISOTROPY_REL * abs(trimers[key]))

    return {
        "strength_matched": abs(disks["sin_phi_star"] - trimers["sin_phi_star"]) <= MATCH_TOLERANCE,
        "a_agrees": agrees("a"),
        "a_n_agrees": agrees("a_n"),
        # a disk's Z (touching pairs) against the trimers' Z and Z_c
        "Z_agrees_with_Z": abs(disks["Z_steady"] - trimers["Z_steady"]) <= Z_ABS,
        "Z_agrees_with_Zc": abs(disks["Z_steady"] - trimers["Zc_steady"]) <= Z_ABS,
    }


def plan(campaign: Path, trimer_campaign: Path) -> tuple[list[dict], dict]:
    """The runs that can be made now (the grid, and the matched disks of each eta whose
    trimers and grid are finished) and the state: grid means, trimers, mu_r*."""
    runs = [rolling_run(mu, s) for mu in MU_R_GRID for s in SEEDS]
    grid = {0.0: ensemble(trimer_campaign, [dict(n=SIZE, eta=0.0, seed=s) for s in SEEDS])}
    grid.update({mu: ensemble(campaign, [rolling_run(mu, s) for s in SEEDS]) for mu in MU_R_GRID})
    state: dict = {"grid": {str(mu): row for mu, row in grid.items()}, "etas": {}}
    if any(row is None for row in grid.values()):
        return runs, state
    strength = {mu: row["sin_phi_star"] for mu, row in grid.items() if row is not None}
    for eta in SHAPED:
        trimers = ensemble(trimer_campaign, [trimer_run(eta, s) for s in SEEDS])
        entry: dict = {"trimers": trimers}
        if trimers is not None:
            mu = matched_mu_r(strength, trimers["sin_phi_star"])
            entry["mu_r_star"] = None if mu is None else round(mu, 4)
            if mu is not None:
                matched = [rolling_run(round(mu, 4), s, tag="_matched") for s in SEEDS]
                runs += matched
                disks = ensemble(campaign, matched)
                entry["disks"] = disks
                if disks is not None:
                    entry["rule"] = rule(trimers, disks)
        state["etas"][str(eta)] = entry
    return runs, state


def summarize(campaign: Path, trimer_campaign: Path, data_dir: Path, figure_dir: Path) -> dict:
    _, state = plan(campaign, trimer_campaign)
    decided = [e for e in state["etas"].values() if "rule" in e]
    state["made_by"] = ("PYTHONPATH=python python benchmarks/rolling_proxy.py summarize /work/campaigns/rolling "
                        "--trimers /work/campaigns/cegeo --data benchmarks/data --figures docs/images")
    state["rule"] = {"anisotropy_abs": ANISOTROPY_ABS, "anisotropy_rel": ANISOTROPY_REL, "z_abs": Z_ABS,
                     "match_tolerance": MATCH_TOLERANCE, "size": SIZE, "seeds": list(SEEDS)}
    if len(decided) == len(SHAPED):
        fabric_ok = sum(e["rule"]["a_agrees"] and e["rule"]["a_n_agrees"] for e in decided)
        state["verdict"] = ("strength and anisotropies" if fabric_ok >= len(SHAPED) - 1 else "strength only")
    no_match = [eta for eta, e in state["etas"].items() if e.get("trimers") and e.get("mu_r_star") is None]
    if no_match:
        state["no_mu_r_in_grid"] = no_match
    data_dir.mkdir(parents=True, exist_ok=True)
    (data_dir / "rolling_proxy.json").write_text(json.dumps(state, indent=1))
    figure(state, figure_dir)
    return state


def figure(state: dict, figure_dir: Path) -> None:
    rows = [(float(mu), row) for mu, row in state["grid"].items() if row is not None]
    if not rows:
        return
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(8, 3.4))
    mus = [mu for mu, _ in rows]
    axes[0].plot(mus, [r["sin_phi_star"] for _, r in rows], "o-", label="disks, rolling friction")
    for eta, e in state["etas"].items():
        if e.get("trimers") and e.get("mu_r_star") is not None:
            axes[0].plot([e["mu_r_star"]], [e["trimers"]["sin_phi_star"]], "s", mfc="none",
                         label=rf"trimers $\eta$ = {eta}")
    axes[0].set_xlabel(r"$\mu_r$")
    axes[0].set_ylabel(r"$\sin\varphi^*$")
    axes[0].legend(fontsize=6)
    for key, marker in (("a", "o"), ("a_n", "s")):
        etas = [float(eta) for eta, e in state["etas"].items() if e.get("disks")]
        if etas:
            axes[1].plot(etas, [state["etas"][str(eta)]["trimers"][key] for eta in etas], marker + "-k", mfc="none",
                         label=f"{key}, trimers")
            axes[1].plot(etas, [state["etas"][str(eta)]["disks"][key] for eta in etas], marker + "--C0",
                         label=rf"{key}, disks at $\mu_r^*$")
    axes[1].set_xlabel(r"$\eta$")
    axes[1].set_ylabel("steady-state anisotropy")
    axes[1].legend(fontsize=6)
    fig.tight_layout()
    figure_dir.mkdir(parents=True, exist_ok=True)
    fig.savefig(figure_dir / "rolling_proxy.png", dpi=120)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    for name in ("run", "summarize"):
        p = sub.add_parser(name)
        p.add_argument("campaign", type=Path, help="this campaign's folder (runs under CAMPAIGN/runs)")
        p.add_argument("--trimers", type=Path, required=True, help="the CEGEO campaign's folder")
        p.add_argument("--data", type=Path, default=None, help="where the summary goes (default: CAMPAIGN)")
        p.add_argument("--figures", type=Path, default=None, help="where the figure goes (default: CAMPAIGN)")
        p.add_argument("--wait", action="store_true", help="run: wait for the trimers' runs still to come")
    args = parser.parse_args(argv)
    campaign, trimers = args.campaign.resolve(), args.trimers.resolve()
    campaign.mkdir(parents=True, exist_ok=True)
    data_dir, figure_dir = args.data or campaign, args.figures or campaign
    if args.command == "summarize":
        state = summarize(campaign, trimers, data_dir, figure_dir)
        print(json.dumps({eta: {k: e.get(k) for k in ("mu_r_star", "rule")} for eta, e in state["etas"].items()},
                         indent=1))
        print("verdict:", state.get("verdict", "not yet (runs missing)"))
        return 0
    failed: set[str] = set()
    while True:
        runs, _ = plan(campaign, trimers)
        todo = [r for r in runs if not cegeo.finished(campaign / "runs" / cegeo.run_name(r))
                and cegeo.run_name(r) not in failed]
        if not todo:
            _, state = plan(campaign, trimers)
            waiting = [eta for eta, e in state["etas"].items() if e.get("trimers") is None]
            if not (args.wait and (waiting or not state["etas"])):
                break
            time.sleep(600)  # the CEGEO campaign makes the trimers' runs
            continue
        if not cegeo.execute(campaign, todo[0]):
            failed.add(cegeo.run_name(todo[0]))
            cegeo.log(campaign, f"{cegeo.run_name(todo[0])} did not finish (see its run.log); going on")
    summarize(campaign, trimers, data_dir, figure_dir)
    cegeo.log(campaign, f"rolling proxy: nothing left to run now, {len(failed)} run(s) not finished")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
