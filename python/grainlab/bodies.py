"""Bodies: the mass properties of a clump, a rigid body of overlapping disks.

The union of its pebbles (overlaps counted once, enclosed holes left out), its area,
centroid and polar second moment exact from Green's theorem over the arcs of its
boundary (the engine's ``grainlab_core::body``; docs/bodies.md, "The closed form:
Green's theorem over the arcs"); per unit thickness, mass ``rho A`` and moment of
inertia ``rho J`` about the centroid.

>>> import numpy as np
>>> two = clump_mass_properties([[-0.5e-3, 0.0], [0.5e-3, 0.0]], [1e-3, 1e-3], density=2650.0)
>>> lens = 2e-6 * np.arccos(0.5) - 0.5e-3 * np.sqrt(4e-6 - 1e-6)
>>> bool(np.isclose(two.area_m2, 2 * np.pi * 1e-6 - lens, rtol=1e-12))
True
>>> bool(np.abs(two.centroid_m).max() < 1e-18)  # the midpoint, by symmetry
True
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from grainlab import _core

__all__ = ["ClumpMassProperties", "ClumpState", "clump_mass_properties"]


@dataclass(frozen=True)
class ClumpMassProperties:
    """The mass properties of a clump, per metre of thickness (arrays read-only)."""

    #: Area of the pebbles' union (m^2), each point counted once.
    area_m2: float
    #: Mass ``density * area_m2`` (kg per m of thickness).
    mass_kg: float
    #: (2,) centroid of the union, in the frame of the offsets given (m).
    centroid_m: NDArray[np.float64]
    #: Moment of inertia about the centroid, ``density * int |x - centroid|^2 dA`` (kg m^2 per m).
    moment_of_inertia_kg_m2: float
    #: (N, 2) the pebbles' centres from the centroid: the body frame (m).
    body_offsets_m: NDArray[np.float64]


def _points(name: str, value: ArrayLike, n: int | None = None) -> NDArray[np.float64]:
    try:
        array = np.ascontiguousarray(value, dtype=np.float64)
    except (TypeError, ValueError) as error:
        raise ValueError(f"{name}: expected an (N, 2) array of numbers ({error})") from None
    if array.ndim != 2 or array.shape[1] != 2:
        raise ValueError(f"{name}: expected shape (N, 2), got {array.shape}")
    if n is not None and len(array) != n:
        raise ValueError(f"{name}: has {len(array)} rows but there are {n} particles")
    if not np.all(np.isfinite(array)):
        k = int(np.argwhere(~np.isfinite(array))[0, 0])
        raise ValueError(f"{name}[{k}]: must be finite, got {array[k].tolist()}")
    return array


def clump_mass_properties(
    offsets: ArrayLike, radii: ArrayLike, *, density: float
) -> ClumpMassProperties:
    """The exact area, mass, centroid and moment of inertia of a clump of disks.

    offsets : (N, 2) pebble centres in any frame (m), N >= 1
    radii : (N,) pebble radii (m), finite and > 0
    density : kg/m^3, finite and > 0

    One pebble gives :class:`grainlab.Simulation`'s disk to the bit:
    ``rho pi r^2`` and ``m r^2 / 2``.
    """
    points = _points("offsets", offsets)
    sizes = np.ascontiguousarray(radii, dtype=np.float64)
    if sizes.ndim != 1 or len(sizes) != len(points):
        raise ValueError(
            f"radii: expected shape ({len(points)},) to match offsets, got {sizes.shape}"
        )
    area, mass, centroid, inertia, body = _core.clump_mass_properties(points, sizes, float(density))
    centre = np.array(centroid, dtype=np.float64)
    centre.flags.writeable = False
    body.flags.writeable = False
    return ClumpMassProperties(area, mass, centre, inertia, body)


@dataclass(frozen=True)
class ClumpState:
    """The clumps of a :class:`grainlab.Simulation` (bodies of two or more
    pebbles), in the order they were made (arrays read-only; docs/bodies.md)."""

    #: (C, 2) centroids (m).
    centroid_m: NDArray[np.float64]
    #: (C,) angles of the body frames, counter-clockwise (rad).
    angle_rad: NDArray[np.float64]
    #: (C, 2) centroid velocities (m/s), leapfrog half-step values as the particles'.
    velocity_m_per_s: NDArray[np.float64]
    #: (C,) angular velocities (rad/s).
    angular_velocity_rad_per_s: NDArray[np.float64]
    #: (C,) masses (kg per m of thickness).
    mass_kg: NDArray[np.float64]
    #: (C,) moments of inertia about the centroid (kg m^2 per m).
    moment_of_inertia_kg_m2: NDArray[np.float64]
    #: (C,) prescribed degrees of freedom (1 x, 2 y, 4 rotation).
    fixity: NDArray[np.uint8]
    #: (C, 2) resultant force of the last step, weight included, before damping (N).
    force_n: NDArray[np.float64]
    #: (C,) resultant torque about the centroid of the last step (N m).
    torque_n_m: NDArray[np.float64]

    def __len__(self) -> int:
        return len(self.mass_kg)

    @classmethod
    def _from_engine(cls, d: dict[str, NDArray[Any]]) -> ClumpState:
        names = {
            "centroid": "centroid_m",
            "angle": "angle_rad",
            "velocity": "velocity_m_per_s",
            "angular_velocity": "angular_velocity_rad_per_s",
            "mass": "mass_kg",
            "moment_of_inertia": "moment_of_inertia_kg_m2",
            "fixity": "fixity",
            "force": "force_n",
            "torque": "torque_n_m",
        }
        fields = {}
        for key, name in names.items():
            array = np.asarray(d[key])
            array.flags.writeable = False
            fields[name] = array
        return cls(**fields)
