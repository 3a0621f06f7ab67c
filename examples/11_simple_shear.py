"""Periodic simple shear from Python: the quick cell (about 280 grains) sheared
to 100 % strain at constant normal stress and, from a looser sample (made and
consolidated with friction), at constant volume; the effective friction
mu = tau / sigma_n at its peak and in the steady state, the dilation or the
normal stress it ends with, and the Rothenburg-Bathurst residual
(docs/protocols.md, "Periodic simple shear").
Run it: ``python examples/11_simple_shear.py [out_dir]`` (about 40 s).
"""

import sys
from pathlib import Path

from grainlab.protocols.registry import resolve_config
from grainlab.protocols.simple_shear import run_simple_shear

out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path("simple_shear")
LOOSE = {"sample.porosity": 0.24, "sample.generation_friction": 0.9, "consolidation.friction": 0.9}
for volume in ("free", "constant"):
    overrides = {"simple_shear.volume": volume, **(LOOSE if volume == "constant" else {})}
    config = resolve_config("simple_shear", overrides=overrides, quick=True)
    folder = out / volume
    result = run_simple_shear(config, folder, resume=(folder / "checkpoint.h5").exists())
    s = result.summary
    end = (f"dilation {-100 * s['volumetric_strain_final']:.2f} %" if volume == "free"
           else f"sigma_n {s['normal_stress_set_pa'] / 1e3:.1f} -> {s['normal_stress_final_pa'] / 1e3:.1f} kPa")
    print(f"{volume} volume: peak mu {s['friction_coefficient_peak']:.3f}, steady mu "
          f"{s['friction_coefficient_steady']:.3f}, {end}, Rothenburg-Bathurst mean |residual| "
          f"{s['rb_residual_mean_abs']:.3f}")
