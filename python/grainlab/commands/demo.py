"""``grainlab demo``: the engine demonstration (isotropic compression in servo walls)."""

from __future__ import annotations

import argparse

from grainlab.demo import compress


def register(subparsers: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    parser = subparsers.add_parser(
        "demo",
        help="engine demo: compress a random disk assembly to 100 kPa in servo walls",
        description="Compresses n x n disks (Table 1 properties) in four servo walls to a target stress.",
    )
    parser.add_argument("--out", default="results-demo", help="results folder (default: results-demo)")
    parser.add_argument("--n-side", type=int, default=20, help="disks per side of the initial grid (default 20)")
    parser.add_argument("--pressure-kpa", type=float, default=100.0, help="target stress in kPa (default 100)")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--threads", type=int, default=None, help="engine threads (default: all cores)")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    result = compress(
        args.out,
        n_side=args.n_side,
        pressure_pa=args.pressure_kpa * 1e3,
        seed=args.seed,
        threads=args.threads,
        progress=args.progress,
    )
    state = "converged" if result.converged else "NOT converged"
    print(
        f"grainlab demo: {result.n_particles} disks {state} in {result.steps} steps, "
        f"stresses {result.wall_stress_pa[0] / 1e3:.1f}/{result.wall_stress_pa[1] / 1e3:.1f} kPa, "
        f"porosity {result.porosity:.3f}, Z {result.coordination_number:.2f}, "
        f"{result.wall_time_s:.1f} s ({result.particle_steps_per_s:.2e} particle-steps/s) -> {args.out}"
    )
    return 0 if result.converged else 1
