"""The ``grainlab`` command line.

Each subcommand lives in its own module under :mod:`grainlab.commands` and
exposes ``register(subparsers)``, which adds its parser and sets ``func`` to a
callable taking the parsed arguments and returning an exit code. Everything a
subcommand does is also a plain Python function that scripts can call.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence

import grainlab

#: Subcommand modules, in the order ``grainlab --help`` lists them.
COMMAND_MODULES: tuple[str, ...] = (
    "grainlab.commands.biaxial",
    "grainlab.commands.run",
    "grainlab.commands.analyze",
    "grainlab.commands.demo",
    "grainlab.commands.study",
    "grainlab.commands.sweep",
    "grainlab.commands.reproduce",
    "grainlab.commands.export",
    "grainlab.commands.report",
    "grainlab.commands.view",
)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="grainlab",
        description="2D discrete element laboratory for granular soils.",
    )
    parser.add_argument("--version", action=_Version)
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in COMMAND_MODULES:
        importlib.import_module(name).register(subparsers)
    for command in subparsers.choices.values():
        add_output_options(command)
    return parser


class _Version(argparse.Action):
    """``--version``: the version on the first line, then how to cite grainlab (CITATION.cff)."""

    def __init__(self, option_strings: Sequence[str], dest: str = argparse.SUPPRESS) -> None:
        super().__init__(option_strings, dest, nargs=0, default=argparse.SUPPRESS,
                         help="print the version and how to cite grainlab, and exit")

    def __call__(self, parser: argparse.ArgumentParser, namespace: argparse.Namespace,
                 values: object, option_string: str | None = None) -> None:
        from grainlab.citation import how_to_cite

        print(f"grainlab {grainlab.__version__}\n{how_to_cite()}")
        parser.exit()


def add_output_options(parser: argparse.ArgumentParser) -> None:
    """``--quiet``, ``--verbose`` and ``--no-progress``, the same on every subcommand.

    A command reads ``args.progress`` (show progress) and ``args.quiet`` (print
    nothing but errors and its final summary line), both set by :func:`main`.
    Progress goes to stderr: a bar on a terminal, a few plain lines otherwise
    (:mod:`grainlab._progress`).
    """
    group = parser.add_argument_group("output")
    loudness = group.add_mutually_exclusive_group()
    loudness.add_argument("-q", "--quiet", action="store_true",
                          help="print nothing but errors and the final summary line")
    loudness.add_argument("-v", "--verbose", action="store_true",
                          help="progress lines with more milestones and the current values (when not on a terminal)")
    group.add_argument("--no-progress", action="store_true", help="no progress display")


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if getattr(args, "func", None) is None:
        parser.print_help()
        return 2
    from grainlab._progress import set_verbose

    args.quiet = getattr(args, "quiet", False)  # a parser built without add_output_options has none
    args.progress = not (getattr(args, "no_progress", False) or args.quiet)
    set_verbose(getattr(args, "verbose", False))
    from grainlab._interrupt import interrupts_recorded

    try:
        with interrupts_recorded():
            return int(args.func(args))
    except ValueError as error:  # bad input, refused before any work
        print(f"grainlab {args.command}: error: {error}", file=sys.stderr)
        return 2
    except Exception as error:
        # imported only on failure: every command would otherwise pay for the protocol's imports
        from grainlab import SimulationUnstableError
        from grainlab.protocols.runner import ProtocolError

        if not isinstance(error, SimulationUnstableError | ProtocolError):
            raise  # a bug: its traceback is the useful report
        print(f"grainlab {args.command}: run stopped: {error}", file=sys.stderr)  # the physics failed mid-run
        return 1
    except KeyboardInterrupt:
        print(
            f"grainlab {args.command}: interrupted; what was written so far is kept (a biaxial "
            "run continues from its last checkpoint with --resume, or starts over if it had none)",
            file=sys.stderr,
        )
        return 130


if __name__ == "__main__":
    sys.exit(main())
