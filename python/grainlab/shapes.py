"""Grain shapes as clumps of disks: dimers, trimers, straight rods and user
templates, each sized by its circumscribed radius ``R`` (a grading gives ``2 R``)
and shaped by CEGEO's parameter ``eta = dR / R`` (``R - dR`` the inscribed radius;
eta = 0 is a disk). The pebbles of each shape, and why: docs/bodies.md, "Shapes".

>>> t = shape_template("trimer", 0.3)
>>> round(t.circumscribed_radius, 12), round(t.inscribed_radius, 12)
(1.0, 0.7)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from grainlab.bodies import clump_mass_properties

__all__ = ["SHAPES", "ShapeTemplate", "inscribed_radius", "shape_template", "template_of"]

#: The shapes :func:`shape_template` makes (besides "disk").
SHAPES = ("disk", "dimer", "trimer", "rod")


@dataclass(frozen=True)
class ShapeTemplate:
    """A body's pebbles about its centroid, scaled to circumscribed radius 1
    (multiply offsets and radii by a body's ``R``; arrays read-only)."""

    #: "disk", "dimer", "trimer", "rod" or "template".
    name: str
    #: CEGEO's shape parameter ``1 - inscribed / circumscribed``.
    eta: float
    #: (K, 2) pebble centres from the centroid, for R = 1.
    offsets: NDArray[np.float64]
    #: (K,) pebble radii, for R = 1.
    radii: NDArray[np.float64]
    #: Area of the union of the pebbles, for R = 1 (times R^2).
    area: float

    @property
    def n_pebbles(self) -> int:
        return len(self.radii)

    @property
    def circumscribed_radius(self) -> float:
        return float(np.max(np.hypot(self.offsets[:, 0], self.offsets[:, 1]) + self.radii))

    @property
    def inscribed_radius(self) -> float:
        return inscribed_radius(self.offsets, self.radii)

    @property
    def equal_area_radius(self) -> float:
        """The radius of the disk of the same area, for R = 1."""
        return math.sqrt(self.area / math.pi)


def _frozen(array: NDArray[np.float64]) -> NDArray[np.float64]:
    array.flags.writeable = False
    return array


def _pebbles(name: str, eta: float, n: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Centres and radii of the named shape at ``eta`` (R = 1), from the module's formulas."""
    if name == "dimer":
        arm, r = (1.0 - (1.0 - eta) ** 2) / 2.0, (1.0 + (1.0 - eta) ** 2) / 2.0
        return np.array([[-arm, 0.0], [arm, 0.0]]), np.full(2, r)
    if name == "trimer":
        arm = eta * (2.0 - eta) / (1.0 + eta)
        angles = np.pi / 2.0 + 2.0 * np.pi * np.arange(3) / 3.0
        return arm * np.column_stack([np.cos(angles), np.sin(angles)]), np.full(3, 1.0 - arm)
    # rod: n pebbles on the x axis
    if n % 2:
        s = 2.0 * eta / (n - 1)
    else:
        # ((n-1)^2 - 1) a^2 - 2 (n-1) a + eta (2 - eta) = 0 with a = s / 2: the smaller root
        p, q = (n - 1) ** 2 - 1.0, float(n - 1)
        c = eta * (2.0 - eta)
        a = c / (2.0 * q) if p == 0.0 else (q - math.sqrt(q * q - p * c)) / p
        s = 2.0 * a
    r = 1.0 - (n - 1) * s / 2.0
    x = (np.arange(n) - (n - 1) / 2.0) * s
    return np.column_stack([x, np.zeros(n)]), np.full(n, r)


def _largest_eta(name: str, n: int) -> float:
    """The eta at which the shape's pebbles only touch (excluded)."""
    if name == "dimer":
        return 1.0
    if name == "trimer":
        return 1.0 - 1.0 / (2.0 + math.sqrt(3.0))
    return (n - 1) / n if n % 2 else 1.0


def shape_template(name: str, eta: float, *, n_pebbles: int | None = None) -> ShapeTemplate:
    """The template of ``name`` ("disk", "dimer", "trimer" or "rod" of
    ``n_pebbles`` >= 2 equal pebbles) at shape parameter ``eta`` (0 <= eta, below
    the value where the pebbles only touch; 0 gives one disk for every shape)."""
    if name not in SHAPES:
        raise ValueError(f"shape: must be one of {', '.join(SHAPES)} or a template file, got {name!r}")
    eta = float(eta)
    n = {"disk": 1, "dimer": 2, "trimer": 3}.get(name, n_pebbles or 0)
    if name == "rod" and (n_pebbles is None or int(n_pebbles) < 2):
        raise ValueError(f"n_pebbles: a rod needs 2 or more pebbles, got {n_pebbles!r}")
    if name != "rod" and n_pebbles is not None:
        raise ValueError(f"n_pebbles: only a rod takes it ({name} has {n})")
    top = 0.0 if name == "disk" else _largest_eta(name, n)
    if not (math.isfinite(eta) and 0.0 <= eta and (eta < top or eta == 0.0)):
        raise ValueError(f"shape_parameter: a {name}'s eta must be in [0, {top:.4g}), got {eta!r}")
    if eta == 0.0:
        offsets, radii = np.zeros((1, 2)), np.ones(1)
    else:
        offsets, radii = _pebbles(name, eta, n)
    area = clump_mass_properties(offsets, radii, density=1.0).area_m2
    return ShapeTemplate(name, eta, _frozen(offsets), _frozen(radii), area)


def template_of(offsets: ArrayLike, radii: ArrayLike) -> ShapeTemplate:
    """A user's template: pebble centres (K, 2) and radii (K,) in any frame and
    scale, put about the union's centroid and scaled to circumscribed radius 1."""
    props = clump_mass_properties(offsets, radii, density=1.0)
    body = np.array(props.body_offsets_m, dtype=np.float64)
    sizes = np.array(radii, dtype=np.float64)
    scale = float(np.max(np.hypot(body[:, 0], body[:, 1]) + sizes))
    body, sizes = body / scale, sizes / scale
    eta = 1.0 - inscribed_radius(body, sizes)
    return ShapeTemplate("template", eta, _frozen(body), _frozen(sizes), props.area_m2 / scale**2)


def inscribed_radius(offsets: ArrayLike, radii: ArrayLike) -> float:
    """The radius of the largest circle about the origin inside the union of
    disks (0 when the origin is not inside it): the nearest point of the
    union's boundary, which is either the point of a circle nearest the origin
    or a crossing of two circles, of those that points a nanometre-scale step
    around leave (some of them in no disk)."""
    c = np.asarray(offsets, dtype=np.float64).reshape(-1, 2)
    r = np.asarray(radii, dtype=np.float64).reshape(-1)
    dist = np.hypot(c[:, 0], c[:, 1])
    if not np.any(dist <= r):
        return 0.0
    candidates = [c[k] * (1.0 - r[k] / dist[k]) if dist[k] > 0 else np.array([r[k], 0.0]) for k in range(len(r))]
    for i in range(len(r)):
        for j in range(i + 1, len(r)):
            d = c[j] - c[i]
            dd = float(np.hypot(*d))
            if dd == 0.0 or dd >= r[i] + r[j] or dd <= abs(r[i] - r[j]):
                continue
            along = (dd * dd + r[i] ** 2 - r[j] ** 2) / (2.0 * dd)
            h = math.sqrt(max(r[i] ** 2 - along * along, 0.0))
            base, across = c[i] + along * d / dd, np.array([-d[1], d[0]]) / dd
            candidates += [base + h * across, base - h * across]
    points = np.array(candidates)
    # a candidate is on the boundary when points just around it lie outside every
    # disk (a point where several circles meet inside the union is not)
    turns = np.linspace(0.0, 2.0 * np.pi, 32, endpoint=False)
    probes = points[:, None, :] + 1e-9 * r.max() * np.stack([np.cos(turns), np.sin(turns)], axis=1)
    reach = np.hypot(probes[..., None, 0] - c[:, 0], probes[..., None, 1] - c[:, 1])
    on_boundary = np.any(np.all(reach > r, axis=2), axis=1)
    return float(np.min(np.hypot(points[on_boundary, 0], points[on_boundary, 1])))
