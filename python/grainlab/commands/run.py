"""``grainlab run PROTOCOL``: any registered test, end to end, into a results folder."""

from __future__ import annotations

import argparse
import functools
from collections.abc import Callable, Sequence
from typing import Any

from grainlab.protocols.registry import PROTOCOLS, resolve_config, run_named


def register(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    parser = subparsers.add_parser(
        "run",
        help=f"run a laboratory test by name ({', '.join(sorted(PROTOCOLS))})",
        description=(
            "Runs a registered test (docs/protocols.md) into a results folder: run.h5, timeseries.csv, "
            "summary.json, its figures and report.html. `grainlab run biaxial` is `grainlab biaxial` without "
            "its --strain-rate shortcut; `grainlab run oedometer` loads a sample between fixed side walls "
            "(K0); `grainlab run ucs` compresses a cemented sample without side walls (unconfined); "
            "`grainlab run brazilian` splits a cemented disc between two platens (indirect tension); `grainlab run "
            "crushing` crushes single agglomerates of bonded disks and fits their Weibull statistics. Keys: docs/cli.md."
        ),
    )
    parser.add_argument("protocol", choices=sorted(PROTOCOLS), help="the test to run")
    add_test_arguments(parser, '--set "oedometer.vertical_stresses=[200 kPa, 400 kPa]"')
    parser.set_defaults(func=run)


def add_test_arguments(parser: argparse.ArgumentParser, set_example: str) -> None:
    """The options of every command that runs a test: --out, --config, --set, --quick,
    --resume and --no-report."""
    parser.add_argument("--out", default="results", help="results folder (default: results)")
    parser.add_argument("--config", help="TOML file with [sample], [material], ... sections")
    parser.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                        help=f"override one key, e.g. {set_example}")
    parser.add_argument("--quick", action="store_true", help="a small sample of a few hundred disks")
    parser.add_argument("--resume", action="store_true", help="continue the killed run in --out")
    parser.add_argument("--no-report", action="store_true", help="do not write report.html at the end")


def run(args: argparse.Namespace) -> int:
    return run_test(args, args.protocol, args.overrides)


def run_test(args: argparse.Namespace, protocol: str, overrides: Sequence[str],
             runner: Callable[..., Any] | None = None) -> int:
    """Runs test ``protocol`` as ``args`` say (:func:`add_test_arguments`), then writes its
    report; ``runner(config, out, resume=, progress=)`` runs it (default :func:`run_named`)."""
    config = resolve_config(protocol, args.config, overrides, quick=args.quick)
    from grainlab.plot.workers import FigurePool  # matplotlib: imported once the command is valid

    # one set of worker processes draws the run's figures and then serves the report
    # (started when the figures are drawn: none while the test runs)
    with FigurePool(page_copies=not args.no_report):
        if runner is None:
            runner = functools.partial(run_named, protocol)
        result = runner(config, args.out, resume=args.resume, progress=args.progress)
        one_line = getattr(result, "one_line", None)
        print(one_line() if callable(one_line) else f"grainlab {protocol}: -> {result.out_dir}")
        if args.no_report or (args.resume and (result.out_dir / "report.html").exists()):
            return 0  # a report is written last (atomically): one there is this finished run's
        from grainlab.commands.report import write_after_run

        return write_after_run(result.out_dir, protocol, quiet=args.quiet)
