"""What a reproduction measures on one stored run, with the current analysis.

:func:`measure_biaxial` recomputes a biaxial run's curves, fabric and band-resolved
fabric from its records and snapshots; :func:`measure_study` reads one seed's
packing study (docs/reproduction.md).
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from grainlab.analysis.peak import nearest_snapshot, peak_is_interior, peak_record
from grainlab.columns import AXIAL_STRAIN, STRESS_RATIO, VOLUMETRIC_STRAIN
from grainlab.io.hdf5 import snapshot_strain

if TYPE_CHECKING:
    from grainlab.analysis.per_body import BodyView
    from grainlab.postprocess.products import RunProducts

#: Analysis options a variant may set, with their defaults: how lambda counts the boundary
#: ("body" or "raw") and reads Eqs. 9-11 (StabilityIndex's slots, anchor and deviation), and
#: which reading of the shear band gives the band's grains (:data:`BAND_READINGS`).
ANALYSIS_DEFAULTS: dict[str, Any] = {"boundary_contacts": "body", "lambda_slots": "angular",
                                     "lambda_anchor": "min", "lambda_deviation": "sum", "band": "strain"}
#: The readings of the band: the detector in the local strain (the default); the zone that
#: separates the two moving blocks in the displacement map (Fig. 11: the best two-block split's
#: transition zone at each snapshot, accepted or not, as the paper reads it without a test;
#: ``band_found`` counts accepted ones); the zone of lambda > 0.5 (Fig. 12), found and accepted at
#: each snapshot as the strain band is (grainlab.postprocess.band); and the band accepted last in
#: the local strain (at 10 %) carried back to every snapshot by id.
BAND_READINGS: tuple[str, ...] = ("strain", "displacement", "lambda", "final")

#: Share of the test's final strain that the end window ("a constant at the end") covers.
END_WINDOW = 0.3
#: The linear range of the stress ratio (paper Sec. 6: linear until 0.5 %).
LINEAR_TO = 0.005


def _reading(options: Mapping[str, Any]) -> dict[str, Any]:
    """Lambda's reading of ``options``: how it counts the boundary and reads Eqs. 9-11."""
    return {"boundary": {"body": "body", "raw": "each"}[options.get("boundary_contacts", "body")],
            "slots": options.get("lambda_slots", "angular"), "anchor": options.get("lambda_anchor", "min"),
            "deviation": options.get("lambda_deviation", "sum")}


def _finite(x: Any) -> float:
    try:
        value = float(x)
    except (TypeError, ValueError):
        return math.nan
    return value if math.isfinite(value) else math.nan


def relative_slope(x: NDArray[np.float64], y: NDArray[np.float64]) -> float:
    """Least-squares slope of ``y`` on ``x`` times 0.01 over the mean of ``y``: the
    relative change per 1 % axial strain (NaN with fewer than 2 finite points)."""
    ok = np.isfinite(x) & np.isfinite(y)
    if ok.sum() < 2 or np.ptp(x[ok]) == 0:
        return math.nan
    slope = np.polyfit(x[ok], y[ok], 1)[0]
    mean = float(np.mean(y[ok]))
    return float(slope * 0.01 / mean) if mean != 0 else math.nan


def correlation(x: NDArray[np.float64], y: NDArray[np.float64]) -> float:
    """Pearson's r of the finite pairs (NaN with fewer than 3, or a constant side)."""
    ok = np.isfinite(x) & np.isfinite(y)
    if ok.sum() < 3 or np.ptp(x[ok]) == 0 or np.ptp(y[ok]) == 0:
        return math.nan
    return float(np.corrcoef(x[ok], y[ok])[0, 1])


def macro_measures(ts: Mapping[str, NDArray[np.float64]]) -> dict[str, Any]:
    """The macro numbers of a biaxial time series (compression positive)."""
    eps = np.asarray(ts[AXIAL_STRAIN], dtype=np.float64)
    q = np.asarray(ts[STRESS_RATIO], dtype=np.float64)
    ev = np.asarray(ts[VOLUMETRIC_STRAIN], dtype=np.float64)
    ok = np.isfinite(eps) & np.isfinite(q)
    rows = np.flatnonzero(ok)
    k = peak_record(eps, q)
    final = float(eps[rows[-1]])
    window = ok & (eps >= max(float(eps[k]), (1.0 - END_WINDOW) * final))
    linear = ok & (eps <= LINEAR_TO + 1e-9)
    contraction_row = int(np.nanargmax(ev))
    return {
        "final_strain": final,
        "peak_row": k,
        "peak_axial_strain": float(eps[k]),
        "peak_stress_ratio": float(q[k]),
        "peak_in_interior": peak_is_interior(eps, q),
        "linear_r2": correlation(eps[linear], q[linear]) ** 2,
        "residual_stress_ratio": float(np.mean(q[window])) if window.any() else math.nan,
        "residual_relative_slope": relative_slope(eps[window], q[window]),
        "end_window_from": float(eps[window][0]) if window.any() else math.nan,
        "max_contraction": float(ev[contraction_row]),
        "axial_strain_at_max_contraction": float(eps[contraction_row]),
        "final_volumetric_strain": float(ev[rows[-1]]),
        "records": {AXIAL_STRAIN: eps[rows].tolist(), STRESS_RATIO: q[rows].tolist(),
                    VOLUMETRIC_STRAIN: ev[rows].tolist()},
    }


def _fabric_of(view: BodyView, options: Mapping[str, Any]) -> dict[str, Any]:
    """The fabric of a snapshot's :func:`~grainlab.analysis.body_view`: per body for clumps
    (its contact number counts every contact, CEGEO's Z_c), per disk otherwise."""
    from grainlab.analysis.fabric import ContactAnisotropy, CoordinationNumber
    from grainlab.analysis.per_body import BodyStabilityIndex

    snap = view.snapshot
    # per body, each contact's direction from the body's centroid (a disk's own: StabilityIndex's bits)
    stability = BodyStabilityIndex(**_reading(options)).compute(view)
    normals = ContactAnisotropy().compute(snap)
    forces = ContactAnisotropy(weight="normal_force").compute(snap) if snap.normal_force is not None else None
    z = CoordinationNumber().compute(snap)
    return {
        "stability": stability,
        "grain_contacts": z.n_contacts,
        "numbers": {
            "a": _finite(normals.anisotropy),
            "a_binned": _finite(getattr(normals, "anisotropy_binned", math.nan)),
            "a_n": _finite(forces.anisotropy) if forces is not None else math.nan,
            "coordination_number": _finite(z.coordination_number),
            "mechanical_coordination_number": _finite(z.mechanical_coordination_number),
            "mean_lambda": _finite(stability.mean),
            "mean_lambda_all": _finite(stability.mean_all),
        },
    }


def measure_biaxial(run_dir: str | Path, options: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """Every number the claims use, of one finished biaxial run (docs/reproduction.md).

    ``options``: analysis options (:data:`ANALYSIS_DEFAULTS`). Returns a
    JSON-ready dict: ``macro``, ``snapshots`` (one dict per snapshot, in strain
    order), ``peak_snapshot`` (index of the snapshot nearest the stress-ratio
    peak, other than the first), ``notes``.
    """
    return measure_biaxial_each(run_dir, [options or {}])[0]


def measure_biaxial_each(run_dir: str | Path, options: Sequence[Mapping[str, Any]]) -> list[dict[str, Any]]:
    """:func:`measure_biaxial` under each of several analysis options, reading the
    run and finding its bands (which do not depend on the options) once."""
    from grainlab.postprocess.products import RunProducts

    products = RunProducts(run_dir, per_body=True)
    results = products.results
    ts = results.timeseries
    macro = macro_measures(ts)
    infos = list(results.snapshots)
    strains = [snapshot_strain(info) for info in infos]
    position = {info.name: k for k, info in enumerate(infos)}
    order = [position[name] for name in products.names_by_strain]
    names = products.names_by_strain
    views = [products.view(name) for name in names]
    snaps = [products.snapshot(name) for name in names]
    peak_pos = nearest_snapshot([strains[k] for k in order], macro["peak_axial_strain"])
    readings: dict[str, tuple[list[NDArray[np.int32] | None], list[tuple[NDArray[np.bool_], int] | None]]] = {}

    def bands(reading: str) -> tuple[list[NDArray[np.int32] | None], list[tuple[NDArray[np.bool_], int] | None]]:
        """Each snapshot's band labels and band grains under ``reading`` (each found once)."""
        if reading not in readings:
            if reading not in BAND_READINGS:
                raise ValueError(f"band: expected one of {', '.join(BAND_READINGS)}, got {reading!r}")
            if reading == "displacement":
                labels, candidates = _displacement_readings(products, snaps)
                readings[reading] = (labels, _band_members(snaps, candidates))
                return readings[reading]
            found = "strain" if reading == "final" else reading
            labels = readings[found][0] if found in readings else (
                [None] + [products.band_labels(name, reading=found) for name in names[1:]])
            members = _final_band_members(snaps, labels) if reading == "final" else _band_members(snaps, labels)
            readings[reading] = (labels, members)
        return readings[reading]

    eps_ts = np.asarray(ts[AXIAL_STRAIN], dtype=np.float64)
    q_ts = np.asarray(ts[STRESS_RATIO], dtype=np.float64)
    finite = np.isfinite(q_ts) & np.isfinite(eps_ts)
    common = {
        "run": str(Path(results.path)),
        "macro": macro,
        "peak_snapshot": peak_pos,
        "wall_time_s": _finite(results.summary.get("wall_time_s")) if results.summary else math.nan,
        "strain_rate": _finite(results.summary.get("strain_rate")) if results.summary else math.nan,
        "notes": [] if macro["peak_in_interior"] else
        ["the stress ratio is largest at the first or last record: no interior peak"],
    }
    out = []
    for given in options:
        opts = {**ANALYSIS_DEFAULTS, **dict(given)}
        labels, members = bands(str(opts["band"]))
        peak_ids: NDArray[np.int64] = np.zeros(0, np.int64)
        peak_members = members[peak_pos]
        if peak_members is not None:
            peak_ids = np.asarray(snaps[peak_pos].ids)[peak_members[0]]
        strain_members = bands("strain")[1] if opts["band"] != "strain" else None
        rows = []
        for i, (k, view, band, member) in enumerate(zip(order, views, labels, members, strict=True)):
            row = {"name": infos[k].name, AXIAL_STRAIN: strains[k],
                   STRESS_RATIO: float(np.interp(strains[k], eps_ts[finite], q_ts[finite]))}
            row.update(_snapshot_row(snaps[0], view, band, member, peak_ids, opts))
            if member is not None:
                row["band_from_strain"] = strains[order[member[1]]]
            row["band_overlap_with_strain"] = (
                math.nan if strain_members is None else _overlap(member, strain_members[i]))
            rows.append(row)
        out.append({**common, "analysis": opts, "snapshots": rows})
    return out


def _overlap(a: tuple[NDArray[np.bool_], int] | None, b: tuple[NDArray[np.bool_], int] | None) -> float:
    """The Jaccard overlap |A & B| / |A | B| of two band grain sets of one snapshot
    (:func:`_band_members`); NaN when either reading has no band there."""
    if a is None or b is None:
        return math.nan
    union = int(np.count_nonzero(a[0] | b[0]))
    return int(np.count_nonzero(a[0] & b[0])) / union if union else math.nan


def _band_members(snaps: Sequence[Any], labels: Sequence[NDArray[np.int32] | None]
                  ) -> list[tuple[NDArray[np.bool_], int] | None]:
    """Per snapshot, the grains of the shear band and the snapshot whose band they
    are: the band accepted at this snapshot; else the first band accepted after
    it, its grains matched by id (the grains that form the band, before the
    detector can tell it from the rest); None when no band is accepted at or
    after the snapshot."""
    out: list[tuple[NDArray[np.bool_], int] | None] = [None] * len(snaps)
    later: tuple[NDArray[np.int64], int] | None = None
    for k in range(len(snaps) - 1, -1, -1):
        band = labels[k]
        if band is not None and np.any(np.asarray(band) > 0):
            later = (np.asarray(snaps[k].ids)[np.asarray(band) > 0], k)
        if later is not None:
            out[k] = (np.isin(np.asarray(snaps[k].ids), later[0]) & np.asarray(snaps[k].is_sample), later[1])
    return out


def _displacement_readings(products: RunProducts, snaps: Sequence[Any]
                           ) -> tuple[list[NDArray[np.int32] | None], list[NDArray[np.int32] | None]]:
    """The displacement map's band at each snapshot (in ``products``' strain order) since
    the first: labels of the band accepted (1; zeros when the two-block fit fails the
    acceptance test), and labels of the best two-block split's transition zone, accepted
    or not: the paper reads its band off the displacement map (Fig. 11) with no test, so
    the band's grains are the candidate's, while ``band_found`` counts accepted bands only."""
    accepted: list[NDArray[np.int32] | None] = [None]
    candidates: list[NDArray[np.int32] | None] = [None]
    for name, snap in zip(products.names_by_strain[1:], snaps[1:], strict=True):
        moved = products.displacement_zone(name)
        zone = np.zeros(snap.n_particles, np.int32) if moved is None else moved.members
        accepted.append(zone if moved is not None and moved.found else np.zeros(snap.n_particles, np.int32))
        candidates.append(zone)
    return accepted, candidates


def _final_band_members(snaps: Sequence[Any], labels: Sequence[NDArray[np.int32] | None]
                        ) -> list[tuple[NDArray[np.bool_], int] | None]:
    """Per snapshot, the grains of the band accepted last (at the end of the test, when
    it is accepted there), matched by id: the final band carried back; None at every
    snapshot when no band is ever accepted."""
    for k in range(len(snaps) - 1, -1, -1):
        band = labels[k]
        if band is not None and np.any(np.asarray(band) > 0):
            ids = np.asarray(snaps[k].ids)[np.asarray(band) > 0]
            return [(np.isin(np.asarray(s.ids), ids) & np.asarray(s.is_sample), k) for s in snaps]
    return [None] * len(snaps)


def _snapshot_row(reference: Any, view: BodyView, labels: NDArray[np.int32] | None,
                  member: tuple[NDArray[np.bool_], int] | None, peak_ids: NDArray[np.int64],
                  options: Mapping[str, Any]) -> dict[str, Any]:
    """Fabric of one snapshot, and inside / outside the band's grains (``member``,
    :func:`_band_members`). ``band_found``: a band is accepted at this snapshot
    itself; ``band_members_known``: at this snapshot or a later one."""
    from grainlab.analysis.band_contacts import BandContacts
    from grainlab.analysis.band_fabric import BandFabric, roc_auc
    from grainlab.analysis.strain import match_ids

    fabric = _fabric_of(view, options)
    snap = view.snapshot
    grains = np.asarray(snap.is_sample)
    stability = fabric["stability"]
    lam = np.asarray(stability.stability_index)[grains]
    counts = np.asarray(stability.n_contacts)[grains]
    ids = np.asarray(snap.ids)[grains]
    rotation = None
    if snap.rotations is not None and reference.rotations is not None:
        to_ref = match_ids(reference, snap)[grains]
        rotation = np.full(int(grains.sum()), np.nan)
        have = to_ref >= 0
        rotation[have] = np.asarray(snap.rotations)[grains][have] - np.asarray(reference.rotations)[to_ref[have]]
    row: dict[str, Any] = dict(fabric["numbers"])
    row["auc_lambda_peak_band"] = roc_auc(lam, np.isin(ids, peak_ids)) if peak_ids.size else math.nan
    row["band_found"] = labels is not None and bool(np.any(labels > 0))
    row["band_members_known"] = member is not None
    if member is not None:
        bf = BandFabric().compute(
            snap.positions[grains], 2.0 * snap.radii[grains], lam, counts, member[0][grains],
            grain_contacts=np.asarray(fabric["grain_contacts"])[grains], rotation=rotation,
        )
        row.update(bf.summary())
        row.update(BandContacts().compute(lam, counts, member[0][grains]).summary())
    return row


def measure_study(rows: Sequence[Mapping[str, Any]]) -> dict[str, Any]:
    """The packing-study numbers of one seed from its rows (``study.csv`` columns;
    failed rows left out). Fits are least squares (:func:`scipy.stats.linregress`)."""
    from scipy.stats import linregress

    from grainlab.study.paper import packing_series

    def fit(kind: str | None, x: str, y: str = "mean_stability_index") -> dict[str, float]:
        xs, ys = packing_series(rows, kind, x, y)
        if xs.size < 3 or np.ptp(xs) == 0:
            return {"slope": math.nan, "intercept": math.nan, "r2": math.nan, "n": int(xs.size)}
        if np.ptp(ys) == 0:
            return {"slope": 0.0, "intercept": float(ys[0]), "r2": math.nan, "n": int(xs.size)}
        res = linregress(xs, ys)
        return {"slope": float(res.slope), "intercept": float(res.intercept), "r2": float(res.rvalue**2),
                "n": int(xs.size)}

    keep = ("kind", "porosity_target", "porosity", "coordination_number", "anisotropy", "mean_stability_index",
            "mean_stability_index_all", "status")
    out: dict[str, Any] = {"n_rows": len(rows), "failed": sum(r.get("status") == "failed" for r in rows),
                           "rows": [{k: r.get(k) for k in keep} for r in rows if r.get("status") != "failed"]}
    for kind, label in ((None, "pooled"), ("irregular", "irregular"), ("hexagonal", "hexagonal")):
        out[f"lambda_vs_z_{label}"] = fit(kind, "coordination_number")
        out[f"lambda_vs_porosity_{label}"] = fit(kind, "porosity")
        out[f"lambda_vs_a_{label}"] = fit(kind, "anisotropy")
    # hexagonal against the irregular fit at the same Z, where the Z ranges overlap
    irr_z, _ = packing_series(rows, "irregular", "coordination_number", "mean_stability_index")
    hex_z, hex_l = packing_series(rows, "hexagonal", "coordination_number", "mean_stability_index")
    f = out["lambda_vs_z_irregular"]
    inside = (hex_z >= irr_z.min()) & (hex_z <= irr_z.max()) if irr_z.size else np.zeros(hex_z.size, bool)
    out["hexagonal_in_irregular_z_range"] = int(inside.sum())
    out["hexagonal_minus_irregular_at_z"] = (
        float(np.mean(hex_l[inside] - (f["intercept"] + f["slope"] * hex_z[inside])))
        if inside.any() and math.isfinite(f["slope"]) else math.nan
    )
    by_target: dict[str, dict[float, float]] = {"irregular": {}, "hexagonal": {}}
    for r in rows:
        if r.get("status") != "failed" and r.get("kind") in by_target:
            by_target[r["kind"]][round(_finite(r.get("porosity_target")), 6)] = _finite(r.get("mean_stability_index"))
    shared = sorted(set(by_target["irregular"]) & set(by_target["hexagonal"]))
    diffs = [by_target["hexagonal"][t] - by_target["irregular"][t] for t in shared]
    diffs = [d for d in diffs if math.isfinite(d)]
    out["hexagonal_minus_irregular_at_porosity"] = float(np.mean(diffs)) if diffs else math.nan
    _, irr_l = packing_series(rows, "irregular", "coordination_number", "mean_stability_index")
    out["hexagonal_minus_irregular_mean"] = (
        float(np.mean(hex_l) - np.mean(irr_l)) if hex_l.size and irr_l.size else math.nan
    )
    return out


#: The analysis options a packing study is measured again under: a reading of Eqs. 9-11.
STUDY_OPTIONS = frozenset({"lambda_slots", "lambda_anchor", "lambda_deviation"})


def read_study_rows(folder: str | Path, options: Mapping[str, Any] | None = None) -> list[dict[str, Any]]:
    """The rows of the packings finished in ``folder`` (``*/result.json``). With lambda
    ``options`` (:data:`STUDY_OPTIONS`: a reading of Eqs. 9-11), each row's mean lambda
    is measured again under that reading on the packing the row was measured on
    (``ValueError`` for a packing stored without it)."""
    return read_study_rows_each(folder, [options or {}])[0]


def read_study_rows_each(folder: str | Path, options: Sequence[Mapping[str, Any]]) -> list[list[dict[str, Any]]]:
    """:func:`read_study_rows` under each of ``options``, each packing read once."""
    from grainlab.analysis.stability import StabilityIndex
    from grainlab.study.packing import read_packing

    for given in options:
        unknown = set(given) - STUDY_OPTIONS
        if unknown:
            raise ValueError(f"a packing study is measured again only under a reading of lambda, not {sorted(unknown)}")
    out: list[list[dict[str, Any]]] = [[] for _ in options]
    for path in sorted(Path(folder).glob("*/result.json")):
        try:
            row = json.loads(path.read_text())["row"]
        except (OSError, json.JSONDecodeError, KeyError):
            continue
        measured = row.get("status") != "failed" and any(options)
        snap = read_packing(path.parent) if measured else None
        for rows, given in zip(out, options, strict=True):
            if given and snap is not None:
                stability = StabilityIndex(**_reading(given)).compute(snap)
                rows.append({**row, "mean_stability_index": stability.mean,
                             "mean_stability_index_all": stability.mean_all})
            else:
                rows.append(row)
    return out
