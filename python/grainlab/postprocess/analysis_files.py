"""The files of ``grainlab analyze``: ``particles.csv``, ``fabric.json`` and the figures.

:func:`write_analysis` writes what :func:`grainlab.analysis.analyze_snapshot`
computed, through io's writers (the JSON atomically, NaN as ``null``), and
draws the figures with each measure's ``plot()``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from grainlab import plot
from grainlab.analysis.analyze import AnalysisResult
from grainlab.io.csv import write_particles_csv
from grainlab.io.results import write_json_atomic

__all__ = ["write_analysis"]


def write_analysis(result: AnalysisResult, out_dir: str | Path, *, figures: bool = True) -> list[Path]:
    """Write ``particles.csv``, ``fabric.json``, for clumps ``bodies.csv``, and (with
    ``figures``) the PNG + SVG figures of ``result`` into ``out_dir`` (made if needed);
    returns the paths written."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    written = [write_particles_csv(out / "particles.csv", result.snapshot, result.particle_table())]
    written.append(write_json_atomic(out / "fabric.json", result.summary()))
    bodies = result.bodies
    if bodies is not None:
        written.append(write_particles_csv(out / "bodies.csv", bodies.view.snapshot, bodies.table()))
    if not figures:
        return written
    snap = result.snapshot
    band = result.found_band
    written += plot.save_figure(result.anisotropy.plot(), out / "contact_normals")
    if result.force_anisotropy is not None:
        written += plot.save_figure(result.force_anisotropy.plot(), out / "normal_forces")
    written += plot.save_figure(result.stability.plot(band=band), out / "map_stability_index")
    if bodies is not None:
        written += plot.save_figure(bodies.stability.plot(), out / "map_stability_index_bodies")
    ax = plot.particle_map(
        snap.positions,
        snap.radii,
        np.where(snap.is_sample, result.stability.n_contacts, np.nan),
        discrete=True,
        cmap="viridis",
        label="number of contacts",
        band=band,
    )
    written += plot.save_figure(ax, out / "map_contacts")
    if result.porosity is not None:
        written += plot.save_figure(result.porosity.plot(), out / "map_local_porosity")
    if result.loops is not None:
        written += plot.save_figure(result.loops.plot(), out / "map_loop_size")
    if result.networks is not None:
        written += plot.save_figure(result.networks.plot(), out / "force_network")
    if result.chains is not None:
        written += plot.save_figure(result.chains.plot(), out / "force_chains")
    if result.stress_force_fabric is not None:
        written += plot.save_figure(result.stress_force_fabric.plot(), out / "stress_force_fabric")
    if result.strain is not None:
        written += plot.save_figure(result.strain.plot(band=band), out / "map_displacement")
        written += plot.save_figure(
            result.strain.plot(quantity="shear_strain", band=band), out / "map_shear_strain"
        )
    return written
