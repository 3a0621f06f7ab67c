"""``grainlab export``: convert a run folder for other tools (``--vtk``: ParaView;
``--lammps``: a LAMMPS data file and input deck of a periodic simple shear).

Thin wrappers around :func:`grainlab.postprocess.export_vtk` and
:func:`grainlab.io.lammps_input.write_lammps_shear`, which scripts can call directly.
"""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from grainlab.io.lammps_input import LammpsShear

__all__ = ["register", "run"]


def register(subparsers: Any) -> None:
    """Add the ``export`` subcommand."""
    p = subparsers.add_parser(
        "export",
        help="export a run folder for other tools (--vtk: ParaView time series; --lammps: a LAMMPS run)",
        description=(
            "Export the snapshots of a run folder DIR/run.h5. With --vtk: one VTK XML "
            "PolyData file per snapshot (snapshot_0000.vtp, ...) and a run.pvd time series, "
            "in DIR/vtk or --out FOLDER. The time is the axial strain (else the time in s, "
            "else the snapshot index), for ParaView's time slider. Particles are points with "
            "a vertex cell and the point data id, kind, radius, displacement, rotation, "
            "n_contacts, stability_index, local_shear_strain, in_shear_band and the stored "
            "per-particle fields (velocity, ...); particle-particle contacts are lines between "
            "the two centres with the cell data normal_force, shear_force and the stored "
            "contact fields (overlap, sliding, bonded), NaN or -1 on the vertex cells "
            "(cell_kind: 0 particle, 1 contact). Wall contacts and contacts across a "
            "periodic boundary have no line. In ParaView: open run.pvd, add a Glyph "
            "filter (2D Glyph, Circle, filled; Scale Array radius, Scale Factor 2; "
            "Glyph Mode All Points) and colour by stability_index; see "
            "docs/file-formats.md, section ParaView. "
            "With --lammps: DIR is an engine state in a periodic cell (a file written by "
            "Simulation.save, a checkpoint.h5, or a run folder holding one); writes data.grainlab, "
            "in.grainlab (periodic simple shear at --shear-rate to --shear-strain, dumps of atoms "
            "and contacts) and export.json into --out (default: DIR/lammps, or STATE.lammps next to "
            "a state file); with --steps N instead, the cell held fixed for N steps, the one run a "
            "state with clumps goes to LAMMPS with (each clump a fix rigid/small body with grainlab's "
            "mass and moment of inertia, bodies.grainlab). Run it with 'mpirun -np 2 lmp -in in.grainlab' there; "
            "grainlab.io.lammps_input.read_lammps_run reads the dumps back as snapshots. "
            "See docs/lammps.md."
        ),
    )
    p.add_argument(
        "dir", metavar="DIR", help="run folder holding run.h5 (or the run.h5 itself); with --lammps: a state"
    )
    p.add_argument("--vtk", action="store_true", help="write .vtp files and a .pvd for ParaView")
    p.add_argument(
        "--lammps", action="store_true", help="write a LAMMPS data file and input deck (periodic simple shear)"
    )
    p.add_argument(
        "--shear-rate", type=float, metavar="PER_S",
        help="--lammps: shear rate gamma-dot, 1/s (required but for a simple-shear run's folder: its own)"
    )
    p.add_argument(
        "--shear-strain", type=float, metavar="GAMMA",
        help="--lammps: shear strain at the end (required but for a simple-shear run's folder: its own)"
    )
    p.add_argument(
        "--steps", type=int, metavar="N",
        help="--lammps: hold the periodic cell fixed for N steps instead of shearing it (clumps need it)",
    )  # fmt: skip
    p.add_argument(
        "--dump-every", type=int, default=0, metavar="STEPS",
        help="--lammps: steps between dumps (default: about 50 dumps over the run)",
    )  # fmt: skip
    p.add_argument(
        "--local-damping", choices=("omit", "cundall"), default="omit",
        help="--lammps: omit grainlab's local damping (LAMMPS 2021) or write fix damping/cundall (LAMMPS 2023+)",
    )  # fmt: skip
    p.add_argument("--out", metavar="FOLDER", help="output folder (default: DIR/vtk, DIR/lammps)")
    p.add_argument(
        "--ascii", action="store_true", help="write ASCII data arrays instead of base64 binary"
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    if args.vtk == args.lammps:
        raise ValueError("give one format: --vtk or --lammps")
    if args.lammps:
        return _lammps(args)
    from pathlib import Path

    from grainlab.io.results import ensure_output_folder
    from grainlab.postprocess.vtk import export_vtk

    run = Path(args.dir)
    if run.exists():  # else export_vtk says what is missing
        ensure_output_folder(args.out if args.out is not None else (run if run.is_dir() else run.parent) / "vtk")
    done = export_vtk(args.dir, args.out, binary=not args.ascii)
    print(
        f"grainlab export: {len(done.files)} snapshot(s) -> {done.pvd} "
        f"(time = {done.time_quantity}); open it in ParaView"
    )
    if done.clumps_pvd is not None:
        print(f"grainlab export: the clumps of {len(done.clump_files)} snapshot(s) -> {done.clumps_pvd}")
    return 0


def _lammps(args: argparse.Namespace) -> int:
    from pathlib import Path

    from grainlab.io.lammps_input import (
        LammpsFixedCell,
        check_lammps_export,
        simulation_to_export,
        write_lammps_fixed_cell,
        write_lammps_shear,
    )
    from grainlab.io.results import ensure_output_folder

    if args.steps is not None and (args.shear_rate is not None or args.shear_strain is not None):
        raise ValueError("--steps: holds the cell fixed; give it without --shear-rate and --shear-strain")
    source = Path(args.dir)
    sim = simulation_to_export(source)  # first: a missing or unusable source is the first thing to say
    protocol = _shear(args, source) if args.steps is None else LammpsFixedCell(args.steps, args.dump_every, args.local_damping)
    check_lammps_export(sim, protocol)  # before the output folder is made
    default = source / "lammps" if source.is_dir() else source.with_name(source.name + ".lammps")
    out = Path(args.out) if args.out is not None else default
    ensure_output_folder(out)
    if isinstance(protocol, LammpsFixedCell):
        done = write_lammps_fixed_cell(sim, out, protocol)
    else:
        done = write_lammps_shear(sim, out, protocol)
    clumps = f" ({len(sim.clumps)} clumps)" if len(sim.clumps) else ""
    print(
        f"grainlab export: {sim.n_particles} disks{clumps}, {done.steps} steps -> {done.input_file} and "
        f"{done.data_file.name}; run 'mpirun -np 2 lmp -in {done.input_file.name}' in {out}"
    )
    for item in done.dropped:
        print(f"  not carried: {item}")
    return 0


def _shear(args: argparse.Namespace, source: Any) -> LammpsShear:
    """The simple shear of ``--shear-rate`` and ``--shear-strain``, or of a simple-shear run's folder."""
    from grainlab.io.lammps_input import LammpsShear

    rate, strain = args.shear_rate, args.shear_strain
    planned = _simple_shear_plan(source)
    if planned is not None:  # a simple-shear run's folder: its rate and strain unless given
        rate = planned[0] if rate is None else rate
        strain = planned[1] if strain is None else strain
    for flag, value in (("--shear-rate", rate), ("--shear-strain", strain)):
        if value is None:
            raise ValueError(
                f"{flag}: required with --lammps but for --steps (a fixed cell) or a simple-shear run's folder, "
                "whose own it takes"
            )
    return LammpsShear(rate, strain, args.dump_every, args.local_damping)


def _simple_shear_plan(source: Any) -> tuple[float, float] | None:
    """``(shear rate, final strain)`` of the finished simple-shear run in folder ``source``, else None."""
    from grainlab.io.hdf5 import read_results, results_kind
    from grainlab.io.results import RESULTS_FILE

    results = source / RESULTS_FILE
    if not (source.is_dir() and results.is_file() and results_kind(results) == "simple_shear"):
        return None
    summary = read_results(results).summary
    return float(summary["shear_rate_per_s"]), float(summary["final_strain"])
