"""examples/16_crushable_grains.py runs: one agglomerate built, eight crushed, each
strength the peak force over the diameter, and a Weibull fit of them."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "16_crushable_grains.py"


def test_the_agglomerates_are_crushed_and_their_strengths_fitted():
    out = subprocess.run([sys.executable, str(EXAMPLE)], capture_output=True, text=True, check=True).stdout
    assert re.search(r"one agglomerate of 1.4 mm: \d+ disks, \d+ bonds", out), out
    rows = re.findall(r"agglomerate \d: F_max (\S+) N/m at \S+ % of d, sigma_f (\S+) kPa, (\w+)", out)
    assert len(rows) == 8, out
    for force, strength, mode in rows:  # sigma_f = F_max / (d t), d = 1.4 mm, t = 1 m
        assert abs(float(force) / 1.4e-3 / 1e3 - float(strength)) <= 0.1 + 1e-3 * float(strength), out
        assert mode in ("split", "fragmented", "unfailed")
    m = float(re.search(r"Weibull modulus m = (\S+) ", out).group(1))
    assert 1.0 < m < 20.0, out
