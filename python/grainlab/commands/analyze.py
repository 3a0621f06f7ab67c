"""``grainlab analyze``: fabric, stability index, strain and shear band of a snapshot.

Everything here is a thin wrapper around :func:`grainlab.io.read_snapshot`,
:func:`grainlab.analysis.analyze_snapshot` and
:func:`grainlab.postprocess.write_analysis`, which scripts can call directly.
"""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path
from typing import Any

__all__ = ["MAX_BINS", "parse_columns", "parse_types", "register", "run"]

#: Most angular bins ``--bins`` takes (0.1 degree each): more only slows the rose diagrams.
MAX_BINS = 3600


def parse_columns(text: str | None, option: str = "--contact-columns") -> dict[str, str] | None:
    """``"i=c_ids[1],j=c_ids[2],normal_force=c_pl[2]"`` -> a role -> column dict."""
    if not text:
        return None
    out: dict[str, str] = {}
    for item in text.split(","):
        role, sep, name = item.partition("=")
        if not sep or not role.strip() or not name.strip():
            raise ValueError(
                f"{option}: expected ROLE=COLUMN items separated by commas, got {item!r}"
            )
        out[role.strip()] = name.strip()
    return out


def parse_types(text: str | None) -> tuple[int, ...]:
    """``"2,3"`` -> ``(2, 3)``."""
    if not text:
        return ()
    try:
        return tuple(int(t) for t in text.split(","))
    except ValueError:
        raise ValueError(
            f"--boundary-types: expected integers separated by commas, got {text!r}"
        ) from None


def register(subparsers: Any) -> None:
    """Add the ``analyze`` subcommand."""
    p = subparsers.add_parser(
        "analyze",
        help="fabric, stability index, strain and shear band of a snapshot",
        description=(
            "Analyse a snapshot (particles CSV id,x,y,radius or other names with --columns, PFC "
            "ball table, LAMMPS dump, YADE text export, legacy VTK file or run.h5, detected from "
            "the content): coordination numbers, contact anisotropy (Eq. 6-8), geometrical "
            "stability index lambda, and, with --reference, displacements, local strain and "
            "the shear band. Writes particles.csv, "
            "fabric.json and PNG + SVG figures into --out."
        ),
    )
    p.add_argument(
        "input", metavar="INPUT",
        help="particles CSV, PFC ball table, LAMMPS atoms dump, YADE text export, legacy VTK file or run.h5",
    )
    _add_input_options(p)
    p.add_argument(
        "--bins", type=int, default=18, help=f"angular bins over 360 degrees, 2 to {MAX_BINS} (default 18)"
    )
    p.add_argument(
        "--min-contacts", type=int, default=2, help="rattler threshold for mechanical Z (default 2)"
    )
    p.add_argument(
        "--lambda-exclude-boundary",
        action="store_true",
        help="leave wall and membrane contacts out of lambda (default: counted)",
    )
    _add_lambda_reading(p)
    p.add_argument(
        "--no-figures", action="store_true", help="write only particles.csv and fabric.json"
    )
    p.add_argument(
        "--out", metavar="DIR", default="analysis", help="output folder (default ./analysis)"
    )
    p.set_defaults(func=run)


def _add_lambda_reading(p: Any) -> None:
    """The options of lambda's reading of Eqs. 9-11 (docs/fabric.md, "Readings of Eqs. 9-11")."""
    from grainlab.analysis.stability import LAMBDA_ANCHORS, LAMBDA_DEVIATIONS, LAMBDA_SLOTS

    p.add_argument(
        "--lambda-slots",
        choices=LAMBDA_SLOTS,
        default=LAMBDA_SLOTS[0],
        help="reading of Eq. 9: each contact is compared with the stable position as many places "
        "on from the reference in angular order (angular), in contact-list order (list), or with "
        "the nearest one (nearest); default angular",
    )
    p.add_argument(
        "--lambda-anchor",
        choices=LAMBDA_ANCHORS,
        default=LAMBDA_ANCHORS[0],
        help="reading of Eq. 10: D the minimum (Eq. 10) or the mean of dSn over the n "
        "reference contacts (default min)",
    )
    p.add_argument(
        "--lambda-deviation",
        choices=LAMBDA_DEVIATIONS,
        default=LAMBDA_DEVIATIONS[0],
        help="reading of Eq. 9: D the sum of the deviations (Eq. 9) or per contact, "
        "divided by n - 1 (default sum)",
    )


def _same_configuration(snapshot: Any, reference: Any) -> bool:
    """True when the reference holds exactly the analysed snapshot's positions."""
    import numpy as np

    a, b = np.asarray(snapshot.positions), np.asarray(reference.positions)
    return a.shape == b.shape and bool(np.array_equal(a, b))


def _read_reference(
    args: argparse.Namespace, columns: Any, particle_columns: Any, boundary_types: tuple[int, ...]
) -> Any:
    """The ``--reference`` snapshot: of a LAMMPS dump its first frame and of a run.h5 its
    first snapshot unless ``--reference-timestep`` says another."""
    from grainlab.io import (
        FileFormatError,
        MissingKindWarning,
        detect_format,
        list_timesteps,
        read_snapshot,
    )

    ref_step = args.reference_timestep
    try:
        ref_format = detect_format(args.reference)
    except FileFormatError:
        if not particle_columns:
            raise
        ref_format = "particles-csv"  # its names are those --columns maps
    if ref_step is None and ref_format == "lammps-dump":
        ref_step = list_timesteps(args.reference)[0]
    # a run.h5 reference without a step: its first snapshot (strain 0)
    first = 0 if ref_step is None and ref_format == "grainlab-hdf5" else None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MissingKindWarning)  # said once, for INPUT
        return read_snapshot(
            args.reference,
            contacts=args.reference_contacts,
            timestep=ref_step,
            tolerance=args.tolerance,
            columns=columns if args.reference_contacts else None,
            boundary_types=boundary_types,
            particle_columns=particle_columns if ref_format != "grainlab-hdf5" else None,
            snapshot=first,
            grain_column=getattr(args, "grain_column", None) if ref_format == "lammps-dump" else None,
        )


def _add_input_options(p: argparse.ArgumentParser) -> None:
    """The options that say how to read the snapshot and its reference."""
    p.add_argument(
        "--contacts", metavar="FILE",
        help="contacts CSV (i,j by id; a PFC table's end1,end2) or LAMMPS local dump",
    )
    p.add_argument(
        "--columns",
        metavar="ROLE=COLUMN,...",
        help="column names of a particles CSV (INPUT and --reference), e.g. id=ID,x=pos_x,y=pos_y,radius=rad",
    )
    p.add_argument(
        "--reference", metavar="SNAPSHOT_FILE", help="earlier snapshot for displacement and strain"
    )
    p.add_argument(
        "--reference-contacts", metavar="FILE", help="contacts file of the reference snapshot"
    )
    p.add_argument(
        "--timestep", type=int, metavar="N", help="frame of a multi-frame dump (default: last)"
    )
    p.add_argument(
        "--reference-timestep",
        type=int,
        metavar="N",
        help="frame of the reference dump or run.h5 (default: the first; a run.h5 its strain-0 snapshot)",
    )
    p.add_argument(
        "--tolerance",
        type=float,
        default=0.0,
        metavar="METRES",
        help="touching tolerance (m) when contacts are detected from geometry (default 0)",
    )
    p.add_argument(
        "--contact-columns",
        metavar="ROLE=COLUMN,...",
        help="column roles of the contacts file: a LAMMPS local dump (i=c_ids[1],j=c_ids[2],"
        "normal_force=c_pl[2]) or a contacts CSV (i=end1,j=end2)",
    )
    p.add_argument(
        "--boundary-types",
        metavar="T1,T2",
        help="LAMMPS atom types that bound the sample (e.g. frozen wall disks): not part of it",
    )
    p.add_argument(
        "--grain-column",
        metavar="COLUMN",
        help="LAMMPS dump column naming each atom's rigid body (mol): the measures per body are "
        "reported too (a CSV's 'grain' column and a run.h5 of clumps give them without it)",
    )


def run(args: argparse.Namespace) -> int:
    """Entry point of ``grainlab analyze``; returns the exit code."""
    from grainlab.analysis import analyze_snapshot
    from grainlab.io.results import check_output_folder, ensure_output_folder
    from grainlab.postprocess import write_analysis

    if not 2 <= args.bins <= MAX_BINS:
        raise ValueError(f"--bins: must be an integer from 2 to {MAX_BINS}, got {args.bins}")
    if not 0 <= args.tolerance < float("inf"):
        raise ValueError(f"--tolerance: must be a finite value >= 0 m, got {args.tolerance}")
    columns = parse_columns(args.contact_columns)
    particle_columns = parse_columns(getattr(args, "columns", None), "--columns")
    boundary_types = parse_types(args.boundary_types)
    check_output_folder(args.out)  # a bad --out is refused before the input is read, and nothing is created
    snapshot = _read_input(args, columns, particle_columns, boundary_types)
    reference = _read_reference(args, columns, particle_columns, boundary_types) if args.reference else None
    if reference is not None and _same_configuration(snapshot, reference):
        print(
            "grainlab analyze: warning: the reference is the analysed snapshot itself (the same "
            "positions): every displacement is 0 and no shear band can be found; choose an earlier "
            "frame with --reference-timestep",
            file=sys.stderr,
        )
    result = analyze_snapshot(
        snapshot,
        reference,
        bins=args.bins,
        min_contacts=args.min_contacts,
        lambda_include_boundary=not args.lambda_exclude_boundary,
        lambda_slots=getattr(args, "lambda_slots", "angular"),
        lambda_anchor=getattr(args, "lambda_anchor", "min"),
        lambda_deviation=getattr(args, "lambda_deviation", "sum"),
    )
    ensure_output_folder(args.out)  # the input is accepted: the folder may now be made
    write_analysis(result, Path(args.out), figures=not args.no_figures)
    print(_summary_line(result.summary()) + f" -> {args.out}")
    return 0


def _read_input(args: argparse.Namespace, columns: Any, particle_columns: Any, boundary_types: Any) -> Any:
    """The snapshot to analyse; a missing ``kind`` column's warning printed in one line."""
    from grainlab.io import MissingKindWarning, read_snapshot

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", MissingKindWarning)
        snapshot = read_snapshot(
            args.input,
            contacts=args.contacts,
            timestep=args.timestep,
            tolerance=args.tolerance,
            columns=columns,
            boundary_types=boundary_types,
            particle_columns=particle_columns,
            grain_column=getattr(args, "grain_column", None),
        )
    for warning in caught:  # one line each, without the warnings module's source line
        if issubclass(warning.category, MissingKindWarning):
            print(f"grainlab analyze: warning: {warning.message}", file=sys.stderr)
        else:
            warnings.warn_explicit(warning.message, warning.category, warning.filename, warning.lineno)
    return snapshot


def _f(x: float | None, fmt: str = ".3f") -> str:
    """A number of the summary line (``n/a`` for None)."""
    return "n/a" if x is None else format(x, fmt)


def _summary_line(s: dict[str, Any]) -> str:
    """The printed line of ``grainlab analyze``: the fabric, and what was measured beyond it."""
    line = (
        f"grainlab analyze: {s['n_particles']} particles, {s['n_contacts']} contacts, "
        f"Z = {_f(s['Z'])}, "
        f"Zm = {_f(s['mechanical_Z'])}, a = {_f(s['a'])}, a_n = {_f(s['a_n'])}, "
        f"mean lambda = {_f(s['mean_lambda'])}"
    )
    if "lambda_reading" in s:  # said only when not the default reading
        line += f" ({s['lambda_reading']})"
    if s.get("strong_deviatoric_share") is not None:
        line += (
            f", strong network's share of q = {_f(s['strong_deviatoric_share'], '.2f')}, "
            f"q/p = {_f(s['rb_stress_ratio'])} (R-B {_f(s['rb_predicted_stress_ratio'])}), "
            f"{s['chains_n_chains']} force chains"
        )
    if s["band_angle_deg"] is not None:
        line += (
            f", band {_f(s['band_angle_deg'], '.1f')} deg x "
            f"{_f(s['band_thickness_diameters'], '.1f')} d, "
            f"lambda in/out {_f(s['mean_lambda_in_band'])}/{_f(s['mean_lambda_outside_band'])}"
        )
    return line + _bodies_line(s)


def _bodies_line(s: dict[str, Any]) -> str:
    """The measures per body of a snapshot of clumps for the summary line ("" for disks)."""
    if "n_bodies" not in s:
        return ""
    return (
        f"; {s['n_bodies']} bodies ({s['n_clumps']} clumps): Z = {_f(s['body_Z'])}, "
        f"Z_c = {_f(s['body_Z_c'])}, Zm = {_f(s['body_mechanical_Z'])}, a = {_f(s['body_a'])}, "
        f"mean lambda = {_f(s['body_mean_lambda'])}, orientation a_p = {_f(s['body_orientation_a'])}"
    )
