"""``grainlab run PROTOCOL``: any registered test, end to end, into a results folder."""

from __future__ import annotations

import argparse

from grainlab.protocols.registry import PROTOCOLS, resolve_config, run_named


def register(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    parser = subparsers.add_parser(
        "run",
        help=f"run a laboratory test by name ({', '.join(sorted(PROTOCOLS))})",
        description=(
            "Runs a registered test (docs/protocols.md) into a results folder: run.h5, timeseries.csv, "
            "summary.json, its figures and report.html. `grainlab run biaxial` is `grainlab biaxial` without "
            "its --strain-rate shortcut; `grainlab run oedometer` loads a sample between fixed side walls "
            "(K0). Keys: docs/cli.md."
        ),
    )
    parser.add_argument("protocol", choices=sorted(PROTOCOLS), help="the test to run")
    parser.add_argument("--out", default="results", help="results folder (default: results)")
    parser.add_argument("--config", help="TOML file with [sample], [material], ... sections")
    parser.add_argument(
        "--set",
        dest="overrides",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help='override one key, e.g. --set "oedometer.vertical_stresses=[200 kPa, 400 kPa]"',
    )
    parser.add_argument("--quick", action="store_true", help="a small sample of a few hundred disks")
    parser.add_argument("--resume", action="store_true", help="continue the killed run in --out")
    parser.add_argument("--no-report", action="store_true", help="do not write report.html at the end")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    config = resolve_config(args.protocol, args.config, args.overrides, quick=args.quick)
    from grainlab.plot.workers import FigurePool  # matplotlib: imported once the command is valid

    with FigurePool(page_copies=not args.no_report):
        result = run_named(args.protocol, config, args.out, resume=args.resume, progress=args.progress)
        one_line = getattr(result, "one_line", None)
        print(one_line() if callable(one_line) else f"grainlab {args.protocol}: -> {result.out_dir}")
        if args.no_report or (args.resume and (result.out_dir / "report.html").exists()):
            return 0
        from grainlab.commands.report import write_after_run

        return write_after_run(result.out_dir, args.protocol, quiet=args.quiet)
