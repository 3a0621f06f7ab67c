"""A custom sample: your own grading curve, box and porosity, made by radius expansion.

Builds a grading from a sieve table, generates a small sample inside rigid
walls by radius expansion (the paper's procedure, Table 1 contact properties),
prints where the sample really is (both porosity readings, the locked-in wall
stress, the coordination number), then makes a hexagonal lattice for
comparison. Runs in a second or two.

Run it: ``python examples/03_custom_sample.py [porosity]``.
"""

from __future__ import annotations

import sys

from grainlab.samples import (
    GradingCurve,
    expand_to_porosity,
    hexagonal_lattice,
    particle_count,
)


def main(porosity: float = 0.14) -> dict[str, float]:
    # a sieve table (sizes in m, percent passing by mass), straight lines on a semi-log chart
    grading = GradingCurve(
        [0.5e-3, 0.8e-3, 1.2e-3, 2.0e-3, 3.0e-3],
        [0, 15, 40, 80, 100],
        name="example sand",
    )
    box = (0.0, 0.0, 0.02, 0.04)  # 20 x 40 mm
    area = (box[2] - box[0]) * (box[3] - box[1])
    print(f"grading: {grading.name}, {grading.passing(1.2e-3):.0f}% of the mass finer than 1.2 mm")
    print(f"particle count for porosity {porosity}: {particle_count(area, porosity, grading)}")

    sample = expand_to_porosity(box, porosity, grading, seed=7, progress=False)
    print(sample.summary())
    print(f"porosity nominal {sample.porosity:.4f}")
    print(f"porosity overlap-corrected {sample.porosity_overlap_corrected:.4f}")
    print(f"coordination number {sample.coordination_number:.3f}")
    print(f"mean wall stress {sample.mean_wall_stress_pa / 1e3:.1f} kPa")
    print(
        "wall stresses (bottom, right, top, left): "
        + ", ".join(f"{s / 1e3:.1f}" for s in sample.wall_stresses_pa)
        + " kPa"
    )

    lattice = hexagonal_lattice(1.75e-3, porosity, box=box)
    print(f"hexagonal lattice: {lattice.note}")
    return {
        "porosity": sample.porosity,
        "porosity_overlap_corrected": sample.porosity_overlap_corrected,
        "coordination_number": sample.coordination_number,
        "mean_wall_stress_pa": sample.mean_wall_stress_pa,
        "lattice_porosity": lattice.porosity,
    }


if __name__ == "__main__":
    main(float(sys.argv[1]) if len(sys.argv) > 1 else 0.14)
