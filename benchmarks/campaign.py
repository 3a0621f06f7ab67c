"""What the resumable campaign scripts share (``cegeo_shapes.py``,
``cement_calibration.py``): their command line (``run``, ``summarize`` and
``plan`` of a campaign folder, with ``--data`` and ``--figures``) and their log,
``CAMPAIGN/campaign.log``, each line also printed."""

from __future__ import annotations

import argparse
import time
from pathlib import Path


def log(campaign: Path, message: str) -> None:
    """``message`` with the time, printed and appended to the campaign's log."""
    line = f"{time.strftime('%Y-%m-%d %H:%M:%S')} {message}"
    print(line, flush=True)
    with open(campaign / "campaign.log", "a") as f:
        f.write(line + "\n")


def arguments(description: str, argv: list[str] | None) -> argparse.Namespace:
    """The campaign command line: ``command`` (run, summarize or plan), ``campaign``
    (resolved and made), ``data`` and ``figures`` (the campaign folder unless given)."""
    parser = argparse.ArgumentParser(description=description)
    sub = parser.add_subparsers(dest="command", required=True)
    for name in ("run", "summarize", "plan"):
        p = sub.add_parser(name)
        p.add_argument("campaign", type=Path, help="campaign folder (runs under CAMPAIGN)")
        p.add_argument("--data", type=Path, default=None, help="where the summary goes (default: CAMPAIGN)")
        p.add_argument("--figures", type=Path, default=None, help="where the figures go (default: CAMPAIGN)")
    args = parser.parse_args(argv)
    args.campaign = args.campaign.resolve()
    args.campaign.mkdir(parents=True, exist_ok=True)
    args.data = args.data or args.campaign
    args.figures = args.figures or args.campaign
    return args
