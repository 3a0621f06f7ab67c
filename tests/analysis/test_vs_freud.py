"""The agreement check of ``benchmarks/analysis_vs_freud.py`` (grainlab against freud):
on the benchmark's own packing (4,000 disks) the two libraries find the same
contacts up to pairs touching to round-off, and the check catches a real
difference. Skipped when freud (``pip install freud-analysis``) is missing."""

from __future__ import annotations

import importlib
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("freud")

BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"


@pytest.fixture(scope="module")
def bench():
    saved = list(sys.path)  # the benchmark puts its folder on the path too
    sys.path.insert(0, str(BENCHMARKS))
    try:
        yield importlib.import_module("analysis_vs_freud")
    finally:
        sys.path[:] = saved


@pytest.fixture(scope="module")
def results(bench):
    pack = bench.packing(*bench.tiled_packing(1))
    snap = bench.grainlab_contacts(pack)
    nlist = bench.freud_contacts(pack)
    counts = (bench.grainlab_coordination(snap)[0], bench.freud_coordination(nlist)[0])
    return pack, snap, nlist, counts


def test_both_find_the_same_contacts_up_to_pairs_touching_to_round_off(bench, results):
    pack, snap, nlist, counts = results
    areas = (bench.grainlab_voronoi(pack), bench.freud_voronoi(pack))
    check = bench.agreement(pack, (snap.contact_i, snap.contact_j), nlist, counts, areas)
    assert check["ok"]
    assert check["pairs grainlab"] == 8328
    # freud's float32 decides a few exactly touching pairs differently, no other
    assert check["freud only"] + check["grainlab only"] <= 10
    assert check["largest |gap| of those, m"] < 1e-12
    assert check["largest |cell difference| / mean cell"] < 1e-4
    assert check["cells sum / box, grainlab"] == pytest.approx(1.0, abs=1e-12)


def test_the_check_catches_a_missing_contact_and_a_wrong_count(bench, results):
    pack, snap, nlist, (counts_g, counts_f) = results
    i, j = np.asarray(snap.contact_i), np.asarray(snap.contact_j)
    deepest = int(np.argmin(bench.pair_gaps(pack, i, j)))  # an overlap far beyond round-off
    dropped = (np.delete(i, deepest), np.delete(j, deepest))
    assert not bench.agreement(pack, dropped, nlist, (counts_g, counts_f))["ok"]
    wrong = counts_g.copy()
    wrong[i[deepest]] += 1
    assert not bench.agreement(pack, (i, j), nlist, (wrong, counts_f))["ok"]
    assert bench.agreement(pack, (i, j), nlist, (counts_g, counts_f))["ok"]
