"""What the viewer page shows of a run, gathered from its ``run.h5`` (docs/report.md,
"The viewer"); arrays quantised to float32, uint8 and uint16/32, base64 encoded.
"""

from __future__ import annotations

import base64
import math
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from grainlab.analysis import match_ids
from grainlab.cement import crack_orientations
from grainlab.columns import (
    AXIAL_STRAIN,
    AXIAL_STRESS_PA,
    FRICTION_COEFFICIENT,
    SHEAR_STRAIN,
    STRESS_RATIO,
    TENSILE_STRESS_PA,
    VERTICAL_STRESS_PA,
)
from grainlab.io.hdf5 import read_results
from grainlab.io.vtk import contact_lines
from grainlab.postprocess.products import RunProducts
from grainlab.postprocess.vtk import snapshot_arrays

__all__ = ["CURVE_COLUMNS", "encode", "viewer_data"]

#: Time series columns drawn as the stress–strain curve (x, y), the first pair the file has
#: (the biaxial test's stress ratio, the oedometer's vertical stress, simple shear's mu, the
#: Brazilian test's 2F / (pi D t) against delta / D).
CURVE_COLUMNS = ((AXIAL_STRAIN, STRESS_RATIO), (AXIAL_STRAIN, AXIAL_STRESS_PA), (AXIAL_STRAIN, VERTICAL_STRESS_PA),
                 (SHEAR_STRAIN, FRICTION_COEFFICIENT), (AXIAL_STRAIN, TENSILE_STRESS_PA))


def encode(values: NDArray[Any], dtype: str) -> str:
    """``values`` as base64 of little-endian ``dtype`` (``"f4"``, ``"u1"``, ``"u2"``, ``"u4"``)."""
    return base64.b64encode(np.ascontiguousarray(values, dtype="<" + dtype).tobytes()).decode("ascii")


def _band_outline(band: Any) -> dict[str, Any] | None:
    if band is None:
        return None
    return {
        "center": [float(v) for v in band.center],
        "angle_deg": float(band.angle_degrees),
        "thickness_m": float(band.thickness),
    }


def _snapshot(name: str, snap: Any, first: Any, walls: Any, index_dtype: str, products: RunProducts) -> dict[str, Any]:
    arrays = snapshot_arrays(snap, first)
    n = snap.n_particles
    rotation = np.zeros(n)
    if snap.rotations is not None and first.rotations is not None and snap is not first:
        to_first = match_ids(first, snap)
        ok = to_first >= 0
        rotation = np.full(n, np.nan)
        rotation[ok] = np.asarray(snap.rotations)[ok] - np.asarray(first.rotations)[to_first[ok]]
    lines, line_data, _ = contact_lines(snap)
    force = line_data.get("normal_force", np.full(len(lines), np.nan))
    outline: dict[str, Any] = {"first": None, "second": None}
    periodic = any(snap.periodic)
    if periodic:  # wrapped and sheared with the cell: displacements from the first snapshot mean nothing
        for key in ("displacement", "local_shear_strain"):
            arrays[key] = np.full_like(np.asarray(arrays[key], dtype=np.float64), np.nan)
        arrays["in_shear_band"] = np.zeros(n, dtype=np.uint8)
    elif name != products.reference:
        try:
            search = products.band_search(name)
            outline = {"first": _band_outline(search.band), "second": _band_outline(search.second)}
        except ValueError:  # too few grains with a local strain: no band
            pass
    disp = arrays["displacement"][:, :2]
    out = {
        "name": name,
        "axial_strain": snap.axial_strain if snap.axial_strain is not None else snap.scalars.get(SHEAR_STRAIN),
        "time_s": snap.time,
        "n": n,
        "n_grains": snap.n_grains,
        "n_contacts": int(len(lines)),
        "band": outline,
        "walls": None if walls is None else walls.segments(_bounds(snap)).tolist(),
        "arrays": {
            "x": encode(snap.positions[:, 0], "f4"),
            "y": encode(snap.positions[:, 1], "f4"),
            "r": encode(snap.radii, "f4"),
            "id": encode(snap.ids, "u4"),
            "kind": encode(snap.kind, "u1"),
            "lambda": encode(products.stability_index(name).stability_index, "f4"),
            "porosity": encode(products.local_porosity(name), "f4"),
            "chain": encode(products.force_chains(name) >= 0, "u1"),
            "contacts": encode(np.minimum(arrays["n_contacts"], 255), "u1"),
            "dx": encode(disp[:, 0], "f4"),
            "dy": encode(disp[:, 1], "f4"),
            "rotation": encode(rotation, "f4"),
            "strain": encode(arrays["local_shear_strain"], "f4"),
            "in_band": encode(arrays["in_shear_band"], "u1"),
            "grain": encode(snap.grains(), "u4"),
            "ci": encode(lines[:, 0], index_dtype),
            "cj": encode(lines[:, 1], index_dtype),
            "fn": encode(force, "f4"),
        },
    }
    return out


def _bounds(snap: Any) -> NDArray[np.float64]:
    r = np.asarray(snap.radii)[:, None]
    return np.array([(snap.positions - r).min(axis=0), (snap.positions + r).max(axis=0)])


def _finite(value: Any) -> float | None:
    return None if value is None or not math.isfinite(float(value)) else float(value)


def _cracks(results: Any, snaps: list[Any]) -> tuple[dict[str, Any] | None, list[int]]:
    """The run's crack records as the page draws them (None without any), and how many
    had broken by each snapshot."""
    cracks = results.cracks
    if not cracks:
        return None, [0] * len(snaps)
    angle = crack_orientations(cracks["normal_x"], cracks["normal_y"])
    grains = np.asarray(snaps[-1].radii)[np.asarray(snaps[-1].is_sample)]
    data = {"n": int(len(angle)), "x": encode(cracks["x_m"], "f4"), "y": encode(cracks["y_m"], "f4"),
            "angle": encode(angle, "f4"), "tension": encode(cracks["tension"], "u1"),
            "half_length_m": 0.5 * float(np.median(grains))}
    by = [len(angle) if snap.time is None else int(np.searchsorted(cracks["time_s"], snap.time, side="right"))
          for snap in snaps]
    return data, by


def _strain_label(curve: dict[str, Any] | None) -> str:
    """What the curve's x and the snapshots' strain are: a shear strain, the Brazilian test's
    platen displacement over the disc's diameter, or an axial strain."""
    if curve is not None and curve["x"] == SHEAR_STRAIN:
        return "shear strain"
    return "platen displacement / D" if curve is not None and curve["y"] == TENSILE_STRESS_PA else "axial strain"


def viewer_data(run: str | Path) -> dict[str, Any]:
    """Everything the page shows of ``run`` (a run folder or its ``run.h5``), JSON-ready.

    Raises ValueError when the run has no snapshots.
    """
    path = Path(run)
    h5 = path / "run.h5" if path.is_dir() else path
    results = read_results(h5)
    names = list(results.snapshot_names)
    if not names:
        raise ValueError(f"{h5}: the run has no snapshots to view")
    products = RunProducts(results)
    snaps = [results.snapshot(name) for name in names]
    largest = max(s.n_particles for s in snaps)
    index_dtype = "u2" if largest < 2**16 else "u4"
    curve = None
    for x, y in CURVE_COLUMNS:
        if x in results.timeseries and y in results.timeseries:
            xs, ys = results.timeseries[x], results.timeseries[y]
            ok = np.isfinite(xs) & np.isfinite(ys)
            curve = {"x": x, "y": y, "xs": encode(xs[ok], "f4"), "ys": encode(ys[ok], "f4"), "n": int(ok.sum())}
            break
    bounds = np.array([_bounds(s) for s in snaps])
    cracks, cracks_by = _cracks(results, snaps)
    return {
        "cracks": cracks,
        "clumps": any(s.n_grains < s.n_particles for s in snaps),
        "title": f"{results.kind} run {h5.parent.name}",
        "source": str(h5),
        "index_dtype": index_dtype,
        "bounds": [bounds[:, 0].min(axis=0).tolist(), bounds[:, 1].max(axis=0).tolist()],
        "peak_stress_ratio": _finite(results.summary.get("peak_stress_ratio")),
        "strain_label": _strain_label(curve),
        "curve": curve,
        "snapshots": [
            {**_snapshot(name, snap, snaps[0], results.walls(name), index_dtype, products), "n_cracks": by}
            for name, snap, by in zip(names, snaps, cracks_by, strict=True)
        ],
    }
