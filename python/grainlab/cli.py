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
    "grainlab.commands.analyze",
    "grainlab.commands.demo",
    "grainlab.commands.study",
    "grainlab.commands.sweep",
    "grainlab.commands.reproduce",
    "grainlab.commands.export",
    "grainlab.commands.report",
)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="grainlab",
        description="2D discrete element laboratory for granular soils.",
    )
    parser.add_argument("--version", action="version", version=f"grainlab {grainlab.__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in COMMAND_MODULES:
        importlib.import_module(name).register(subparsers)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if getattr(args, "func", None) is None:
        parser.print_help()
        return 2
    try:
        return int(args.func(args))
    except ValueError as error:  # bad input, refused before any work
        print(f"grainlab {args.command}: error: {error}", file=sys.stderr)
        return 2
    except Exception as error:
        # imported only on failure: every command would otherwise pay for the protocol's imports
        from grainlab import SimulationUnstableError
        from grainlab.protocols.biaxial import BiaxialError

        if not isinstance(error, SimulationUnstableError | BiaxialError):
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
