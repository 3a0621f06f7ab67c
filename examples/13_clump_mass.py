"""The mass properties of a trimer (three overlapping pebbles), exact, beside a raster.

Run: python examples/13_clump_mass.py

grainlab.clump_mass_properties integrates over the arcs of the union's boundary
(docs/bodies.md); the raster counts the centres of 2000 x 2000 cells that fall in
some pebble, so it agrees to about the cell size times the boundary's length.
"""

from __future__ import annotations

import numpy as np

import grainlab

DENSITY = 2650.0  # kg/m^3
R = 1e-3  # m
# three equal pebbles at the corners of a triangle of side 1.2 R: every pair
# overlaps and the three share a region about the centre
OFFSETS = (
    np.array([[np.cos(t), np.sin(t)] for t in np.pi / 2 + 2 * np.pi / 3 * np.arange(3)])
    * 1.2
    * R
    / np.sqrt(3)
)
RADII = np.full(3, R)


def raster(
    offsets: np.ndarray, radii: np.ndarray, cells: int = 2000
) -> tuple[float, np.ndarray, float]:
    """Area, centroid and polar moment about the centroid from the cells' centres in the union."""
    lo = (offsets - radii[:, None]).min(0)
    h = ((offsets + radii[:, None]).max(0) - lo).max() / cells
    axis = (np.arange(cells) + 0.5) * h
    x, y = np.meshgrid(lo[0] + axis, lo[1] + axis, indexing="ij")
    inside = np.zeros(x.shape, bool)
    for (cx, cy), r in zip(offsets, radii, strict=True):
        inside |= (x - cx) ** 2 + (y - cy) ** 2 < r * r
    area = inside.sum() * h * h
    centroid = np.array([x[inside].mean(), y[inside].mean()])
    polar = (
        (
            ((x[inside] - centroid[0]) ** 2 + (y[inside] - centroid[1]) ** 2).sum()
            + inside.sum() * h * h / 6
        )
        * h
        * h
    )
    return float(area), centroid, float(polar)


def main() -> None:
    props = grainlab.clump_mass_properties(OFFSETS, RADII, density=DENSITY)
    area, centroid, polar = raster(OFFSETS, RADII)
    print(f"trimer of three pebbles r = {R:g} m, centres 1.2 r apart, density {DENSITY:g} kg/m^3")
    print(f"area (per m of thickness): exact {props.area_m2:.9e} m^2, raster {area:.9e} m^2")
    print(f"three separate disks would be {3 * np.pi * R * R:.9e} m^2")
    print(f"centroid: exact {props.centroid_m.tolist()}, raster {centroid.tolist()} m")
    print(f"mass: exact {props.mass_kg:.9e} kg/m, raster {DENSITY * area:.9e} kg/m")
    print(
        f"moment of inertia: exact {props.moment_of_inertia_kg_m2:.9e} kg m^2/m, "
        f"raster {DENSITY * polar:.9e} kg m^2/m"
    )


if __name__ == "__main__":
    main()
