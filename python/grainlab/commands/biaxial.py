"""``grainlab biaxial``: the paper's biaxial test, end to end."""

from __future__ import annotations

import argparse

from grainlab.protocols.biaxial import run_biaxial
from grainlab.protocols.biaxial.config import resolve


def register(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    parser = subparsers.add_parser(
        "biaxial",
        help="the paper's biaxial test: sample, consolidation, membrane, shearing",
        description=(
            "Generates a sample by radius expansion, consolidates it to sigma_0, replaces the side walls "
            "by a bonded membrane under the confining pressure and shears it at a constant strain rate. "
            "Defaults are the paper's Table 1."
        ),
    )
    parser.add_argument("--out", default="results", help="results folder (default: results)")
    parser.add_argument("--config", help="TOML file with [sample], [material], ... sections")
    parser.add_argument(
        "--set",
        dest="overrides",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help='override one key, e.g. --set sample.porosity=0.14 --set "consolidation.pressure=200 kPa"',
    )
    parser.add_argument("--strain-rate", help='axial strain rate, e.g. "2%%/min" (the paper\'s) or 0.01 (1/s)')
    parser.add_argument("--quick", action="store_true", help="a small sample of a few hundred disks")
    parser.add_argument("--resume", action="store_true", help="continue the killed run in --out")
    parser.add_argument("--no-report", action="store_true", help="do not write report.html at the end")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    overrides = list(args.overrides)
    if args.strain_rate is not None:
        overrides.append(f"shear.strain_rate={args.strain_rate}")
    config = resolve(args.config, overrides, quick=args.quick)
    from grainlab.plot.workers import FigurePool  # matplotlib: imported once the command is valid

    # one set of worker processes draws the run's figures and then serves the report
    # (started when the figures are drawn: none while the test runs)
    with FigurePool(page_copies=not args.no_report):
        result = run_biaxial(config, args.out, resume=args.resume, progress=args.progress)
        print(result.one_line())
        if args.no_report or (args.resume and (result.out_dir / "report.html").exists()):
            return 0  # a report is written last (atomically): one there is this finished run's
        from grainlab.commands.report import write_after_run

        return write_after_run(result.out_dir, "biaxial", quiet=args.quiet)
