"""The oedometer (K0) test from Python: a small sample loaded between fixed side
walls to 800 kPa and unloaded, K = sigma_h / sigma_v printed at each step, and
K0 on first loading beside Jaky's 1 - sin(phi') for phi' = 30 deg
(docs/protocols.md, "The oedometer (K0) test").
Run it: ``python examples/09_oedometer.py [out_dir]`` (about 10 s).
"""

import sys
from pathlib import Path

from grainlab.io.hdf5 import read_results
from grainlab.protocols.oedometer import run_oedometer
from grainlab.protocols.registry import resolve_config

out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path("oedometer")
config = resolve_config(
    "oedometer",
    overrides={"oedometer.vertical_stresses": ["200 kPa", "400 kPa", "800 kPa", "400 kPa", "200 kPa", "100 kPa"],
               "oedometer.friction_angle": "30 deg"},
    quick=True,  # 30 x 60 mm, 563 grains
)
result = run_oedometer(config, out, resume=(out / "checkpoint.h5").exists())
series = read_results(out / "run.h5").timeseries
for sigma_v, k, ocr in zip(series["vertical_stress_pa"], series["lateral_stress_ratio"],
                           series["overconsolidation_ratio"], strict=True):
    print(f"sigma_v {sigma_v / 1e3:7.1f} kPa: K {k:.3f} at OCR {ocr:.2f}")
print(result.one_line())
