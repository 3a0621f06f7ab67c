"""LAMMPS / LIGGGHTS text dumps: atoms (``dump custom``) and contacts (``dump local``).

Columns, the contacts' roles and how they are recognised, boundary types, labels,
3D data and multi-frame files: docs/analysis.md, "Files read and written".
"""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from grainlab.io._planar import check_z_policy, detected_snapshot, keep_planar_rows, planar
from grainlab.io._points import boundary_kind, pair_indices
from grainlab.io._table import (
    MAX_LENGTH_M,
    FileFormatError,
    check_geometry,
    check_unique_ids,
    integral_column,
    label_column,
    parse_float_table,
    plain,
    read_lines,
    refuse_first,
)
from grainlab.snapshot import BODY_FIELD, GRAIN_FIELD, Snapshot

__all__ = [
    "DumpFrame",
    "attach_lammps_contacts",
    "list_timesteps",
    "read_dump_frames",
    "read_lammps_dump",
]


@dataclasses.dataclass
class DumpFrame:
    """One frame of a dump file: header values and the raw table."""

    timestep: int
    kind: str  # "ATOMS" or "ENTRIES"
    columns: list[str]
    data: NDArray[np.float64]
    line_numbers: NDArray[np.int64]  # 1-based file line of each row
    box: NDArray[np.float64] | None
    boundary: list[str]
    tilt: float  # the xy tilt of a triclinic box (m), 0 for an orthogonal one
    time: float | None
    header_line: int


#: A LAMMPS boundary flag of one direction: ``pp`` periodic, else two of f, s, m.
_BOUNDARY_FLAG = re.compile(r"^(pp|[fsm]{2})$")


def _frame_index(path: str | Path, lines: list[str]) -> list[dict[str, Any]]:
    """Walk the frames using the counts in their headers (no scan of data rows).

    A last frame cut short by the end of the file is kept with ``truncated``
    = (line, problem), so that the frames before it stay readable; a
    timestep given twice is refused.
    """
    walk = _HeaderWalk(path, lines)
    frames = []
    k = 0
    while k < len(lines):
        if not lines[k].strip():
            k += 1
            continue
        frame, k = walk.start(k)
        if "truncated" not in frame:
            k = walk.items(frame, k)
        frames.append(frame)
        if "truncated" in frame:
            break
    _check_frames(path, frames)
    return frames


def _check_frames(path: str | Path, frames: list[dict[str, Any]]) -> None:
    """Refuses an empty file, a first frame cut short and a timestep given twice."""
    if not frames:
        raise FileFormatError(path, None, "empty file: no 'ITEM: TIMESTEP' frame")
    if "truncated" in frames[0]:
        raise FileFormatError(path, *frames[0]["truncated"])
    first_line: dict[int, int] = {}
    for frame in frames[:-1] if "truncated" in frames[-1] else frames:
        if frame["timestep"] in first_line:
            raise FileFormatError(
                path,
                frame["line"],
                f"timestep {frame['timestep']} again (its first frame starts on line "
                f"{first_line[frame['timestep']]}): which frame is meant is ambiguous",
            )
        first_line[frame["timestep"]] = frame["line"]


class _HeaderWalk:
    """The header items of a dump's frames, line by line (:func:`_frame_index`);
    each method takes the line index ``k`` of an item and returns the next one."""

    def __init__(self, path: str | Path, lines: list[str]) -> None:
        self.path, self.lines, self.n = path, lines, len(lines)

    def value(self, k: int, cast: type[int] | type[float], what: str) -> Any:
        """The first word of line ``k + 1`` as ``cast``, or a clear error naming it."""
        try:
            return cast(self.lines[k + 1].split()[0])
        except (IndexError, ValueError):
            raise FileFormatError(self.path, k + 2, f"expected {what}") from None

    def start(self, k: int) -> tuple[dict[str, Any], int]:
        """A new frame from its (optional ``ITEM: TIME`` and) ``ITEM: TIMESTEP`` lines."""
        lines, n = self.lines, self.n
        frame: dict[str, Any] = {
            "box": None, "tilt": 0.0, "boundary": [], "time": None, "count": None, "line": k + 1
        }  # fmt: skip
        if lines[k].startswith("ITEM: TIME") and not lines[k].startswith("ITEM: TIMESTEP"):
            # `dump_modify time yes` puts the time first
            frame["time"] = self.value(k, float, "the simulation time")
            k += 2
        if k >= n or not lines[k].startswith("ITEM: TIMESTEP"):
            found = lines[k][:60] if k < n else "the end of the file"
            raise FileFormatError(self.path, k + 1, f"expected 'ITEM: TIMESTEP', found {found!r}")
        if k + 1 >= n:
            frame["truncated"] = (n, "file ends after 'ITEM: TIMESTEP'")
            return frame, n
        frame["timestep"] = self.value(k, int, "the timestep number")
        return frame, k + 2

    def items(self, frame: dict[str, Any], k: int) -> int:
        """The frame's header items up to and over its table (``ATOMS`` / ``ENTRIES``)."""
        lines, n = self.lines, self.n
        while True:
            if k >= n:
                frame["truncated"] = (k, "file ends inside a frame header (no ITEM: ATOMS / ENTRIES)")
                return k
            item = lines[k]
            if not item.startswith("ITEM:"):
                raise FileFormatError(self.path, k + 1, f"expected an 'ITEM:' line, found {item[:60]!r}")
            if (item.startswith("ITEM: NUMBER OF") or item.startswith("ITEM: TIME")) and k + 1 >= n:
                frame["truncated"] = (n, "file ends inside a frame header")
                return k
            if item.startswith("ITEM: NUMBER OF"):
                frame["count"] = self.value(k, int, "the number of atoms / entries")
                k += 2
            elif item.startswith("ITEM: BOX BOUNDS"):
                k = self.box(frame, k, item)
                if "truncated" in frame:
                    return k
            elif item.startswith("ITEM: TIME"):
                frame["time"] = self.value(k, float, "the simulation time")
                k += 2
            elif item.startswith("ITEM: UNITS"):
                frame["units"] = lines[k + 1].strip() if k + 1 < n else ""
                k += 2
            elif item.startswith("ITEM: ATOMS") or item.startswith("ITEM: ENTRIES"):
                return self.table(frame, k, item)
            else:
                raise FileFormatError(self.path, k + 1, f"unknown dump item {item[:60]!r}")

    def box(self, frame: dict[str, Any], k: int, item: str) -> int:
        """``ITEM: BOX BOUNDS`` with its boundary flags and three lines of bounds."""
        path = self.path
        flags = item.split()[3:]
        triclinic = flags[:3] == ["xy", "xz", "yz"]
        if triclinic:
            flags = flags[3:]
        if len(flags) != 3 or not all(_BOUNDARY_FLAG.match(f) for f in flags):
            raise FileFormatError(
                path,
                k + 1,
                "expected three boundary flags after 'ITEM: BOX BOUNDS' (x y z, each pp for "
                f"periodic or two of f, s, m, e.g. 'pp ff pp'), found {' '.join(flags) or 'none'!r}: "
                "cannot tell which directions are periodic",
            )
        if k + 3 >= self.n:
            frame["truncated"] = (self.n, "file ends inside the box bounds")
            return k
        try:
            frame["box"], frame["tilt"] = _box_bounds(self.lines[k + 1 : k + 4], triclinic)
        except (IndexError, ValueError):
            raise FileFormatError(
                path, k + 2, "expected three lines of box bounds 'lo hi'" + (" tilt" if triclinic else "")
            ) from None
        except _TiltOutOfPlane as error:
            raise FileFormatError(path, k + 3, str(error)) from None
        for axis, name in ((0, "x"), (1, "y")):
            lo, hi = frame["box"][axis]
            if not -MAX_LENGTH_M <= lo < hi <= MAX_LENGTH_M:
                raise FileFormatError(
                    path,
                    k + 2 + axis,
                    f"box bounds: {name}lo {plain(lo)} and {name}hi {plain(hi)} are not a finite "
                    f"range with {name}lo < {name}hi",
                )
        frame["boundary"] = flags
        return k + 4

    def table(self, frame: dict[str, Any], k: int, item: str) -> int:
        """``ITEM: ATOMS`` / ``ENTRIES``: the columns, and past the table's rows."""
        kind = item.split()[1]
        if frame["count"] is None:
            raise FileFormatError(self.path, k + 1, f"'ITEM: {kind}' before 'ITEM: NUMBER OF ...'")
        frame["kind"] = kind
        frame["columns"] = item.split()[2:]
        frame["header_line"] = k + 1
        frame["first"] = k + 1
        k += 1 + frame["count"]
        if k > self.n:
            frame["truncated"] = (
                self.n,
                f"file ends inside a frame: expected {frame['count']} rows after line {frame['header_line']}",
            )
        return k


class _TiltOutOfPlane(Exception):
    """A triclinic box leaning out of the x-y plane (xz or yz not 0)."""


def _box_bounds(rows: list[str], triclinic: bool) -> tuple[NDArray[np.float64], float]:
    """``[[xlo, xhi], [ylo, yhi], [zlo, zhi]]`` and the tilt ``xy`` of a dump's three
    box lines. A triclinic dump gives the bounding box and the tilts ``xy xz yz``;
    the cell's own bounds are the bounding box less the tilt's reach."""
    values = [[float(v) for v in row.split()[: 3 if triclinic else 2]] for row in rows]
    if len(rows) != 3 or any(len(v) != (3 if triclinic else 2) for v in values):
        raise ValueError("box bounds")
    box = np.array([v[:2] for v in values])
    if not triclinic:
        return box, 0.0
    xy, xz, yz = values[0][2], values[1][2], values[2][2]
    if xz != 0.0 or yz != 0.0:
        raise _TiltOutOfPlane(f"a triclinic box leaning out of the x-y plane (xz {xz!r}, yz {yz!r}) is 3D")
    box[0] -= (min(0.0, xy), max(0.0, xy))
    return box, xy


def list_timesteps(path: str | Path) -> list[int]:
    """The timesteps of the frames in a dump file, in file order (a last frame cut
    short by the end of the file is left out)."""
    return [f["timestep"] for f in _frame_index(path, read_lines(path)) if "truncated" not in f]


def read_dump_frames(path: str | Path, timestep: int | None = None) -> DumpFrame:
    """Parse one frame of a dump (the last one when ``timestep`` is None)."""
    lines = read_lines(path)
    frames = _frame_index(path, lines)
    steps = [fr["timestep"] for fr in frames if "truncated" not in fr]
    shown = ", ".join(map(str, steps[:20])) + (" ..." if len(steps) > 20 else "")
    if timestep is None:
        f = frames[-1]
    else:
        match = [fr for fr in frames if fr.get("timestep") == int(timestep)]
        if not match:
            raise FileFormatError(
                path, None, f"no frame with timestep {timestep} (timesteps: {shown})"
            )
        f = match[-1]
    if "truncated" in f:  # the last frame: the ones before it are intact
        line, problem = f["truncated"]
        raise FileFormatError(path, line, f"{problem}; the intact frames are at timesteps {shown}")
    first, count = f["first"], f["count"]
    rows = lines[first : first + count]
    numbers = np.arange(first + 1, first + count + 1, dtype=np.int64)
    columns = f["columns"]
    if len(set(columns)) != len(columns):
        raise FileFormatError(path, f["header_line"], "duplicate column names in the header")
    data = parse_float_table(
        path, rows, numbers, len(columns), delimiter=None, column_names=columns
    )
    return DumpFrame(
        timestep=f["timestep"],
        kind=f["kind"],
        columns=columns,
        data=data,
        line_numbers=numbers,
        box=f["box"],
        boundary=f["boundary"],
        tilt=f["tilt"],
        time=f["time"],
        header_line=f["header_line"],
    )


def read_lammps_dump(
    path: str | Path,
    *,
    timestep: int | None = None,
    contacts: str | Path | None = None,
    columns: Mapping[str, str] | None = None,
    tolerance: float = 0.0,
    detect: bool = True,
    boundary_types: Sequence[int] = (),
    body_column: str | None = None,
    z_policy: str = "refuse",
    z0: float | None = None,
    grain_column: str | None = None,
) -> Snapshot:
    """Read one frame of a LAMMPS atoms dump (and its contacts) into a :class:`Snapshot`.

    ``contacts`` is a ``dump local`` file whose roles ``columns`` names; without it
    (and with ``detect``) contacts come from the geometry within ``tolerance`` (m).
    ``boundary_types``, ``body_column``, ``grain_column`` and ``z_policy`` / ``z0``
    (3D data): docs/analysis.md, "Files read and written".
    """
    check_z_policy(z_policy, z0, contacts)
    frame = _atoms_frame(path, timestep)
    col = {name: frame.data[:, k] for k, name in enumerate(frame.columns)}
    where, numbers = frame.header_line, frame.line_numbers
    ids = integral_column(path, col["id"], numbers, "id")
    check_unique_ids(path, ids, numbers)
    box2 = None if frame.box is None else frame.box[:2].copy()
    used = {"id", "z", "zu", "zs", "zsu", "vz", "fz", "omegax", "omegay", "ix", "iy", "iz"}
    x, y, (xn, yn) = _dump_positions(path, frame, col, box2)
    used |= {xn, yn}
    radius = _dump_radii(path, frame, col, used)
    zn = {"x": "z", "xu": "zu", "xs": "zs", "xsu": "zsu"}[xn]
    z = col[zn] if zn in col else None
    if z is not None and zn in ("zs", "zsu"):
        assert frame.box is not None  # the scaled x and y needed it (refused above)
        z = frame.box[2, 0] + z * (frame.box[2, 1] - frame.box[2, 0])
    plan = planar(path, where, z, radius, z_policy=z_policy, z0=z0, column=zn)
    check_geometry(path, np.c_[x, y][plan.keep], plan.radii, numbers[plan.keep], (xn, yn))
    fields = _dump_fields(col, used)
    fields |= _label_fields(path, frame, {"body_column": body_column, "grain_column": grain_column})
    kind = _dump_kinds(path, frame, col, boundary_types)
    periodic = _dump_periodic(path, frame, z_policy)
    metadata = {"source": str(path), "format": "lammps-dump", "timestep": frame.timestep, "positions": f"{xn} {yn}"}
    snap_kwargs: dict[str, Any] = dict(
        ids=ids, kind=kind, particle_fields=fields, box=box2, tilt=frame.tilt, time=frame.time, metadata=metadata,
        periodic=periodic if box2 is not None else (False, False),
    )  # fmt: skip
    positions, radius = keep_planar_rows(plan, np.c_[x, y], radius, snap_kwargs, z_field=True)
    if contacts is not None:
        snap = Snapshot(positions, radius, **snap_kwargs)
        return attach_lammps_contacts(snap, contacts, timestep=frame.timestep, columns=columns)
    return detected_snapshot(path, plan, positions, radius, snap_kwargs, detect=detect, tolerance=tolerance)


def _atoms_frame(path: str | Path, timestep: int | None) -> DumpFrame:
    """The frame of an atoms dump, with an ``id`` column and at least one atom."""
    frame = read_dump_frames(path, timestep)
    where = frame.header_line
    if frame.kind != "ATOMS":
        raise FileFormatError(path, where, f"expected an atoms dump ('ITEM: ATOMS'), found 'ITEM: {frame.kind}'")
    if "id" not in frame.columns:
        raise FileFormatError(path, where, f"missing column 'id' (columns: {' '.join(frame.columns)})")
    if frame.data.shape[0] == 0:
        raise FileFormatError(path, where, "the frame has no atoms")
    return frame


def _dump_positions(
    path: str | Path, frame: DumpFrame, col: Mapping[str, NDArray[np.float64]], box2: NDArray[np.float64] | None
) -> tuple[NDArray[np.float64], NDArray[np.float64], tuple[str, str]]:
    """The atoms' x and y (m) from the first pair of position columns found, unscaled."""
    for xn, yn, scaled in (("x", "y", False), ("xu", "yu", False), ("xs", "ys", True), ("xsu", "ysu", True)):
        if xn in col and yn in col:
            x, y = col[xn].copy(), col[yn].copy()
            if scaled:
                if box2 is None:
                    raise FileFormatError(path, frame.header_line, "scaled coordinates need the box bounds")
                x = box2[0, 0] + x * (box2[0, 1] - box2[0, 0]) + y * frame.tilt
                y = box2[1, 0] + y * (box2[1, 1] - box2[1, 0])
            return x, y, (xn, yn)
    raise FileFormatError(
        path,
        frame.header_line,
        f"missing position columns 'x y' (or xu yu, xs ys) (columns: {' '.join(frame.columns)})",
    )


def _dump_radii(path: str | Path, frame: DumpFrame, col: Mapping[str, NDArray[np.float64]],
                used: set[str]) -> NDArray[np.float64]:
    """The atoms' radii (m) from ``radius`` or ``diameter``, each > 0; the column joins ``used``."""
    if "radius" in col:
        radius, rname = col["radius"], "radius"
    elif "diameter" in col:
        radius, rname = 0.5 * col["diameter"], "diameter"
    else:
        raise FileFormatError(
            path,
            frame.header_line,
            f"missing column 'radius' (or 'diameter') (columns: {' '.join(frame.columns)})",
        )
    used.add(rname)
    refuse_first(path, radius <= 0, frame.line_numbers,
                 lambda k: f"column {rname!r}: {plain(col[rname][k])} is not > 0")
    return radius


def _dump_fields(col: Mapping[str, NDArray[np.float64]], used: set[str]) -> dict[str, NDArray[Any]]:
    """The particle fields of the columns not read otherwise: velocity and force as
    pairs, every other column as it is."""
    fields: dict[str, NDArray[Any]] = {}
    for pair, name in ((("vx", "vy"), "velocity"), (("fx", "fy"), "force")):
        if pair[0] in col and pair[1] in col:
            fields[name] = np.c_[col[pair[0]], col[pair[1]]]
            used |= set(pair)
    for name, values in col.items():
        if name not in used:
            fields[name] = values
    return fields


def _dump_kinds(path: str | Path, frame: DumpFrame, col: Mapping[str, NDArray[np.float64]],
                boundary_types: Sequence[int]) -> NDArray[Any] | None:
    """Each atom's kind: a boundary atom (``MEMBRANE``) of a type in ``boundary_types``."""
    if not len(boundary_types):
        return None
    if "type" not in col:
        raise FileFormatError(path, frame.header_line, "boundary_types needs a 'type' column in the dump")
    return boundary_kind(col["type"], boundary_types)


def _dump_periodic(path: str | Path, frame: DumpFrame, z_policy: str) -> tuple[bool, bool]:
    """Which of x and y are periodic (``pp``); a tilted box needs y periodic and no 3D policy."""
    periodic = (False, False)
    if frame.boundary:
        periodic = (frame.boundary[0] == "pp", frame.boundary[1] == "pp")
    if frame.tilt != 0.0 and not periodic[1]:
        raise FileFormatError(path, frame.header_line, "a triclinic box with xy tilt needs y periodic ('pp')")
    if frame.tilt != 0.0 and z_policy != "refuse":
        raise ValueError(f"z_policy: {z_policy!r} is not supported in a triclinic (tilted) box")
    return periodic


#: The label fields a dump's columns may give: argument -> (field, what, least label).
_LABELS = {"body_column": (BODY_FIELD, "body", -1), "grain_column": (GRAIN_FIELD, "grain", 0)}


def _label_fields(path: str | Path, frame: DumpFrame, columns: Mapping[str, str | None]) -> dict[str, NDArray[Any]]:
    """The boundary body and grain labels of the atoms from the columns ``columns`` names
    (``{"body_column": "mol", "grain_column": None}``), checked, naming the line."""
    fields: dict[str, NDArray[Any]] = {}
    for argument, name in columns.items():
        if name is None:
            continue
        field, what, least = _LABELS[argument]
        if name not in frame.columns:
            raise FileFormatError(
                path, frame.header_line, f"no column {name!r} for {argument} (columns: {' '.join(frame.columns)})"
            )
        values = frame.data[:, frame.columns.index(name)]
        fields[field] = label_column(path, values, frame.line_numbers, name, what, least)
    return fields


_ID_NAMES = (("patom1", "patom2"), ("id1", "id2"), ("atom1", "atom2"), ("i", "j"))
_ROLE_NAMES = {
    "normal_force": ("normal_force", "fn", "force"),
    "shear_force": ("shear_force", "fs"),
    "dist": ("dist",),
    "fx": ("fx",),
    "fy": ("fy",),
}
_ROLES = ("i", "j", "normal_force", "shear_force", "fx", "fy", "shear_x", "shear_y", "dist")


def _resolve_columns(
    path: str | Path,
    frame: DumpFrame,
    columns: Mapping[str, str] | None,
    atom_ids: NDArray[np.int64],
) -> dict[str, int]:
    names = frame.columns
    lower = [c.lower() for c in names]
    roles: dict[str, int] = {}
    for role, name in (columns or {}).items():
        if role not in _ROLES:
            raise ValueError(f"columns: unknown role {role!r} (roles: {', '.join(_ROLES)})")
        if name not in names:
            raise FileFormatError(
                path,
                frame.header_line,
                f"no column {name!r} for role {role!r} (columns: {' '.join(names)})",
            )
        roles[role] = names.index(name)
    if "i" not in roles or "j" not in roles:
        for a, b in _ID_NAMES:
            if a in lower and b in lower:
                roles.setdefault("i", lower.index(a))
                roles.setdefault("j", lower.index(b))
                break
        else:
            roles.update(_guess_id_columns(frame, atom_ids))
    for role, options in _ROLE_NAMES.items():
        if role not in roles:
            for opt in options:
                if opt in lower:
                    roles[role] = lower.index(opt)
                    break
    if "i" not in roles or "j" not in roles:
        raise FileFormatError(
            path,
            frame.header_line,
            "cannot tell which columns hold the two atom ids; name them with "
            "columns={'i': ..., 'j': ...} (columns: " + " ".join(names) + ")",
        )
    return roles


def _guess_id_columns(frame: DumpFrame, atom_ids: NDArray[np.int64]) -> dict[str, int]:
    """First c_NAME[1], c_NAME[2] pair of columns whose values are all atom ids."""
    pattern = re.compile(r"^(c_[^\[]+)\[1\]$")
    for k, name in enumerate(frame.columns):
        m = pattern.match(name)
        if not m:
            continue
        second = f"{m.group(1)}[2]"
        if second not in frame.columns:
            continue
        k2 = frame.columns.index(second)
        a, b = frame.data[:, k], frame.data[:, k2]
        if (
            np.all(a == np.round(a))
            and np.all(b == np.round(b))
            and np.all(np.isin(a, atom_ids))
            and np.all(np.isin(b, atom_ids))
        ):
            return {"i": k, "j": k2}
    return {}


def _pair_forces(data: NDArray[np.float64], roles: Mapping[str, int],
                 n_hat: NDArray[np.float64]) -> tuple[NDArray[np.float64] | None, NDArray[np.float64] | None]:
    """Each pair's normal force (compression positive) and shear force along
    ``(-n_y, n_x)`` from the columns there are (None where none gives it)."""
    t_hat = np.c_[-n_hat[:, 1], n_hat[:, 0]]
    normal_force = None
    if "normal_force" in roles:
        normal_force = data[:, roles["normal_force"]]
    elif "fx" in roles and "fy" in roles:
        normal_force = -(data[:, roles["fx"]] * n_hat[:, 0] + data[:, roles["fy"]] * n_hat[:, 1])
    shear_force = None
    if "shear_x" in roles and "shear_y" in roles:
        shear_force = data[:, roles["shear_x"]] * t_hat[:, 0] + data[:, roles["shear_y"]] * t_hat[:, 1]
    elif "shear_force" in roles:
        shear_force = data[:, roles["shear_force"]]
    return normal_force, shear_force


def attach_lammps_contacts(
    snapshot: Snapshot,
    path: str | Path,
    *,
    timestep: int | None = None,
    columns: Mapping[str, str] | None = None,
) -> Snapshot:
    """The snapshot with contacts from a LAMMPS ``dump local`` file (docs/analysis.md)."""
    if timestep is None:
        timestep = snapshot.metadata.get("timestep")
    frame = read_dump_frames(path, timestep)
    if frame.kind != "ENTRIES":
        raise FileFormatError(
            path,
            frame.header_line,
            f"expected a local dump ('ITEM: ENTRIES'), found 'ITEM: {frame.kind}'",
        )
    roles = _resolve_columns(path, frame, columns, np.asarray(snapshot.ids))
    data, numbers = frame.data, frame.line_numbers
    names = (frame.columns[roles["i"]], frame.columns[roles["j"]])
    id_i, id_j = (integral_column(path, frame.data[:, roles[r]], numbers, n)
                  for r, n in zip("ij", names, strict=True))
    i, j = pair_indices(path, snapshot, (id_i, id_j), names, numbers, "atom", "paired with itself")

    d = snapshot.minimum_image(snapshot.positions[j] - snapshot.positions[i])
    dist_geom = np.hypot(d[:, 0], d[:, 1])
    z = snapshot.particle_fields.get("z") if snapshot.metadata.get("z_policy") == "project" else None
    dist_3d = dist_geom if z is None else np.hypot(dist_geom, z[j] - z[i])  # projected spheres
    dist = data[:, roles["dist"]] if "dist" in roles else dist_3d
    touching = dist < snapshot.radii[i] + snapshot.radii[j]
    refuse_first(path, dist_geom == 0.0, numbers,
                 lambda k: "the two atoms of this pair have the same position")
    n_hat = d / dist_geom[:, None]
    normal_force, shear_force = _pair_forces(data, roles, n_hat)

    keep = touching
    metadata = dict(snapshot.metadata)
    metadata["contacts"] = (
        f"read from {path} (timestep {frame.timestep}); {int((~keep).sum())} listed pairs "
        "not touching were dropped"
    )
    metadata["contact_columns"] = {role: frame.columns[k] for role, k in roles.items()}

    def sel(a: NDArray[np.float64] | None) -> NDArray[np.float64] | None:
        return None if a is None else a[keep]

    return dataclasses.replace(
        snapshot,
        contact_i=i[keep],
        contact_j=j[keep],
        normal_force=sel(normal_force),
        shear_force=sel(shear_force),
        contact_normal=None,
        contact_point=None,
        contact_fields={},
        metadata=metadata,
    )
