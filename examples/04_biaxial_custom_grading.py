"""A biaxial test on a sample with your own grading, and the grading it really got.

The biaxial protocol (docs/biaxial.md) generates its sample from the grading
its configuration names: ``sample.grading`` (``paper``, ``uniform_by_number``,
``uniform_by_mass`` or ``curve``). Here it is a sieve table, the way a
laboratory reports a sand: ``sample.grading = "curve"`` with
``sample.sieve_sizes`` 0.8, 1.0, 1.4 and 2 mm passing 0, 20, 60 and 100 % by
mass (straight lines in log d between sieves), unlike the paper's 0.5-3 mm
sand. The script runs the test through the Python API
(``resolve`` + ``run_biaxial``, what ``grainlab biaxial --set ...`` does),
then reads the grains back from ``run.h5`` and compares their grading curve
(percent passing by mass, 2D mass ~ d^2) with the one asked for: D10, D30,
D50, D60, the uniformity and curvature coefficients, and the largest gap
between the two curves. It prints the peak stress ratio sigma_1 / sigma_3.

The radius expansion scales all drawn diameters by one factor so that the
porosity is exactly the target (docs/samples.md), so the sizes achieved
differ from the drawn ones by that factor, about 1 %.

Run it::

    python examples/04_biaxial_custom_grading.py            # 50 x 100 mm, 10 % strain, a few minutes
    python examples/04_biaxial_custom_grading.py --small    # 20 x 40 mm to 5 % strain, about 10 s
    python examples/04_biaxial_custom_grading.py --out DIR  # keep the results folder

The same from the command line::

    grainlab biaxial --set 'sample.grading="curve"' \
        --set 'sample.sieve_sizes=["0.8 mm", "1.0 mm", "1.4 mm", "2 mm"]' \
        --set 'sample.percent_passing=[0, 20, 60, 100]'
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np

from grainlab.io.hdf5 import read_results
from grainlab.protocols.biaxial import run_biaxial
from grainlab.protocols.biaxial.config import resolve
from grainlab.samples import GradingCurve
from grainlab.snapshot import ParticleKind

#: The grading asked for: a sieve table (sizes, percent passing by mass).
GRADING = {
    "sample.grading": "curve",
    "sample.sieve_sizes": ["0.8 mm", "1.0 mm", "1.4 mm", "2 mm"],
    "sample.percent_passing": [0, 20, 60, 100],
}

FULL = {"sample.width": "50 mm", "sample.height": "100 mm"}
SMALL = {
    "sample.width": "20 mm",  # at least 10 largest diameters (the configuration checks it)
    "sample.height": "40 mm",
    "shear.final_strain": "5 %",
    "shear.strain_rate": "20 %/min",  # ten times the paper's 2 %/min: a quick look
    "shear.snapshot_strains": [0.0, 0.01, 0.05],
}

#: Percent passing at which the characteristic sizes are read.
PERCENTS = (10, 30, 50, 60)


def passing_by_mass(diameters: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The grading curve of a set of disks: sizes (sorted) and percent of the
    mass finer than or equal to each (2D disks: mass ~ d^2)."""
    d = np.sort(np.asarray(diameters, dtype=np.float64))
    mass = d**2
    return d, 100.0 * np.cumsum(mass) / mass.sum()


def characteristic_sizes(d: np.ndarray, percent: np.ndarray) -> dict[int, float]:
    """D_x (m): the size that x % of the mass passes, by linear interpolation."""
    return {p: float(np.interp(p, percent, d)) for p in PERCENTS}


def coefficients(sizes: dict[int, float]) -> tuple[float, float]:
    """Uniformity Cu = D60 / D10 and curvature Cc = D30^2 / (D10 D60)."""
    return sizes[60] / sizes[10], sizes[30] ** 2 / (sizes[10] * sizes[60])


def main(out: Path, small: bool = False) -> dict[str, float]:
    overrides = {**GRADING, **(SMALL if small else FULL), "run.threads": 1}
    config = resolve(overrides=overrides)  # validated before any work: units, ranges, d_max vs box
    target = GradingCurve(config["sample.sieve_sizes"], config["sample.percent_passing"])
    print(
        f"grading asked for: {target.name}; sample {config['sample.width'] * 1e3:g} x "
        f"{config['sample.height'] * 1e3:g} mm, porosity {config['sample.porosity']:g}, "
        f"sheared to {100 * config['shear.final_strain']:g} % axial strain"
    )

    result = run_biaxial(config, out, progress=False)
    summary = result.summary
    print(result.one_line())

    # the grains at the start of shearing (membrane disks are not part of the sample)
    snap = read_results(out / "run.h5").snapshot(0)
    grains = np.asarray(snap.kind) == ParticleKind.SOIL
    d, percent = passing_by_mass(2.0 * np.asarray(snap.radii)[grains])

    # the target curve, read at the same percentages
    fine = np.linspace(target.d_min, target.d_max, 2001)
    wanted = characteristic_sizes(fine, np.asarray(target.passing(fine)))
    got = characteristic_sizes(d, percent)
    # largest vertical gap between the curves, in percentage points
    gap = float(np.max(np.abs(percent - np.asarray(target.passing(d)))))

    print(f"{'':>6} {'target (mm)':>12} {'achieved (mm)':>14} {'ratio':>7}")
    for p in PERCENTS:
        print(f"{f'D{p}':>6} {wanted[p] * 1e3:12.3f} {got[p] * 1e3:14.3f} {got[p] / wanted[p]:7.3f}")
    cu_t, cc_t = coefficients(wanted)
    cu, cc = coefficients(got)
    print(f"Cu = D60/D10: target {cu_t:.3f}, achieved {cu:.3f}")
    print(f"Cc = D30^2/(D10 D60): target {cc_t:.3f}, achieved {cc:.3f}")
    print(f"largest gap between the grading curves: {gap:.1f} percentage points ({grains.sum()} grains)")
    print(
        f"peak stress ratio sigma1/sigma3 = {summary['peak_stress_ratio']:.3f} at "
        f"{100 * summary['axial_strain_at_peak']:.2f} % axial strain (compression positive)"
    )
    return {
        "peak_stress_ratio": summary["peak_stress_ratio"],
        "axial_strain_at_peak": summary["axial_strain_at_peak"],
        "n_grains": int(grains.sum()),
        "d_min": float(d[0]),
        "d_max": float(d[-1]),
        "target_d_min": target.d_min,
        "target_d_max": target.d_max,
        "max_curve_gap_percent": gap,
        **{f"D{p}": got[p] for p in PERCENTS},
        **{f"target_D{p}": wanted[p] for p in PERCENTS},
        "Cu": cu,
        "target_Cu": cu_t,
    }


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--small", action="store_true", help="20 x 40 mm to 5 %% strain (tests)")
    parser.add_argument("--out", type=Path, default=None, help="results folder (default: a new temporary one)")
    args = parser.parse_args()
    main(args.out or Path(tempfile.mkdtemp(prefix="grainlab_biaxial_")) / "run", small=args.small)
