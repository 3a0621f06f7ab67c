"""Constructed measures of a run that behaves as the paper says (or the opposite):
what :func:`grainlab.reproduction.measures.measure_biaxial` returns, from analytic
curves, so that claims and their verdicts are checked without simulating."""

from __future__ import annotations

import numpy as np

SNAPSHOT_STRAINS = [0.0, 0.0025, 0.005, 0.007, 0.0075, 0.009, 0.01, 0.0125, 0.015, 0.0175, 0.02,
                    0.03, 0.04, 0.05, 0.06, 0.07, 0.08, 0.09, 0.10]


def paper_like(seed: int, *, band_sign: float = 1.0) -> dict:
    """Measures of one seed: a peak at 1.5 %, a softening to a constant, contraction then
    dilation, a rising to 0.18 at 0.5 %, Z from 3.9 to 3.0, a band from 0.5 % whose lambda
    is 0.34 against 0.31 at the peak (``band_sign=-1``: the band more stable instead)."""
    rng = np.random.default_rng(seed)
    jitter = 1.0 + 0.01 * rng.standard_normal()
    eps = np.linspace(0.0, 0.10, 201)
    peak = 0.015
    q = np.where(eps <= 0.005, 1.0 + 400.0 * eps,
                 np.where(eps <= peak, 3.0 + 50.0 * (eps - 0.005), 3.5 - 40.0 * (eps - peak)))
    q = np.maximum(q, 3.0) * jitter
    ev = 0.002 * np.sin(np.pi * np.minimum(eps / 0.01, 1.0)) - 0.4 * np.maximum(eps - 0.01, 0.0)
    snaps = []
    for e in SNAPSHOT_STRAINS:
        rise = min(e / peak, 1.0)
        after = max(e - peak, 0.0)
        a = (0.0034 + (0.18 - 0.0034) * min(e / 0.005, 1.0) + 0.04 * (rise - min(e / 0.005, 1.0))
             - 0.06 * min(after / 0.02, 1.0)) * jitter
        lam = (0.30 + 0.03 * rise - 0.015 * min(after / 0.02, 1.0)) * jitter
        z = 3.9 - 0.9 * rise
        row = {
            "name": f"strain_{e:.4f}", "axial_strain": e, "stress_ratio": float(np.interp(e, eps, q)),
            "a": a, "a_binned": a, "a_n": 0.009 + 0.5 * rise, "coordination_number": z,
            "mean_lambda": lam, "mean_lambda_all": lam + 0.01,
            "auc_lambda_peak_band": 0.5 if e == 0.0 else 0.5 + 0.2 * rise,
            "band_found": e >= 0.005,
        }
        if row["band_found"]:
            d = band_sign * 0.03 * rise
            row.update({
                "inside_mean_lambda": 0.31 + d + 0.001 * jitter, "outside_mean_lambda": 0.31,
                "inside_mean_lambda_all": 0.32 + d, "outside_mean_lambda_all": 0.32,
                "inside_coordination_number": 2.6, "outside_coordination_number": 3.1,
                "inside_fraction_2_of_load_bearing": 0.6, "outside_fraction_2_of_load_bearing": 0.3,
                "inside_fraction_3_or_more_of_load_bearing": 0.4, "outside_fraction_3_or_more_of_load_bearing": 0.7,
                "inside_fraction_lambda_above_half": 0.2, "outside_fraction_lambda_above_half": 0.1,
                "inside_mean_abs_rotation_rad": 0.05, "outside_mean_abs_rotation_rad": 0.01,
                "auc_lambda": 0.7 * jitter, "auc_lambda_field": 0.8 * jitter,
            })
        snaps.append(row)
    final = q[-1]
    window = eps >= 0.07
    return {
        "run": f"seed-{seed}", "analysis": {"boundary_contacts": "body"},
        "macro": {
            "final_strain": 0.10, "peak_row": int(np.argmax(q)), "peak_axial_strain": float(eps[np.argmax(q)]),
            "peak_stress_ratio": float(q.max()), "peak_in_interior": True, "linear_r2": 0.999,
            "residual_stress_ratio": float(np.mean(q[window])), "residual_relative_slope": 0.0,
            "end_window_from": 0.07, "max_contraction": float(ev.max()),
            "axial_strain_at_max_contraction": float(eps[np.argmax(ev)]), "final_volumetric_strain": float(ev[-1]),
            "records": {"axial_strain": eps.tolist(), "stress_ratio": q.tolist(), "volumetric_strain": ev.tolist()},
        },
        "snapshots": snaps,
        "peak_snapshot": SNAPSHOT_STRAINS.index(0.015),
        "wall_time_s": 100.0 + seed, "strain_rate": 0.02 / 60.0, "notes": [], "final": final,
    }


def study_like(seed: int) -> dict:
    """Study measures where lambda falls with Z in both series and hexagonal lies below."""
    rng = np.random.default_rng(100 + seed)
    rows = []
    for target in (0.08, 0.10, 0.12, 0.14):
        z = 4.7 - 8.0 * (target - 0.08) + 0.02 * rng.standard_normal()
        rows.append({"kind": "irregular", "porosity_target": target, "porosity": target, "coordination_number": z,
                     "anisotropy": 0.02, "mean_stability_index": 0.3 - 0.03 * z, "status": "ok"})
        zh = 6.0 - 5.0 * (target - 0.08)
        rows.append({"kind": "hexagonal", "porosity_target": target, "porosity": target, "coordination_number": zh,
                     "anisotropy": 0.0, "mean_stability_index": 0.5 - 0.08 * zh, "status": "ok"})
    from grainlab.reproduction.measures import measure_study

    return measure_study(rows)
