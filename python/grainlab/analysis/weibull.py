"""The Weibull statistics of grain strength (McDowell and Bolton 1998): the survival
probability of a grain at the characteristic stress sigma is
``P_s = exp(-(sigma / sigma_0)^m)``, with the Weibull modulus ``m`` and ``sigma_0``
the stress at which 37 % of the grains survive.

The fit's rule, fixed before any run was seen: the N strengths sorted, the i-th
smallest (i = 1 .. N) is given the survival probability of the median-rank estimator
``P_s = 1 - (i - 0.5) / N``; ``m`` and ``sigma_0`` are the least-squares line of
``ln(-ln P_s)`` on ``ln sigma`` (slope ``m``, intercept ``-m ln sigma_0``), and R^2
is that line's. The confidence intervals are the 2.5 and 97.5 percentiles of the
same fit over resamples of the strengths (a bootstrap with a fixed seed, so a run's
numbers are reproducible). Pure: arrays in, numbers out.

>>> import numpy as np
>>> strengths = 2e6 * np.random.default_rng(3).weibull(5.0, 2000)
>>> fit = weibull_fit(strengths, resamples=200)
>>> round(fit.modulus), round(fit.scale / 1e6, 1)
(5, 2.0)
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["ESTIMATOR", "WeibullFit", "weibull_fit", "weibull_points"]

#: The fit's rule in a line (summaries, report pages).
ESTIMATOR = "median ranks P_s = 1 - (i - 0.5)/N; least squares of ln(-ln P_s) on ln sigma"
#: The bootstrap's resamples and seed.
RESAMPLES = 2000
BOOTSTRAP_SEED = 20030701


@dataclass(frozen=True)
class WeibullFit:
    """A Weibull fit of N strengths: the modulus m, the scale sigma_0 (the strengths'
    unit), the line's R^2 and the 95 % bootstrap intervals of m and sigma_0."""

    n: int
    modulus: float
    scale: float
    r_squared: float
    modulus_interval: tuple[float, float]
    scale_interval: tuple[float, float]

    def survival(self, sigma: ArrayLike) -> NDArray[np.float64]:
        """``exp(-(sigma / sigma_0)^m)``."""
        return np.asarray(np.exp(-((np.asarray(sigma, dtype=np.float64) / self.scale) ** self.modulus)))

    def to_dict(self) -> dict[str, Any]:
        return {**asdict(self), "estimator": ESTIMATOR, "interval": "95 % bootstrap"}


def weibull_points(strengths: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The Weibull plot's points: ``ln sigma`` of the sorted strengths and ``ln(-ln P_s)``
    of their median ranks."""
    s = np.sort(np.asarray(strengths, dtype=np.float64).reshape(-1))
    n = len(s)
    survival = 1.0 - (np.arange(1, n + 1) - 0.5) / n
    return np.log(s), np.log(-np.log(survival))


def _line(x: NDArray[np.float64], y: NDArray[np.float64]) -> tuple[float, float]:
    slope, intercept = np.polyfit(x, y, 1)
    return float(slope), float(math.exp(-intercept / slope)) if slope != 0 else math.nan


def weibull_fit(strengths: ArrayLike, *, resamples: int = RESAMPLES, seed: int = BOOTSTRAP_SEED) -> WeibullFit:
    """The module's fit of ``strengths`` (at least 3, each finite and > 0, not all equal)."""
    s = np.asarray(strengths, dtype=np.float64).reshape(-1)
    if len(s) < 3:
        raise ValueError(f"strengths: a Weibull fit needs at least 3, got {len(s)}")
    if not np.all(np.isfinite(s) & (s > 0)):
        raise ValueError("strengths: each must be finite and > 0")
    if np.ptp(s) == 0:
        raise ValueError("strengths: all equal, no scatter to fit")
    x, y = weibull_points(s)
    modulus, scale = _line(x, y)
    r_squared = float(np.corrcoef(x, y)[0, 1] ** 2)
    rng = np.random.default_rng(seed)
    fits = []
    for _ in range(int(resamples)):
        resample = rng.choice(s, len(s))
        if np.ptp(resample) > 0:
            fits.append(_line(*weibull_points(resample)))
    m, s0 = np.array(fits).T if fits else (np.array([modulus]), np.array([scale]))
    band = (2.5, 97.5)
    return WeibullFit(len(s), modulus, scale, r_squared, tuple(float(v) for v in np.percentile(m, band)),  # type: ignore[arg-type]
                      tuple(float(v) for v in np.percentile(s0, band)))  # type: ignore[arg-type]
