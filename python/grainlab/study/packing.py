"""One packing of the paper's Sec. 7 study, made and measured (Tables 2 and 3).

The two kinds, the generation friction search and what is measured: docs/study.md.
:func:`run_packing` returns :data:`MEASURES`, ``status`` and ``note``, and stores the
packing (:data:`PACKING_FILE`) for :func:`read_packing`.
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Mapping
from dataclasses import asdict, dataclass, fields
from pathlib import Path
from typing import Any, TypedDict

import numpy as np

from grainlab.analysis import fabric_summary
from grainlab.snapshot import Snapshot

#: The results file a packing's folder holds: its measured snapshot and its measures.
PACKING_FILE = "run.h5"
#: The name of that snapshot.
PACKING_SNAPSHOT = "packing"

#: The measured columns of one packing, in table order.
MEASURES: tuple[str, ...] = (
    "porosity",
    "porosity_overlap_corrected",
    "coordination_number",
    "mechanical_coordination_number",
    "mean_stability_index",
    "mean_stability_index_all",
    "anisotropy",
    "anisotropy_binned",
    "anisotropy_fourier",
    "force_anisotropy",
    "force_anisotropy_binned",
    "n_particles",
    "mean_wall_stress_pa",
    "generation_friction",
    "generation_expansions",
)

#: ``PackingParams.generation_friction`` value that asks for the friction search.
GENERATION_FRICTION_SEARCH = "search"


@dataclass(frozen=True)
class PackingParams:
    """Parameters of one packing run (SI units; defaults: the paper's Tables 2-3)."""

    kind: str = "irregular"
    """``"irregular"`` (radius expansion) or ``"hexagonal"`` (lattice)."""
    porosity: float = 0.12
    """Target nominal porosity, in (0, 1)."""
    width: float = 0.075
    height: float = 0.150
    d_min: float = 0.5e-3
    """Smallest diameter of the irregular packings (Table 2: 0.5 mm)."""
    d_max: float = 3.0e-3
    diameter: float = 1.75e-3
    """Diameter of the hexagonal packings' disks (Table 3's 0.875 mm read as a radius)."""
    generation_friction: float | str = GENERATION_FRICTION_SEARCH
    """Particle friction during the radius expansion: a number (fixed), or ``"search"``
    (chosen per packing in ``[0, friction]``; docs/study.md)."""
    friction: float = 0.9
    """Table 2's mu: the upper end of the generation friction search (the packing is
    measured as generated; docs/study.md)."""
    platen_friction: float = 0.0
    normal_stiffness: float = 8.45e7
    shear_stiffness: float = 8.45e7
    density: float = 2.0e8
    local_damping: float = 0.8
    max_stress: float = 5.0e6
    """Stress bound of the radius expansion, Pa (the samples library default)."""
    search_stress_min: float = 1.0e5
    """Friction search: least mean wall stress of a stress-bearing packing, Pa (the
    paper's consolidation stress, 100 kPa)."""
    search_stress_max: float = 3.0e5
    """Friction search: upper end of the stress band aimed at, Pa (about what the
    frictionless expansion locks in at 0.15, the loosest target it jams at)."""
    lattice_boundary: str = "periodic"
    """Hexagonal packings: ``"periodic"`` or ``"walls"``."""
    threads: int = 1
    seed: int = 0

    def validate(self) -> PackingParams:
        """Checks every field; raises ``ValueError`` naming it."""
        if self.kind not in ("irregular", "hexagonal"):
            raise ValueError(f"kind: expected 'irregular' or 'hexagonal', got {self.kind!r}")
        if self.lattice_boundary not in ("periodic", "walls"):
            raise ValueError(f"lattice_boundary: expected 'periodic' or 'walls', got {self.lattice_boundary!r}")
        for name in ("porosity",):
            value = getattr(self, name)
            if not (0.0 < value < 1.0):
                raise ValueError(f"{name}: expected a number in (0, 1), got {value!r}")
        for name in ("width", "height", "d_min", "d_max", "diameter", "normal_stiffness", "shear_stiffness",
                     "density", "max_stress", "search_stress_min", "search_stress_max"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"{name}: expected a number > 0, got {value!r}")
        for name in ("friction", "platen_friction"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0):
                raise ValueError(f"{name}: expected a number >= 0, got {value!r}")
        if not self.searches_friction:
            value = self.generation_friction
            if isinstance(value, str | bool) or not (math.isfinite(value) and value >= 0):
                raise ValueError(
                    f"generation_friction: expected a number >= 0 or {GENERATION_FRICTION_SEARCH!r}, got {value!r}"
                )
        elif self.kind == "irregular":  # a lattice is built, not generated: no search to check
            if self.friction <= 0:
                raise ValueError(
                    "friction: the generation friction search runs over [0, friction] and needs friction > 0, "
                    f"got {self.friction!r}; give a fixed generation_friction instead"
                )
            if self.search_stress_min >= self.search_stress_max:
                raise ValueError(
                    f"search_stress_min: {self.search_stress_min:g} Pa must be below search_stress_max "
                    f"{self.search_stress_max:g} Pa"
                )
            if self.search_stress_max > self.max_stress:
                raise ValueError(
                    f"search_stress_max: {self.search_stress_max:g} Pa exceeds the expansion's stress bound "
                    f"max_stress {self.max_stress:g} Pa, so the band could not be reached"
                )
        if not (0.0 <= self.local_damping < 1.0):
            raise ValueError(f"local_damping: expected a number in [0, 1), got {self.local_damping!r}")
        if self.d_min > self.d_max:
            raise ValueError(f"d_min: {self.d_min:g} m exceeds d_max {self.d_max:g} m")
        if int(self.threads) != self.threads or self.threads < 1:
            raise ValueError(f"threads: expected an integer >= 1, got {self.threads!r}")
        if int(self.seed) != self.seed or self.seed < 0:
            raise ValueError(f"seed: expected an integer >= 0, got {self.seed!r}")
        return self

    @property
    def searches_friction(self) -> bool:
        """Whether the generation friction is searched (``generation_friction = "search"``)."""
        return self.generation_friction == GENERATION_FRICTION_SEARCH

    @classmethod
    def from_mapping(cls, values: Mapping[str, Any]) -> PackingParams:
        """From a plain mapping; an unknown key raises ``ValueError`` naming it."""
        known = {f.name: f for f in fields(cls)}
        kwargs: dict[str, Any] = {}
        for key, value in values.items():
            if key not in known:
                raise ValueError(f"unknown packing parameter {key!r}; known: {', '.join(known)}")
            default = getattr(cls, key)
            if key == "generation_friction":
                if isinstance(value, bool) or not isinstance(value, int | float | str):
                    raise ValueError(
                        f"{key}: expected a number >= 0 or {GENERATION_FRICTION_SEARCH!r}, got {value!r}")
                value = value if isinstance(value, str) else float(value)
            elif isinstance(default, str):
                if not isinstance(value, str):
                    raise ValueError(f"{key}: expected a string, got {value!r}")
            elif isinstance(default, int) and not isinstance(default, bool):
                if isinstance(value, bool) or not isinstance(value, int | float) or int(value) != value:
                    raise ValueError(f"{key}: expected an integer, got {value!r}")
                value = int(value)
            else:
                if isinstance(value, bool) or not isinstance(value, int | float):
                    raise ValueError(f"{key}: expected a number, got {value!r}")
                value = float(value)
            kwargs[key] = value
        return cls(**kwargs).validate()

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def measure(snapshot: Snapshot) -> dict[str, float]:
    """Z, Z_m, mean lambda (both readings), anisotropies (the exact estimate and Eq. 7 on
    the histogram) of a snapshot (library defaults: boundary contacts excluded from Z and
    the anisotropies, included in lambda)."""
    summary = fabric_summary(snapshot)
    keys = ("coordination_number", "mechanical_coordination_number", "mean_stability_index",
            "mean_stability_index_all", "anisotropy", "anisotropy_binned", "anisotropy_fourier",
            "force_anisotropy", "force_anisotropy_binned")
    return {k: summary[k] for k in keys}


class _ExpansionOptions(TypedDict, total=False):
    """The keywords of a packing's radius expansion (``expand_to_porosity``)."""

    seed: int
    wall_friction: float
    normal_stiffness: float
    shear_stiffness: float
    density: float
    local_damping: float
    max_stress_pa: float
    threads: int
    progress: bool
    keep_simulation: bool
    density_scaling: bool


def _expanded(p: PackingParams) -> tuple[Any, Any, str, list[str], int]:
    """The irregular packing by radius expansion (with the friction search if asked):
    ``(sample, search or None, status, notes, expansions run)``; once more with the
    real masses after a stop at the engine's overlap limit, and the densest packing
    the stress bound allows when the target is beyond it."""
    from grainlab.samples import (
        ExpansionError,
        UniformByNumber,
        expand_to_porosity,
        expand_with_friction_search,
    )

    box = (0.0, 0.0, p.width, p.height)
    grading = UniformByNumber(p.d_min, p.d_max)
    common = _ExpansionOptions(
        seed=p.seed,
        wall_friction=p.platen_friction,
        normal_stiffness=p.normal_stiffness,
        shear_stiffness=p.shear_stiffness,
        density=p.density,
        local_damping=p.local_damping,
        max_stress_pa=p.max_stress,
        threads=p.threads,
        progress=False,
        keep_simulation=True,
    )
    # the least friction the search may use: a target too dense for it is too dense for any
    friction = 0.0 if p.searches_friction else float(p.generation_friction)

    def generate(porosity: float, density_scaling: bool, search: bool) -> tuple[Any, Any]:
        """(sample, friction search or None) at ``porosity``."""
        options: _ExpansionOptions = {**common, "density_scaling": density_scaling}
        if search:
            found = expand_with_friction_search(
                box, porosity, grading, friction_range=(0.0, p.friction),
                stress_band_pa=(p.search_stress_min, p.search_stress_max), **options,
            )
            return found.sample, found
        return expand_to_porosity(box, porosity, grading, friction=friction, **options), None

    status, notes, expansions = "ok", [], 0
    density_scaling = True
    try:
        try:
            expansions += 1
            sample, search = generate(p.porosity, density_scaling, p.searches_friction)
        except ExpansionError as error:
            if not (error.engine_stopped and error.stress_pa < p.max_stress):
                raise
            # not the stress bound but one pair overlapping beyond the engine's limit while the
            # packing rearranges under MPa: the overshoot of a contact grows with the disk's mass,
            # and density scaling gives the smallest disks the largest one's mass; once more with
            # the real masses
            density_scaling = False
            notes.append(f"the first expansion stopped at the engine's overlap limit at "
                         f"{error.stress_pa / 1e6:.3g} MPa, below the stress bound; expanded again "
                         "with the real masses (density scaling off)")
            expansions += 1
            sample, search = generate(p.porosity, density_scaling, p.searches_friction)
    except ExpansionError as error:
        # the densest packing the bound allows: aim just above where this expansion stopped
        fallback = math.ceil(error.porosity * 1000.0) / 1000.0 + 0.001
        expansions += 1
        sample, search = generate(fallback, density_scaling, False)
        status = "densest_reached"
        notes.append(
            f"target {p.porosity:.4f} not reached within the stress bound {p.max_stress / 1e6:.3g} MPa "
            f"({error}); measured instead the packing expanded to {fallback:.4f} with generation friction "
            f"{friction:g}, just above the densest one reached ({error.porosity:.4f})"
        )
    return sample, search, status, notes, expansions


def _irregular(p: PackingParams) -> tuple[dict[str, Any], Snapshot]:
    sample, search, status, notes, expansions = _expanded(p)
    if search is not None:
        expansions += len(search.trials) - 1
    sim = sample.simulation
    snap = sim.snapshot()
    result = measure(snap)
    if not sample.jammed:
        status = "unjammed" if status == "ok" else status
        notes.append(
            f"stress-free at nominal porosity {sample.porosity:.4f}: the radius expansion with generation "
            f"friction {sample.friction:g} jams denser than this in this box, so the disks do not fill it under "
            f"load (mean wall stress {sample.mean_wall_stress_pa:.3g} Pa); contacts are the near-touching ones "
            "left at rest"
        )
    elif status == "ok":
        how = f"generation friction {sample.friction:g} (fixed)" if search is None else search.summary()
        notes.append(
            f"equilibrium after radius expansion, locked-in mean wall stress "
            f"{sample.mean_wall_stress_pa / 1e3:.0f} kPa, {sample.steps} DEM steps; {how}"
        )
    result.update(
        porosity=sample.porosity,
        porosity_overlap_corrected=sample.porosity_overlap_corrected,
        n_particles=float(len(sample.radii)),
        mean_wall_stress_pa=sample.mean_wall_stress_pa,
        generation_friction=sample.friction,
        generation_expansions=expansions,
    )
    return {**result, "status": status, "note": "; ".join(notes),
            "friction_search": search.trials_json() if search is not None else ""}, snap


def _hexagonal(p: PackingParams) -> tuple[dict[str, Any], Snapshot]:
    from grainlab.samples import hexagonal_lattice

    lattice = hexagonal_lattice(
        p.diameter, p.porosity, box=(0.0, 0.0, p.width, p.height), boundary=p.lattice_boundary, rng=p.seed
    )
    x0, y0, x1, y1 = lattice.box
    periodic = lattice.boundary == "periodic"
    tol = 1e-9 * p.diameter
    snap = Snapshot.from_geometry(
        lattice.positions,
        lattice.radii,
        tolerance=tol,
        box=[[x0, x1], [y0, y1]],
        periodic=(periodic, periodic),
    )
    i, j = np.asarray(snap.contact_i), np.asarray(snap.contact_j)
    d = snap.minimum_image(lattice.positions[j] - lattice.positions[i])
    dist = np.hypot(d[:, 0], d[:, 1])
    overlap = np.maximum(lattice.radii[i] + lattice.radii[j] - dist, 0.0)
    normal = d / dist[:, None]
    if not periodic:
        # walls as contacts: a disk touching a box side (within tol)
        walls_i, walls_id, walls_n, walls_ov = [], [], [], []
        pos, r = lattice.positions, lattice.radii
        for wid, (axis, side, sign) in enumerate(((1, y0, -1), (0, x1, 1), (1, y1, 1), (0, x0, -1))):
            gap = sign * (side - pos[:, axis]) - r
            hit = np.flatnonzero(gap < tol)
            n = np.zeros((hit.size, 2))
            n[:, axis] = sign
            walls_i.append(hit)
            walls_id.append(np.full(hit.size, -1 - wid))
            walls_n.append(n)
            walls_ov.append(np.maximum(-gap[hit], 0.0))
        i = np.concatenate([i, *walls_i])
        j = np.concatenate([j, *walls_id])
        normal = np.concatenate([normal, *walls_n])
        overlap = np.concatenate([overlap, *walls_ov])
    overlap = np.where(overlap > tol, overlap, 0.0)  # touching lattice neighbours: round-off, no load
    snap = snap.with_contacts(i, j, contact_normal=normal, normal_force=p.normal_stiffness * overlap)
    result = measure(snap)
    result.update(
        porosity=lattice.porosity,
        porosity_overlap_corrected=lattice.porosity_overlap_corrected,
        n_particles=float(lattice.n_particles),
        mean_wall_stress_pa=float("nan"),
        generation_friction=float("nan"),  # built, not generated: no friction involved
        generation_expansions=0,
    )
    note = lattice.note
    if not overlap.any():
        note += "; the lattice at contact carries no load, so the force anisotropy is undefined (NaN)"
    return {**result, "status": "ok", "note": note, "friction_search": ""}, snap


def run_packing(params: PackingParams | Mapping[str, Any],
                out_dir: str | os.PathLike[str] | None = None) -> dict[str, Any]:
    """Makes and measures one packing; returns :data:`MEASURES` + ``status``, ``note``,
    ``friction_search`` (the search's trials as JSON, or ``""``), ``seed``, ``wall_time_s``.
    With ``out_dir``, the measured snapshot and the parameters are stored in
    ``out_dir/run.h5`` (:data:`PACKING_FILE`, replacing one an earlier attempt left)."""
    p = params if isinstance(params, PackingParams) else PackingParams.from_mapping(params)
    p.validate()
    started = time.perf_counter()
    result, snap = _irregular(p) if p.kind == "irregular" else _hexagonal(p)
    result["seed"] = p.seed
    result["wall_time_s"] = time.perf_counter() - started
    if out_dir is not None:
        _store(Path(out_dir), p, result, snap)
    return result


def _store(folder: Path, p: PackingParams, result: Mapping[str, Any], snap: Snapshot) -> Path:
    from grainlab.io.hdf5 import ResultsWriter

    folder.mkdir(parents=True, exist_ok=True)
    with ResultsWriter(folder / PACKING_FILE, kind="packing", overwrite=True, buffered=True) as writer:
        writer.write_config(asdict(p))  # finalized on leaving the block, closed on an error
        writer.write_snapshot(PACKING_SNAPSHOT, snap)
        writer.write_summary(result)
    return folder / PACKING_FILE


def read_packing(folder: str | os.PathLike[str]) -> Snapshot:
    """The packing :func:`run_packing` stored in ``folder``; ``ValueError`` naming the
    folder when it holds none (a packing measured before grainlab stored them)."""
    from grainlab.io.hdf5 import read_results

    path = Path(folder) / PACKING_FILE
    if not path.exists():
        raise ValueError(f"{folder}: no stored packing ({PACKING_FILE} not found): the packing was measured "
                         "without being stored; run it again to measure it another way")
    results = read_results(path)
    if results.kind != "packing":
        raise ValueError(f"{path}: a results file of kind {results.kind!r}, not a packing")
    return results.snapshot(PACKING_SNAPSHOT)
