"""Particle-size distributions (gradings) of 2D disks, by number (what
:meth:`Grading.sample` draws from) and by mass (the grading curve,
:meth:`Grading.passing`; in 2D mass goes as ``d^2``). Diameters in metres;
docs/samples.md, "Gradings", gives each one's formulas.

Example
-------
>>> import numpy as np
>>> from grainlab.samples import UniformByMass
>>> g = UniformByMass(0.5e-3, 3e-3)
>>> d = g.sample(4, np.random.default_rng(0))
>>> bool(np.all((d >= 0.5e-3) & (d <= 3e-3)))
True
>>> round(g.passing(1.75e-3), 6)  # mass uniform in d: half the mass is finer than the middle size
50.0
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod

import numpy as np
from numpy.typing import ArrayLike, NDArray

from grainlab.samples._checks import in_range, positive_lengths

__all__ = [
    "PAPER_GRADING",
    "Grading",
    "GradingCurve",
    "UniformByMass",
    "UniformByNumber",
]


def _check_range(d_min: float, d_max: float) -> tuple[float, float]:
    d_min = in_range("d_min", d_min, "(0, inf)", "a diameter (m)")
    d_max = in_range("d_max", d_max, "(0, inf)", "a diameter (m)")
    if d_min > d_max:
        raise ValueError(f"d_min: must be <= d_max, got d_min={d_min} > d_max={d_max}")
    return d_min, d_max


class Grading(ABC):
    """A distribution of disk diameters on ``[d_min, d_max]`` (m).

    Subclasses give the number CDF and its inverse; everything else follows.
    """

    #: Short human-readable name, stored with every generated sample.
    name: str

    @property
    @abstractmethod
    def d_min(self) -> float:
        """Smallest diameter (m)."""

    @property
    @abstractmethod
    def d_max(self) -> float:
        """Largest diameter (m)."""

    @abstractmethod
    def number_cdf(self, d: ArrayLike) -> NDArray[np.float64]:
        """``F_N(d)``: fraction of particles (by number) with diameter ``<= d``."""

    @abstractmethod
    def number_ppf(self, u: ArrayLike) -> NDArray[np.float64]:
        """Inverse of :meth:`number_cdf`: the diameter below which a fraction ``u`` of particles lie."""

    @abstractmethod
    def mean_square_diameter(self) -> float:
        """``E_N[d^2]`` over particles (m^2)."""

    @abstractmethod
    def passing(self, d: ArrayLike) -> NDArray[np.float64] | float:
        """Percent of solid mass passing a sieve of size ``d`` (0..100); 2D mass ``∝ d^2``."""

    def mean_disk_area(self) -> float:
        """Mean disk area per particle ``pi E_N[d^2] / 4`` (m^2): what
        :func:`~grainlab.samples.particle_count` divides the solid area by."""
        return math.pi * self.mean_square_diameter() / 4.0

    def sample(self, n: int, rng: np.random.Generator) -> NDArray[np.float64]:
        """``n`` diameters (m) drawn independently by number, from ``n`` uniforms of ``rng``."""
        n = int(n)
        if n < 0:
            raise ValueError(f"n: must be >= 0, got {n}")
        return self.number_ppf(rng.random(n))

    def __repr__(self) -> str:
        return f"{type(self).__name__}(d_min={self.d_min!r}, d_max={self.d_max!r})"


def _scalar_or_array(x: NDArray[np.float64], like: ArrayLike) -> NDArray[np.float64] | float:
    return float(x) if np.ndim(like) == 0 else x


class _UniformRange(Grading):
    """A grading on ``[d_min, d_max]`` given by its two ends (``_kind`` names it)."""

    _kind = ""

    def __init__(self, d_min: float, d_max: float, name: str | None = None) -> None:
        self._a, self._b = _check_range(d_min, d_max)
        self.name = name or f"uniform by {self._kind} {self._a * 1e3:g}-{self._b * 1e3:g} mm"

    @property
    def d_min(self) -> float:
        return self._a

    @property
    def d_max(self) -> float:
        return self._b


class UniformByNumber(_UniformRange):
    """Diameters uniform by number on ``[d_min, d_max]``: ``f_N(d) = 1 / (d_max - d_min)``.

    This is what PFC's ``ball generate``/``distribute`` draw by default.
    ``E_N[d^2] = (d_min^2 + d_min d_max + d_max^2) / 3``; mass passing (2D,
    ``m ∝ d^2``): ``P(d) = 100 (d^3 - d_min^3) / (d_max^3 - d_min^3)``.
    """

    _kind = "number"

    def number_cdf(self, d: ArrayLike) -> NDArray[np.float64]:
        d = np.asarray(d, dtype=np.float64)
        if self._b == self._a:
            return (d >= self._a).astype(np.float64)
        return np.clip((d - self._a) / (self._b - self._a), 0.0, 1.0)

    def number_ppf(self, u: ArrayLike) -> NDArray[np.float64]:
        u = np.asarray(u, dtype=np.float64)
        return self._a + (self._b - self._a) * u

    def mean_square_diameter(self) -> float:
        a, b = self._a, self._b
        return (a * a + a * b + b * b) / 3.0

    def passing(self, d: ArrayLike) -> NDArray[np.float64] | float:
        x = np.clip(np.asarray(d, dtype=np.float64), self._a, self._b)
        a3, b3 = self._a**3, self._b**3
        p = 100.0 * (x >= self._b) if b3 == a3 else 100.0 * (x**3 - a3) / (b3 - a3)
        return _scalar_or_array(np.asarray(p, dtype=np.float64), d)


class UniformByMass(_UniformRange):
    """Mass uniform in diameter on ``[d_min, d_max]``: the grading curve is a
    straight line in ``d``, ``P(d) = 100 (d - d_min) / (d_max - d_min)``; by number
    ``F_N(d) = (1/d_min - 1/d) / (1/d_min - 1/d_max)`` and ``E_N[d^2] = d_min d_max``
    (docs/samples.md derives them).
    """

    _kind = "mass"

    def number_cdf(self, d: ArrayLike) -> NDArray[np.float64]:
        d = np.asarray(d, dtype=np.float64)
        if self._b == self._a:
            return (d >= self._a).astype(np.float64)
        x = np.clip(d, self._a, self._b)
        return np.asarray((1.0 / self._a - 1.0 / x) / (1.0 / self._a - 1.0 / self._b), np.float64)

    def number_ppf(self, u: ArrayLike) -> NDArray[np.float64]:
        u = np.asarray(u, dtype=np.float64)
        return 1.0 / (1.0 / self._a - u * (1.0 / self._a - 1.0 / self._b))

    def mean_square_diameter(self) -> float:
        return self._a * self._b

    def passing(self, d: ArrayLike) -> NDArray[np.float64] | float:
        x = np.clip(np.asarray(d, dtype=np.float64), self._a, self._b)
        p = 100.0 * (x >= self._b) if self._b == self._a else 100.0 * (x - self._a) / (self._b - self._a)
        return _scalar_or_array(np.asarray(p, dtype=np.float64), d)


class GradingCurve(Grading):
    """A grading curve: sieve sizes (m) against percent passing *by mass*, a straight
    line between two sieves in ``log d`` (``interpolation="log"``, default) or in ``d``
    (``"linear"``), from 0% at ``d_min`` to 100% at ``d_max``. Each segment's
    number density, the checks and ``E_N[d^2]``: docs/samples.md, "Gradings".
    """

    def __init__(
        self,
        sieve_sizes_m: ArrayLike,
        percent_passing: ArrayLike,
        *,
        interpolation: str = "log",
        name: str | None = None,
    ) -> None:
        sizes = np.array(sieve_sizes_m, dtype=np.float64)
        pct = np.array(percent_passing, dtype=np.float64)
        if sizes.ndim != 1 or len(sizes) < 2:
            raise ValueError(f"sieve_sizes_m: expected at least 2 sizes in a 1-D list, got shape {sizes.shape}")
        if pct.shape != sizes.shape:
            raise ValueError(
                f"percent_passing: expected {len(sizes)} values (one per sieve size), got shape {pct.shape}"
            )
        positive_lengths("sieve_sizes_m", sizes, "size")
        if np.any(np.diff(sizes) <= 0):
            k = int(np.argmax(np.diff(sizes) <= 0)) + 1
            raise ValueError(
                f"sieve_sizes_m[{k}]: sizes must strictly increase, got {sizes[k]} after {sizes[k - 1]}"
            )
        if not np.all(np.isfinite(pct)) or np.any((pct < 0) | (pct > 100)):
            k = int(np.argmax(~np.isfinite(pct) | (pct < 0) | (pct > 100)))
            raise ValueError(f"percent_passing[{k}]: must be in 0..100, got {pct[k]}")
        if np.any(np.diff(pct) < 0):
            k = int(np.argmax(np.diff(pct) < 0)) + 1
            raise ValueError(
                f"percent_passing[{k}]: must not decrease with size, got {pct[k]} after {pct[k - 1]}"
            )
        if pct[0] != 0.0:
            raise ValueError(f"percent_passing[0]: the smallest sieve must pass 0% (it is d_min), got {pct[0]}")
        if pct[-1] != 100.0:
            raise ValueError(
                f"percent_passing[{len(pct) - 1}]: the largest sieve must pass 100% (it is d_max), got {pct[-1]}"
            )
        if interpolation not in ("log", "linear"):
            raise ValueError(f"interpolation: must be 'log' or 'linear', got {interpolation!r}")
        self.interpolation = interpolation
        self.sieve_sizes_m = sizes
        self.percent_passing = pct
        self.sieve_sizes_m.flags.writeable = False
        self.percent_passing.flags.writeable = False
        self.name = name or (
            f"grading curve {sizes[0] * 1e3:g}-{sizes[-1] * 1e3:g} mm ({len(sizes)} sieves, {interpolation})"
        )
        lo, hi = sizes[:-1], sizes[1:]
        w = np.diff(pct) / 100.0
        if interpolation == "log":
            self._number = w / np.log(hi / lo) * (lo**-2 - hi**-2) / 2.0
        else:
            self._number = w / (hi - lo) * (1.0 / lo - 1.0 / hi)
        total = float(self._number.sum())
        self._msd = 1.0 / total  # sum(w) = 1
        self._cum = np.concatenate([[0.0], np.cumsum(self._number) / total])
        self._cum[-1] = 1.0

    @property
    def d_min(self) -> float:
        return float(self.sieve_sizes_m[0])

    @property
    def d_max(self) -> float:
        return float(self.sieve_sizes_m[-1])

    def _inverse_variable(self, d: NDArray[np.float64]) -> NDArray[np.float64]:
        """The variable uniform by number within a segment: ``d^-2`` (log) or ``1/d`` (linear)."""
        return d**-2 if self.interpolation == "log" else 1.0 / d

    def number_cdf(self, d: ArrayLike) -> NDArray[np.float64]:
        sizes = self.sieve_sizes_m
        x = np.clip(np.asarray(d, dtype=np.float64), sizes[0], sizes[-1])
        k = np.clip(np.searchsorted(sizes, x, side="right") - 1, 0, len(sizes) - 2)
        g = self._inverse_variable
        lo, hi = sizes[k], sizes[k + 1]
        frac = (g(lo) - g(x)) / (g(lo) - g(hi))
        return np.asarray(self._cum[k] + frac * (self._cum[k + 1] - self._cum[k]), np.float64)

    def number_ppf(self, u: ArrayLike) -> NDArray[np.float64]:
        sizes = self.sieve_sizes_m
        u = np.clip(np.asarray(u, dtype=np.float64), 0.0, 1.0)
        k = np.searchsorted(self._cum, u, side="right") - 1
        k = np.clip(k, 0, len(sizes) - 2)
        span = self._cum[k + 1] - self._cum[k]
        # empty segments (no mass) are never chosen with u < 1; guard the division anyway
        frac = np.where(span > 0, (u - self._cum[k]) / np.where(span > 0, span, 1.0), 0.0)
        g = self._inverse_variable
        lo, hi = sizes[k], sizes[k + 1]
        v = g(lo) - frac * (g(lo) - g(hi))
        return v**-0.5 if self.interpolation == "log" else 1.0 / v

    def mean_square_diameter(self) -> float:
        return self._msd

    def passing(self, d: ArrayLike) -> NDArray[np.float64] | float:
        sizes = self.sieve_sizes_m
        x = np.clip(np.asarray(d, dtype=np.float64), sizes[0], sizes[-1])
        xp = np.log(sizes) if self.interpolation == "log" else sizes
        p = np.interp(np.log(x) if self.interpolation == "log" else x, xp, self.percent_passing)
        return _scalar_or_array(np.asarray(p, dtype=np.float64), d)

    def __repr__(self) -> str:
        return (
            f"GradingCurve(sieve_sizes_m={self.sieve_sizes_m.tolist()!r}, "
            f"percent_passing={self.percent_passing.tolist()!r}, interpolation={self.interpolation!r})"
        )


#: The paper's well-graded sand, diameters 0.5-3 mm (Table 1), read as uniform
#: by number (PFC's default draw); see docs/samples.md for why.
PAPER_GRADING = UniformByNumber(0.5e-3, 3.0e-3, name="paper sand: uniform by number 0.5-3 mm")
