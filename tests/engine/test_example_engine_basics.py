"""examples/01_engine_basics.py runs and its settled pile is in equilibrium."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "01_engine_basics.py"


def test_engine_basics_example_settles_a_pile():
    out = subprocess.run([sys.executable, str(EXAMPLE), "10"], capture_output=True, text=True, check=True).stdout
    carried, weight = map(float, re.search(r"walls carry (\S+) N of the (\S+) N weight", out).groups())
    # static equilibrium: the walls carry the weight of the pile
    assert abs(carried / weight - 1) < 0.02, out
