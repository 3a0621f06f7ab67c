"""examples/04_biaxial_custom_grading.py, run small: the sample has the grading
asked for, and the test behaves like a dense granular soil."""

from __future__ import annotations

import contextlib
import io
import re
import runpy
from pathlib import Path

import numpy as np
import pytest

from grainlab.io.hdf5 import read_results
from grainlab.snapshot import ParticleKind

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "04_biaxial_custom_grading.py"


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    out = tmp_path_factory.mktemp("example04") / "run"
    module = runpy.run_path(str(EXAMPLE), run_name="example")
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        result = module["main"](out, small=True)
    return out, result, printed.getvalue()


def test_generated_sample_has_the_requested_grading(run):
    out, result, text = run
    d_min, d_max = 0.8e-3, 2.0e-3  # the example's sieve table: 0.8, 1.0, 1.4, 2 mm pass 0, 20, 60, 100 %
    # Independent reading of run.h5: the grains' diameters and their mass (2D: ~ d^2).
    snap = read_results(out / "run.h5").snapshot(0)
    d = 2.0 * np.asarray(snap.radii)[np.asarray(snap.kind) == ParticleKind.SOIL]
    assert d.size == result["n_grains"] > 400
    # Every size lies in the requested range, up to the expansion's common radius factor (~1 %).
    assert d.min() >= 0.97 * d_min and d.max() <= 1.03 * d_max
    # Mass-weighted median, from the sorted cumulative mass (not the example's interpolation).
    order = np.sort(d)
    cum = np.cumsum(order**2) / np.sum(order**2)
    d50 = order[np.searchsorted(cum, 0.5)]
    # 50 % lies between the 1.0 mm (20 %) and 1.4 mm (60 %) sieves, straight in log d
    target_d50 = 1.0e-3 * 1.4 ** ((50 - 20) / (60 - 20))
    # Sampling scatter of a mass percentile with ~560 grains is about 2 %, the radius factor about 1 %.
    assert d50 == pytest.approx(target_d50, rel=0.05)
    assert result["D50"] == pytest.approx(d50, rel=0.01)
    for p in (10, 30, 50, 60):
        assert result[f"D{p}"] == pytest.approx(result[f"target_D{p}"], rel=0.05), p
    # the target sizes, read off the sieve table by hand (log-linear between sieves)
    expected = {10: 0.8e-3 * 1.25 ** 0.5, 30: 1.0e-3 * 1.4**0.25, 50: target_d50, 60: 1.4e-3}
    for p, size in expected.items():
        assert result[f"target_D{p}"] == pytest.approx(size, rel=2e-3), p
    # The whole curve: a Dvoretzky-Kiefer-Wolfowitz band at 99.9 % for ~560 draws is about
    # 8 percentage points (wider by mass, which weights the coarse grains); 10 leaves margin.
    assert result["max_curve_gap_percent"] < 10.0
    printed = float(re.search(r"D50\s+\S+\s+(\S+)", text).group(1))
    assert printed == pytest.approx(result["D50"] * 1e3, abs=1e-3)


def test_biaxial_response_is_that_of_a_dense_soil(run):
    out, result, text = run
    ts = read_results(out / "run.h5").timeseries
    ratio, eps = ts["stress_ratio"], ts["axial_strain"]
    # isotropic at the start of shearing: the membrane carries sigma_3 = sigma_0 and the
    # platens hold sigma_1 within consolidation.tolerance (1 %) of it (without their servo
    # in the boundary phase this small sample started at 1.11)
    assert ratio[0] == pytest.approx(1.0, abs=0.011)
    # a peak well above 1 inside the run, then softening
    peak = int(np.argmax(ratio))
    assert result["peak_stress_ratio"] == pytest.approx(ratio[peak])
    assert result["peak_stress_ratio"] > 2.0
    assert 0.003 < result["axial_strain_at_peak"] < eps[-1]
    assert ratio[-1] < ratio[peak]
    printed = float(re.search(r"peak stress ratio sigma1/sigma3 = (\S+)", text).group(1))
    assert printed == pytest.approx(result["peak_stress_ratio"], abs=1e-3)
