"""A strain rate whose density scaling factor (paper Eq. 16) exceeds 1e-3 is
warned about before any work (docs/biaxial.md, docs/contact-law.md)."""

from __future__ import annotations

import math
import warnings

import pytest

from grainlab.protocols.biaxial import DensityScalingWarning, check_density_scaling, run_biaxial
from grainlab.protocols.biaxial.config import resolve


def eq16(rate: float, density: float, radius: float, pressure: float) -> float:
    # paper Eq. 16: I = rate * sqrt(rho r_min^2 / p_y), p_y the limiting contact pressure
    return rate * radius * math.sqrt(density / pressure)


def test_factor_is_eq16_of_the_smallest_grain_and_quiet_below_the_limit():
    config = resolve(overrides=["shear.strain_rate=0.01"])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        factor = check_density_scaling(config)
    assert factor == pytest.approx(eq16(0.01, 2.0e8, 0.25e-3, 150.0e6), rel=1e-12)  # Table 1 p_y
    assert check_density_scaling(resolve(overrides=["shear.strain_rate=auto"])) is None  # bounded by construction
    # the default is the paper's 2 %/min, far below the limit
    assert check_density_scaling(resolve()) == pytest.approx(eq16(0.02 / 60, 2.0e8, 0.25e-3, 150.0e6), rel=1e-12)


def test_fast_rate_is_warned_about_before_any_work(tmp_path):
    # with Table 1's p_y every rate above the limit is refused as too fast for the records
    # (tests/reliability/test_run_limits.py); a softer p_y brings the limit within reach
    config = resolve(overrides=["shear.strain_rate=0.4", "material.limiting_contact_pressure=1 MPa"])
    assert eq16(0.4, 2.0e8, 0.25e-3, 1.0e6) > 1e-3
    (tmp_path / "run.h5").write_bytes(b"")  # a folder that holds a run: refused right after the check
    with pytest.warns(DensityScalingWarning, match=r"Eq\. 16\) of 1\.4e-03"), pytest.raises(ValueError):
        run_biaxial(config, tmp_path, progress=False)


def test_limiting_contact_pressure_is_a_key_with_the_paper_value():
    assert resolve()["material.limiting_contact_pressure"] == 150.0e6
    config = resolve(overrides=["shear.strain_rate=0.01", "material.limiting_contact_pressure=1 MPa"])
    assert check_density_scaling(config) == pytest.approx(eq16(0.01, 2.0e8, 0.25e-3, 1.0e6), rel=1e-12)
