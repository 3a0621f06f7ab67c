"""``grainlab view``: one self-contained interactive HTML page of a run folder.

A thin wrapper around :func:`grainlab.viewer.write_viewer`, which scripts can call directly.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

__all__ = ["register", "run"]


def register(subparsers: Any) -> None:
    """Add the ``view`` subcommand."""
    p = subparsers.add_parser(
        "view",
        help="write (and open) an interactive HTML page of a run's snapshots",
        description=(
            "Write DIR/viewer.html (or --out FILE): one self-contained page, no network, with "
            "the grains of every snapshot of DIR/run.h5 coloured by the stability index lambda, "
            "the number of contacts, the displacement, rotation or local shear strain, the "
            "contact network, the shear band outline, a strain slider beside the stress-strain "
            "curve and a grain's values on hover. Opens it in the default browser when there "
            "is one (not without a display, not with --no-open)."
        ),
    )
    p.add_argument("dir", metavar="DIR", help="run folder holding run.h5 (or the run.h5 itself)")
    p.add_argument("--out", metavar="FILE", help="the page to write (default: DIR/viewer.html)")
    p.add_argument("--no-open", action="store_true", help="write the page without opening it")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Entry point of ``grainlab view``; returns the exit code."""
    from grainlab.io.results import ensure_output_folder
    from grainlab.viewer import open_in_browser, write_viewer

    folder = Path(args.dir)
    h5 = folder / "run.h5" if folder.is_dir() else folder
    if not h5.is_file():
        raise ValueError(f"{args.dir}: no run.h5 there (give a run folder or its run.h5)")
    out = Path(args.out) if args.out is not None else h5.parent / "viewer.html"
    if out.is_dir():
        raise ValueError(f"--out: {out} is a folder; give the file to write, e.g. {out / 'viewer.html'}")
    ensure_output_folder(out.parent)
    page = write_viewer(h5, out)
    opened = not args.no_open and open_in_browser(page)
    size_kb = page.stat().st_size / 1024
    print(f"grainlab view: {page} ({size_kb:.0f} KB){'; opened in the browser' if opened else ''}")
    return 0
