"""``grainlab report DIR``: a self-contained ``report.html`` of a biaxial run or of the packing study."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from grainlab.report import write_report


def register(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    parser = subparsers.add_parser(
        "report",
        help="a self-contained report.html of a biaxial run or of the packing study",
        description=(
            "Writes DIR/report.html: one HTML file with the figures embedded, no scripts and no network "
            "needed. For a biaxial run (DIR/run.h5): the resolved configuration, how to rerun, the sample "
            "(grading curve, porosity, Z), the macro curves, the paper's Figs. 6-14, the shear band against "
            "the Mohr-Coulomb, Roscoe and Arthur angles from the run's own friction and dilation angles, "
            "the paper's values beside the run's, and the wall time per phase. For a study "
            "(DIR/study.csv): the configuration, the table, Figs. 15-17 with their fits and the wall time. "
            "Figures missing from DIR are drawn into it first. 'grainlab biaxial' and 'grainlab study' "
            "write the report themselves (unless --no-report). See docs/report.md."
        ),
    )
    parser.add_argument("dir", metavar="DIR", help="a biaxial results folder or a study folder")
    parser.add_argument(
        "--redraw",
        action="store_true",
        help="draw every figure again with this grainlab (and recompute the fabric numbers they show) "
        "instead of embedding the figures already in DIR",
    )
    parser.add_argument("--out", metavar="FILE", help="write the page here instead of DIR/report.html")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    started = time.perf_counter()
    path = write_report(args.dir, redraw=args.redraw, out=args.out)
    print(f"grainlab report: {path} ({path.stat().st_size / 1e6:.1f} MB, {time.perf_counter() - started:.1f} s)")
    return 0


def write_after_run(out_dir: str | Path, command: str, quiet: bool = False) -> int:
    """The report at the end of ``grainlab biaxial`` / ``grainlab study``: prints its path
    (unless ``quiet``), or, if it fails, says why on stderr and how to retry (the run's results stay valid)."""
    try:
        path = write_report(out_dir)
    except Exception as error:  # the run is done and valid; a report failure must not hide that
        print(
            f"grainlab {command}: the report could not be written ({type(error).__name__}: {error}); "
            f"retry with: grainlab report {out_dir}",
            file=sys.stderr,
        )
        return 1
    if not quiet:
        print(f"grainlab {command}: report {path}")
    return 0
