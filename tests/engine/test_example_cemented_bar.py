"""examples/15_cemented_bar.py runs: the bar breaks first at its weakest section, in
tension, under a pulling force that section's bonds bound, and then parts."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "15_cemented_bar.py"


def test_the_cemented_bar_breaks_at_its_weakest_section():
    out = subprocess.run([sys.executable, str(EXAMPLE)], capture_output=True, text=True, check=True).stdout
    assert "57 bonds on 36 disks" in out, out  # 33 axial and 24 transverse touching pairs
    peak, lo, hi, carry = re.search(r"peak pulling force (\S+) N/m; the weakest section \(between columns (\d+) and "
                                    r"(\d+)\) can carry (\S+) N/m", out).groups()
    assert 0.3 * float(carry) < float(peak) <= float(carry), out
    first = float(re.search(r"the first was axial, in tension, at x = (\S+) mm", out).group(1))
    assert 2 * int(lo) < first < 2 * int(hi), out  # between the weakest section's two columns (2 mm apart)
    assert "the two halves parted" in out, out
