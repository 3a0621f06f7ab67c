"""``grainlab sweep PLAN.toml``: a parameter sweep of packing runs or of a test."""

from __future__ import annotations

import argparse

from grainlab.study.plan import load_plan, run_sweep


def register(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    parser = subparsers.add_parser(
        "sweep",
        help="a parameter sweep (grid or zip) of packing runs or of a test (biaxial, oedometer, cyclic, simple_shear)",
        description=(
            "Runs every combination named by PLAN.toml (docs/study.md), each in OUT/runs/run_NNNN, "
            "one row per run in OUT/sweep.csv. Resumable: rerunning skips finished runs."
        ),
    )
    parser.add_argument("plan", help="the plan (TOML)")
    parser.add_argument("--out", default="sweep", help="results folder (default: sweep)")
    parser.add_argument("--workers", type=int, default=None, help="local worker processes (default: cores)")
    parser.add_argument("--scheduler", default=None, help="Dask scheduler address, e.g. tcp://host:8786")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    if args.workers is not None and args.workers < 1:
        raise ValueError(f"--workers: expected an integer >= 1, got {args.workers}")
    load_plan(args.plan)  # validate before anything runs
    result = run_sweep(args.plan, args.out, workers=args.workers, scheduler=args.scheduler,
                       progress=args.progress)
    print(
        f"grainlab sweep: {len(result.rows)} runs ({len(result.executed)} run, {len(result.skipped)} already "
        f"finished, {len(result.failed)} failed); {result.wall_time_s:.1f} s -> {result.table}"
    )
    return 1 if result.failed else 0
