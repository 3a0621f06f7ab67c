"""``grainlab export``: convert a run folder for other tools (``--vtk``: ParaView).

A thin wrapper around :func:`grainlab.postprocess.export_vtk`, which scripts can call directly.
"""

from __future__ import annotations

import argparse
from typing import Any

__all__ = ["register", "run"]


def register(subparsers: Any) -> None:
    """Add the ``export`` subcommand."""
    p = subparsers.add_parser(
        "export",
        help="export a run folder for other tools (--vtk: ParaView time series)",
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
            "docs/file-formats.md, section ParaView."
        ),
    )
    p.add_argument("dir", metavar="DIR", help="run folder holding run.h5 (or the run.h5 itself)")
    p.add_argument("--vtk", action="store_true", help="write .vtp files and a .pvd for ParaView")
    p.add_argument("--out", metavar="FOLDER", help="output folder (default: DIR/vtk)")
    p.add_argument(
        "--ascii", action="store_true", help="write ASCII data arrays instead of base64 binary"
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    if not args.vtk:
        raise ValueError("nothing to export: give a format, e.g. --vtk")
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
    return 0
