"""``grainlab reproduce --out DIR``: the paper's tests over an ensemble of seeds and
variants, every claim of the paper checked with statistics and a verdict
(docs/reproduction.md)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from grainlab.reproduction.runs import (
    DEFAULT_SEEDS,
    DEFAULT_VARIANTS,
    PLAN_FILE,
    QUICK_SEEDS,
    QUICK_VARIANTS,
    describe,
    plan_from_args,
    run_reproduction,
)


def register(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    parser = subparsers.add_parser(
        "reproduce",
        help="does the paper's finding hold? an ensemble of runs, every claim with a verdict",
        description=(
            "Runs the paper's biaxial test (and its packing study) once per seed for each variant into "
            "OUT/runs/<variant>/seed-<k>/, then measures every claim of the paper from the stored runs "
            "and writes OUT/claims.json, OUT/claims.csv and OUT/reproduction.html (docs/reproduction.md). "
            "Resumable: rerunning skips finished runs; a later call may add variants or seeds."
        ),
    )
    parser.add_argument("--out", required=True, help="the reproduction folder")
    parser.add_argument("--seeds", type=int, default=None,
                        help=f"seeds 1..N of the ensemble (default {DEFAULT_SEEDS}, {QUICK_SEEDS} with --quick; "
                        "at least 2)")
    parser.add_argument(
        "--variants", nargs="+", default=None, metavar="VARIANT",
        help="paper, boundary_b, lambda_raw, rate=<rate> (e.g. rate=1%%/min), set:<key>=<value>, study, "
        f"study:<field>=<value> (default: {' '.join(DEFAULT_VARIANTS)}; with --quick {' '.join(QUICK_VARIANTS)}; "
        "a folder that already holds a reproduction keeps its variants)",
    )
    parser.add_argument("--quick", action="store_true", default=None,
                        help="small samples, 5 %%/min to 5 %% strain, the packing study in a small box")
    parser.add_argument("--workers", type=int, default=None, help="local worker processes (default: cores)")
    parser.add_argument("--scheduler", default=None, help="Dask scheduler address, e.g. tcp://host:8786")
    parser.add_argument("--claims-only", action="store_true",
                        help="run nothing: recompute the claims from the runs already in OUT")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    if args.workers is not None and args.workers < 1:
        raise ValueError(f"--workers: expected an integer >= 1, got {args.workers}")
    if args.workers is not None and args.scheduler is not None:
        raise ValueError("--workers/--scheduler: give one of them (Dask sets its own workers)")
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise ValueError(f"--out: {out} is a file, not a folder")
    if args.claims_only and not (out / PLAN_FILE).exists():
        raise ValueError(f"--claims-only: {out} holds no reproduction ({PLAN_FILE} not found); run it first")
    plan = plan_from_args(args.seeds, args.variants, args.quick, args.out)
    if not args.quiet:
        print(f"grainlab reproduce: seeds {', '.join(map(str, plan.seeds))}" + (" (quick)" if plan.quick else ""))
        for line in describe(plan):
            print(f"  {line}")
    failed: list[str] = []
    if not args.claims_only:
        result = run_reproduction(plan, args.out, workers=args.workers, scheduler=args.scheduler,
                                  progress=args.progress)
        failed = result.failed
        print(
            f"grainlab reproduce: {len(result.rows)} runs ({len(result.executed)} run, {len(result.skipped)} "
            f"already finished, {len(failed)} failed); {result.wall_time_s:.1f} s -> {result.table}"
        )
        for name in failed:
            print(f"  failed: {name} (see {args.out}/runs/{name}/error.txt)", file=sys.stderr)
    from grainlab.reproduction.outputs import write_outputs

    written = write_outputs(plan, args.out, workers=args.workers, progress=args.progress)
    for line in written.lines():
        print(line)
    return 1 if failed else 0
