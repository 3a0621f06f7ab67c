"""``grainlab biaxial``: the paper's biaxial test, end to end."""

from __future__ import annotations

import argparse
from typing import Any

from grainlab.commands.run import add_test_arguments, run_test
from grainlab.protocols.biaxial import run_biaxial


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
    add_test_arguments(parser, '--set sample.porosity=0.14 --set "consolidation.pressure=200 kPa"')
    parser.add_argument("--strain-rate", help='axial strain rate, e.g. "2%%/min" (the paper\'s) or 0.01 (1/s)')
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    overrides = list(args.overrides)
    if args.strain_rate is not None:
        overrides.append(f"shear.strain_rate={args.strain_rate}")

    def runner(config: Any, out: str, **kwargs: Any) -> Any:
        return run_biaxial(config, out, **kwargs)

    return run_test(args, "biaxial", overrides, runner)
