r"""Friction and dilation angles of a biaxial run, and the classical shear-band angles.

Radians here, degrees only in the report's text; the formulas and conventions:
docs/report.md, "How the angles are computed".

Example
-------
>>> import math
>>> phi = mobilised_friction_angle(3.0)            # sigma_1 = 3 sigma_3: sin(phi) = 1/2
>>> round(math.degrees(phi), 6)
30.0
>>> psi = math.radians(10.0)
>>> [round(math.degrees(f), 6) for f in (mohr_coulomb_angle(phi), roscoe_angle(psi), arthur_angle(phi, psi))]
[60.0, 50.0, 55.0]
>>> round(math.degrees(dilation_angle_from_slope(-2.0 / 3.0)), 6)   # s = -2/3: sin(psi) = 1/4
14.477512
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

__all__ = [
    "DEFAULT_DILATION_WINDOW",
    "ClassicalAngles",
    "DilationFit",
    "arthur_angle",
    "dilation_angle_from_slope",
    "fit_dilation",
    "mobilised_friction_angle",
    "mohr_coulomb_angle",
    "roscoe_angle",
]

#: Axial strain after the peak over which the dilation angle is fitted (1 %).
DEFAULT_DILATION_WINDOW = 0.01

_QUARTER = math.pi / 4.0


def mobilised_friction_angle(stress_ratio: float) -> float:
    """``phi`` (rad) from ``R = sigma_1 / sigma_3``: ``sin(phi) = (R - 1) / (R + 1)``.

    NaN when ``R`` is not finite or below 1 (no friction is mobilised).
    """
    r = float(stress_ratio)
    if not math.isfinite(r) or r < 1.0:
        return math.nan
    return math.asin((r - 1.0) / (r + 1.0))


def dilation_angle_from_slope(slope: float) -> float:
    """``psi`` (rad) from ``s = d eps_v / d eps_1``: ``sin(psi) = -s / (2 - s)``.

    Compression positive, so dilation (``s < 0``) gives ``psi > 0``. NaN when
    the slope is not finite or gives ``|sin(psi)| > 1`` (``s >= 1``: the
    sample would contract faster than it shortens, no shearing).
    """
    s = float(slope)
    if not math.isfinite(s) or s >= 1.0:
        return math.nan
    return math.asin(-s / (2.0 - s))


def mohr_coulomb_angle(phi: float) -> float:
    """Mohr–Coulomb inclination to the sigma_3 direction, ``pi/4 + phi/2`` (rad)."""
    return _QUARTER + 0.5 * phi


def roscoe_angle(psi: float) -> float:
    """Roscoe inclination to the sigma_3 direction, ``pi/4 + psi/2`` (rad)."""
    return _QUARTER + 0.5 * psi


def arthur_angle(phi: float, psi: float) -> float:
    """Arthur inclination to the sigma_3 direction, ``pi/4 + (phi + psi)/4`` (rad)."""
    return _QUARTER + 0.25 * (phi + psi)


@dataclass(frozen=True)
class DilationFit:
    """The dilation angle fitted on the volumetric curve after the peak."""

    #: ``psi`` (rad); NaN when it cannot be fitted (``reason`` says why).
    angle: float
    #: Least-squares slope ``s = d eps_v / d eps_1`` over the window.
    slope: float
    #: Intercept of the fitted line (``eps_v = slope * eps_1 + intercept``).
    intercept: float
    #: First and last axial strain of the records used.
    start_strain: float
    end_strain: float
    #: Records in the window.
    n_records: int
    #: Axial strain window asked for.
    window: float
    #: Why there is no angle ("" when there is one).
    reason: str = ""


def fit_dilation(
    axial_strain: ArrayLike,
    volumetric_strain: ArrayLike,
    peak_row: int,
    window: float = DEFAULT_DILATION_WINDOW,
) -> DilationFit:
    """Fit ``eps_v = s eps_1 + c`` over the records with ``eps_1`` in
    ``[eps_1(peak_row), eps_1(peak_row) + window]`` and turn ``s`` into ``psi``.

    At least 3 records with finite values are needed.

    >>> import numpy as np, math
    >>> eps = np.linspace(0.0, 0.05, 101)
    >>> ev = np.where(eps < 0.01, 0.2 * eps, 0.002 - 0.5 * (eps - 0.01))   # s = -1/2 after 1 %
    >>> fit = fit_dilation(eps, ev, peak_row=20)
    >>> round(fit.slope, 9), fit.n_records, round(math.degrees(fit.angle), 4)   # sin(psi) = 0.2
    (-0.5, 21, 11.537)
    """
    eps = np.asarray(axial_strain, dtype=np.float64)
    ev = np.asarray(volumetric_strain, dtype=np.float64)
    if eps.shape != ev.shape or eps.ndim != 1:
        raise ValueError(f"axial_strain, volumetric_strain: expected equal 1D shapes, got {eps.shape}, {ev.shape}")
    if not 0 <= int(peak_row) < eps.size:
        raise ValueError(f"peak_row: {peak_row} is not a row of the {eps.size} records")
    if not (math.isfinite(window) and window > 0):
        raise ValueError(f"window: expected an axial strain > 0, got {window!r}")
    start = float(eps[peak_row])
    rows = np.flatnonzero(
        (np.arange(eps.size) >= peak_row)
        & (eps >= start)
        & (eps <= start + window * (1.0 + 1e-9))
        & np.isfinite(eps)
        & np.isfinite(ev)
    )

    def failed(reason: str) -> DilationFit:
        end = float(eps[rows[-1]]) if rows.size else start
        return DilationFit(math.nan, math.nan, math.nan, start, end, int(rows.size), float(window), reason)

    if rows.size < 3:
        return failed(
            f"only {rows.size} record(s) between the peak ({100 * start:.2f} %) and "
            f"{100 * (start + window):.2f} % axial strain; 3 are needed"
        )
    x, y = eps[rows], ev[rows]
    if np.ptp(x) <= 0.0:
        return failed("the records after the peak do not span any axial strain")
    slope, intercept = np.polyfit(x, y, 1)
    psi = dilation_angle_from_slope(float(slope))
    reason = "" if math.isfinite(psi) else f"the slope d eps_v / d eps_1 = {slope:.3g} gives no angle"
    return DilationFit(
        psi, float(slope), float(intercept), float(x[0]), float(x[-1]), int(rows.size), float(window), reason
    )


@dataclass(frozen=True)
class ClassicalAngles:
    """``phi``, ``psi`` and the three classical inclinations (rad, NaN when unknown)."""

    phi: float
    psi: float
    mohr_coulomb: float
    roscoe: float
    arthur: float

    @classmethod
    def from_angles(cls, phi: float, psi: float) -> ClassicalAngles:
        """The three inclinations of a run with friction angle ``phi`` and dilation angle ``psi``."""
        return cls(phi, psi, mohr_coulomb_angle(phi), roscoe_angle(psi), arthur_angle(phi, psi))

    def degrees(self) -> dict[str, float]:
        """The five angles in degrees, keyed by name."""
        return {k: math.degrees(v) for k, v in self.__dict__.items()}

    def closest(self, inclination: float) -> str | None:
        """Name of the classical angle closest to ``inclination`` (rad), or None."""
        candidates = {
            "Mohr-Coulomb": self.mohr_coulomb,
            "Roscoe": self.roscoe,
            "Arthur": self.arthur,
        }
        known = {k: abs(v - inclination) for k, v in candidates.items() if math.isfinite(v)}
        if not known or not math.isfinite(inclination):
            return None
        return min(known, key=known.__getitem__)
