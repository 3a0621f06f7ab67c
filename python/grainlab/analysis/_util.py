"""Small shared helpers for the analysis classes (not public API)."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from grainlab.snapshot import Snapshot

TWO_PI = 2.0 * np.pi


class NotComputedError(AttributeError):
    """Raised when a result property is read before ``compute`` ran."""


class Computable:
    """Base for freud-style analysis objects: results raise until computed."""

    _results: dict[str, Any] | None = None

    def _result(self, name: str) -> Any:
        if self._results is None:
            raise NotComputedError(
                f"{type(self).__name__}.{name} is not available: call compute(...) first"
            )
        return self._results[name]

    def _store(self, **results: Any) -> None:
        self._results = results


def contact_ends(
    snapshot: Snapshot, *, include_boundary: bool
) -> tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.bool_]]:
    """Owner particle and contact angle of every contact *end* on a sample particle.

    Each particle–particle contact gives two ends (angle theta on i, theta +
    pi on j); a wall contact gives one end on its particle. Ends on membrane
    particles are dropped; with ``include_boundary=False`` so are the contacts
    with walls or membrane particles.

    Returns ``owner (K,)``, ``angle (K,)`` in [0, 2 pi) and the (Nc,) mask of
    the contacts used.
    """
    ci = np.asarray(snapshot.contact_i)
    cj = np.asarray(snapshot.contact_j)
    angle = np.asarray(snapshot.contact_angles())
    keep = np.ones(ci.shape, bool) if include_boundary else ~snapshot.is_boundary_contact
    sample = snapshot.is_sample
    pp = keep & (cj >= 0)
    on_i = keep & sample[ci]
    on_j = pp & sample[np.where(cj >= 0, cj, 0)]
    angle_j = angle[on_j] + np.pi
    angle_j[angle_j >= TWO_PI] -= TWO_PI
    owner = np.concatenate([ci[on_i], cj[on_j]])
    ends = np.concatenate([angle[on_i], angle_j])
    return owner, ends, keep


def finite_mean(values: NDArray[np.float64], mask: NDArray[np.bool_] | None = None) -> float:
    """Mean of the finite entries (under ``mask``); NaN when there are none."""
    v = np.asarray(values, dtype=np.float64)
    ok = np.isfinite(v)
    if mask is not None:
        ok &= mask
    return float(v[ok].mean()) if ok.any() else float("nan")
