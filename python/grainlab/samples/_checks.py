"""The samples' checks of their input: each bad value is a ``ValueError`` naming its
field, before any work."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray


def in_range(name: str, value: Any, interval: str, what: str = "a finite number") -> float:
    """``value`` as a float inside ``interval``, written as ``"(0, 1]"`` or ``"[0, inf)"``.

    >>> in_range("porosity", "0.2", "(0, 1)")
    0.2
    """
    low, high = (float(end) for end in interval[1:-1].split(","))
    x = float(value)
    above = low < x if interval[0] == "(" else low <= x
    below = x < high if interval[-1] == ")" else x <= high
    if not (math.isfinite(x) and above and below):
        raise ValueError(f"{name}: must be {what} in {interval}, got {value!r}")
    return x


def positive_lengths(name: str, values: ArrayLike, what: str) -> NDArray[np.float64]:
    """``values`` as a 1-D array of finite lengths > 0 (m), else one line naming ``name[k]``."""
    r = np.asarray(values, dtype=np.float64)
    if r.ndim != 1:
        raise ValueError(f"{name}: expected a 1-D array, got shape {r.shape}")
    if not np.all(np.isfinite(r)) or np.any(r <= 0):
        k = int(np.argmax(~np.isfinite(r) | (r <= 0)))
        raise ValueError(f"{name}[{k}]: must be a finite {what} > 0 (m), got {r[k]}")
    return r
