"""``grainlab study``: the paper's Sec. 7 packing study (19 packings, Figs. 15-17)."""

from __future__ import annotations

import argparse
import math

from grainlab.study.packing import GENERATION_FRICTION_SEARCH
from grainlab.study.paper import run_study


def register(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    parser = subparsers.add_parser(
        "study",
        help="the paper's packing study: 11 irregular + 8 hexagonal packings, Figs. 15-17",
        description=(
            "Makes and measures the 19 packings of the paper's Tables 2-3 (radius expansion to each target "
            "porosity, with the generation friction searched so that each packing bears load; hexagonal "
            "lattices with vacancies or compression), in parallel, resumable: rerunning "
            "the same command skips finished runs. Writes study.csv, Figs. 15-17 and summary.json."
        ),
    )
    parser.add_argument("--out", default="study", help="results folder (default: study)")
    parser.add_argument("--workers", type=int, default=None, help="local worker processes (default: cores)")
    parser.add_argument("--scheduler", default=None, help="Dask scheduler address, e.g. tcp://host:8786")
    parser.add_argument("--seed", type=int, default=0, help="campaign seed (default 0)")
    parser.add_argument(
        "--generation-friction", default="search", metavar="MU|search",
        help=("particle friction of the irregular packings' radius expansion: 'search' (default: per packing, "
              "0 where the frictionless packing at the target bears >= 100 kPa, otherwise one found by "
              "bisection in [0, 0.9] at which it bears 100-300 kPa) or a fixed number, e.g. 0 (frictionless) "
              "or 0.9 (Table 2's mu)"),
    )
    parser.add_argument("--no-report", action="store_true", help="do not write report.html at the end")
    parser.set_defaults(func=run)


def _generation_friction(text: str) -> float | str:
    if text == GENERATION_FRICTION_SEARCH:
        return text
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value >= 0):
        raise ValueError(f"--generation-friction: expected a number >= 0 or 'search', got {text!r}")
    return value


def run(args: argparse.Namespace) -> int:
    if args.workers is not None and args.workers < 1:
        raise ValueError(f"--workers: expected an integer >= 1, got {args.workers}")
    if args.seed < 0:
        raise ValueError(f"--seed: expected an integer >= 0, got {args.seed}")
    campaign, summary = run_study(args.out, seed=args.seed, workers=args.workers, scheduler=args.scheduler,
                                  progress=args.progress,
                                  overrides={"generation_friction": _generation_friction(args.generation_friction)})
    fit = summary["fig17_fit"]
    r2 = fit.get("r2", float("nan"))
    print(
        f"grainlab study: {len(campaign.rows)} packings ({len(campaign.executed)} run, "
        f"{len(campaign.skipped)} already finished, {len(campaign.failed)} failed); "
        f"statuses {summary['statuses']}; Fig. 17 R^2 {r2:.3f}; "
        f"{summary['campaign_wall_time_s']:.1f} s -> {args.out}"
    )
    report_failed = 0
    if not args.no_report:
        from grainlab.commands.report import write_after_run

        report_failed = write_after_run(args.out, "study", quiet=args.quiet)
    return 1 if campaign.failed or report_failed else 0
