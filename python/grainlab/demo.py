"""An engine demonstration: isotropic compression of a random disk assembly to
a target stress inside four servo-controlled walls, with Table 1 properties.

This is what ``grainlab demo`` runs. It shows the engine end to end (random
placement, walls, servo control, local damping, diagnostics) on a small
sample in well under a minute.
"""

from __future__ import annotations

import csv
import io
import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from grainlab._progress import progress_bar
from grainlab.io.results import (
    ensure_output_folder,
    refuse_overwrite,
    write_json_atomic,
    write_text_atomic,
)
from grainlab.protocols.consolidate import BOX_WALLS, BoxState, servo_box
from grainlab.simulation import (
    TABLE1_DENSITY_KG_PER_M3,
    TABLE1_FRICTION,
    TABLE1_LOCAL_DAMPING,
    TABLE1_STIFFNESS_N_PER_M,
    WALL_GROUP,
    ContactModel,
    Simulation,
    Wall,
)

#: What the demo writes into its folder; a folder already holding one is refused.
DEMO_FILES = ("timeseries.csv", "summary.json", "state.bin")


@dataclass(frozen=True)
class CompressionResult:
    """What the demo reports."""

    n_particles: int
    steps: int
    converged: bool
    wall_stress_pa: tuple[float, float]
    porosity: float
    coordination_number: float
    unbalanced_force_ratio: float
    wall_time_s: float
    particle_steps_per_s: float


def random_disks(
    n_side: int, spacing_m: float, d_min_m: float, d_max_m: float, seed: int
) -> tuple[np.ndarray, np.ndarray]:
    """Disks on a jittered square grid of ``n_side x n_side`` cells, one per cell,
    diameters uniform in ``[d_min, d_max]`` scaled down to fit their cells (no overlap)."""
    if not 0 < d_min_m <= d_max_m:
        raise ValueError(f"diameters: need 0 < d_min <= d_max, got {d_min_m}, {d_max_m}")
    rng = np.random.default_rng(seed)
    n = n_side * n_side
    diameters = rng.uniform(d_min_m, d_max_m, n) * (0.9 * spacing_m / d_max_m)
    a, b = np.meshgrid(np.arange(n_side), np.arange(n_side), indexing="ij")
    centres = np.column_stack([a.ravel() + 0.5, b.ravel() + 0.5]) * spacing_m
    slack = (spacing_m - diameters)[:, None] / 2
    centres += rng.uniform(-1, 1, (n, 2)) * slack
    return centres, diameters / 2


def _boxed_disks(n_side: int, seed: int, threads: int | None) -> tuple[Simulation, dict[str, Wall]]:
    """``n_side**2`` random disks on a grid (Table 1's contacts, no platen
    friction) in a box of four segment walls, named as :data:`BOX_WALLS`."""
    spacing = 3.2e-3
    positions, radii = random_disks(n_side, spacing, 0.5e-3, 3.0e-3, seed)
    box = n_side * spacing
    sim = Simulation(
        positions,
        radii,
        TABLE1_DENSITY_KG_PER_M3,
        contact_model=ContactModel(TABLE1_STIFFNESS_N_PER_M, TABLE1_STIFFNESS_N_PER_M, TABLE1_FRICTION),
        local_damping=TABLE1_LOCAL_DAMPING,
        threads=threads,
    )
    # Table 1: particle-platen friction 0
    sim.set_contact_model(0, WALL_GROUP, ContactModel(friction=0.0))
    corners = [(0.0, 0.0), (box, 0.0), (box, box), (0.0, box)]
    walls = dict(zip(BOX_WALLS, (sim.add_segment_wall(corners[k], corners[(k + 1) % 4]) for k in range(4)),
                     strict=True))
    return sim, walls


def _write(out: Path, rows: list[dict[str, Any]], result: CompressionResult, sim: Simulation) -> None:
    """The demo's ``timeseries.csv``, ``summary.json`` and ``state.bin`` in ``out``."""
    table = io.StringIO()
    writer = csv.DictWriter(table, fieldnames=list(rows[0]), lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    write_text_atomic(out / "timeseries.csv", table.getvalue())
    write_json_atomic(out / "summary.json", asdict(result))
    sim.save(out / "state.bin")


def compress(
    out_dir: str | Path | None = None,
    *,
    n_side: int = 20,
    pressure_pa: float = 1.0e5,
    seed: int = 1,
    max_steps: int = 400_000,
    tolerance: float = 0.01,
    unbalanced_force_limit: float = 1.0e-3,
    threads: int | None = None,
    progress: bool = False,
) -> CompressionResult:
    """Compresses ``n_side**2`` disks (diameters 0.5-3 mm scaled to their grid
    cells) in a box of four servo walls to ``pressure_pa`` until both wall
    stresses are within ``tolerance`` of the target and the mean unbalanced
    force ratio is below ``unbalanced_force_limit``. Writes ``timeseries.csv``,
    ``summary.json`` and ``state.bin`` to ``out_dir`` if given; a folder that
    already holds one of them (another run's) is refused before any work."""
    if not pressure_pa > 0:
        raise ValueError(f"pressure_pa: must be > 0, got {pressure_pa}")
    if n_side < 3:
        raise ValueError(f"n_side: must be >= 3, got {n_side}")
    if out_dir is not None:
        ensure_output_folder(out_dir)
        refuse_overwrite(out_dir, DEMO_FILES, why="grainlab demo writes its own")
    sim, walls = _boxed_disks(n_side, seed, threads)
    rows = []
    start = time.perf_counter()
    bar = progress_bar(max_steps, "compressing", enabled=progress, unit="step")

    def record(state: BoxState, steps: int) -> None:
        rows.append(
            {
                "step": sim.step_count,
                "time_s": sim.time,
                "stress_xx_pa": state.stress_xx_pa,
                "stress_yy_pa": state.stress_yy_pa,
                "porosity": 1.0 - np.pi * np.sum(sim.radii**2) / (state.width_m * state.height_m),
                "coordination_number": sim.coordination_number,
                "unbalanced_force_ratio": sim.unbalanced_force_ratio,
                "kinetic_energy_j": sim.energy.kinetic,
            }
        )
        bar.update(2000)
        bar.set_postfix_str(f"sxx {state.stress_xx_pa / 1e3:.1f} kPa, syy {state.stress_yy_pa / 1e3:.1f} kPa, "
                            f"unbalanced {sim.unbalanced_force_ratio:.1e}")

    _, steps, converged = servo_box(
        sim, walls, pressure_pa, tolerance=tolerance, unbalanced_force_limit=unbalanced_force_limit,
        max_steps=max_steps, max_speed_m_per_s=0.05, chunk_steps=2000, after_chunk=record,
    )
    bar.close()
    wall_time = time.perf_counter() - start
    last = rows[-1]
    result = CompressionResult(
        n_particles=sim.n_particles,
        steps=steps,
        converged=converged,
        wall_stress_pa=(float(last["stress_xx_pa"]), float(last["stress_yy_pa"])),
        porosity=float(last["porosity"]),
        coordination_number=float(last["coordination_number"]),
        unbalanced_force_ratio=float(last["unbalanced_force_ratio"]),
        wall_time_s=wall_time,
        particle_steps_per_s=sim.n_particles * steps / wall_time,
    )
    if out_dir is not None:
        _write(Path(out_dir), rows, result, sim)
    return result
