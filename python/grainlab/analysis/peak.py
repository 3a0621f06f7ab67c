"""The stress-ratio peak of a loading test, one rule for every use (docs/analysis.md,
"Figures of a biaxial run").

>>> peak_record([0.0, 0.01, 0.02, 0.03], [1.0, 3.0, 3.0, 2.0])
1
>>> nearest_snapshot([0.0, 0.005, 0.015, 0.10], 0.012)
2
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["nearest_snapshot", "peak_is_interior", "peak_record"]


def _finite_rows(axial_strain: ArrayLike, stress_ratio: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    eps = np.asarray(axial_strain, dtype=np.float64)
    q = np.asarray(stress_ratio, dtype=np.float64)
    if eps.shape != q.shape or eps.ndim != 1:
        raise ValueError(f"axial_strain and stress_ratio: two 1-D series of one length, got {eps.shape} and {q.shape}")
    rows = np.flatnonzero(np.isfinite(eps) & np.isfinite(q))
    if rows.size == 0:
        raise ValueError("no record has both a finite axial_strain and a finite stress_ratio")
    return rows, q


def peak_record(axial_strain: ArrayLike, stress_ratio: ArrayLike) -> int:
    """The index of the peak record (module docstring); ``ValueError`` when no record
    has both values finite."""
    rows, q = _finite_rows(axial_strain, stress_ratio)
    return int(rows[np.argmax(q[rows])])


def peak_is_interior(axial_strain: ArrayLike, stress_ratio: ArrayLike) -> bool:
    """Whether the peak lies inside the record: neither its first nor its last finite record
    (else the test ended before, or began at, its largest stress ratio)."""
    rows, q = _finite_rows(axial_strain, stress_ratio)
    k = int(rows[np.argmax(q[rows])])
    return bool(rows[0] < k < rows[-1])


def nearest_snapshot(snapshot_strains: Sequence[float], peak_strain: float) -> int:
    """The index of the snapshot nearest ``peak_strain`` (module docstring), snapshots
    whose strain is unknown (NaN) left out; the last one when none is known, or when
    ``peak_strain`` is not finite."""
    strains = [float(s) for s in snapshot_strains]
    if not strains:
        raise ValueError("snapshot_strains: no snapshots")
    candidates = range(1 if len(strains) > 1 else 0, len(strains))
    known = [k for k in candidates if math.isfinite(strains[k])]
    if not known or not math.isfinite(peak_strain):
        return candidates[-1]
    return min(known, key=lambda k: (abs(strains[k] - peak_strain), k))
