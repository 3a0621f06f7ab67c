"""Crushable grains: agglomerates of bonded disks crushed one by one between two
platens, and the Weibull statistics of their strengths.

Run: python examples/16_crushable_grains.py [agglomerates]

An agglomerate is a grain of disks on a hexagonal lattice in its circle, turned and
shifted at random, a few sites left empty and the disks' sizes scattered, every two
lattice neighbours bonded (grainlab.samples.agglomerate, docs/cemented.md, "Crushable
grains"). The crushing test (grainlab.protocols.crushing) crushes each between two
platens until it splits; its strength is sigma_f = F_max / (d t), t = 1 m, and the
strengths of all give the Weibull modulus m and sigma_0 (P_s = exp(-(sigma/sigma_0)^m)).
"""

from __future__ import annotations

import sys
import tempfile

import numpy as np

from grainlab.protocols.crushing import run_crushing
from grainlab.protocols.registry import resolve_config
from grainlab.samples.agglomerate import BondStrengths, build_agglomerate

D = 1.4e-3  # m, the agglomerates' diameter


def main(agglomerates: int = 8) -> None:
    grain = build_agglomerate(D, 0.2e-3, np.random.default_rng(1), strengths=BondStrengths(1e6, 1e6, 0.2))
    print(f"one agglomerate of {D * 1e3:g} mm: {grain.n_disks} disks, {grain.n_bonds} bonds")
    config = resolve_config("crushing", overrides=[f"crushing.agglomerates={agglomerates}", f"crushing.d_min={D}",
                                                   f"crushing.d_max={D}", "run.threads=1"])
    with tempfile.TemporaryDirectory() as folder:
        summary = run_crushing(config, folder).summary
    for a in summary["agglomerates"]:
        print(f"agglomerate {a['agglomerate']}: F_max {a['peak_force_n']:.1f} N/m at {100 * a['axial_strain_at_peak']:.2f} % "
              f"of d, sigma_f {a['strength_pa'] / 1e3:.1f} kPa, {a['mode']} ({a['fragments']} fragments)")
    w = summary["weibull"]
    if w is None:
        print("no Weibull fit: fewer than 3 agglomerates failed")
        return
    print(f"Weibull modulus m = {w['modulus']:.2f} (95 % {w['modulus_interval'][0]:.2f} to "
          f"{w['modulus_interval'][1]:.2f}), sigma_0 = {w['scale'] / 1e3:.0f} kPa, R^2 = {w['r_squared']:.3f}")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 8)
