"""examples/14_clumps.py runs: its pile of trimers rests on the walls, no contact
lies inside a clump, and its snapshot and ParaView file know the grains."""

from __future__ import annotations

import re
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "14_clumps.py"


def test_the_clumps_example_settles_a_pile_of_trimers(tmp_path):
    out = subprocess.run(
        [sys.executable, str(EXAMPLE), "8", "0.25", "--vtk", str(tmp_path)], capture_output=True, text=True, check=True
    ).stdout
    carried, weight = map(float, re.search(r"walls carry (\S+) N of the (\S+) N weight", out).groups())
    assert abs(carried / weight - 1) < 1e-4, out
    assert re.search(r"contacts between clumps, 0 inside one", out), out
    assert "the snapshot has 8 grains; grain of pebbles 0-5: [0, 0, 0, 1, 1, 1]" in out
    pairs, contacts = map(float, re.search(r"per body, walls counted: Z = (\S+) \(touching pairs\), Z_c = (\S+)", out).groups())
    assert 0 < pairs <= contacts, out
    assert (tmp_path / "pile.vtp").is_file()
    clumps = ET.parse(tmp_path / "pile_clumps.vtp").getroot().find("PolyData/Piece")
    assert clumps is not None and clumps.get("NumberOfPoints") == "8"  # one point per trimer
