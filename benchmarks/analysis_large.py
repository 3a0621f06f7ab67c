"""Analysis of 1,024,000 disks from geometry: the NumPy path and the compiled kernels side by side.

The snapshot is the common throughput packing (``benchmarks/data/dense-4000-disks.xyr``:
4,000 dense disks in a periodic square cell, diameters 0.5-3 mm) tiled
``--tiles`` x ``--tiles`` times (16 x 16: 1,024,000 disks, about 2.1 million
contacts) into one periodic cell. Each repetition times, on fresh objects,

* detection: ``Snapshot.from_geometry`` (contacts with centre distance below
  the radius sum, periodic in x and y, tolerance 0);
* lambda: ``StabilityIndex().compute`` (contact normals and angles included);
* Z + a: ``CoordinationNumber().compute`` and ``ContactAnisotropy().compute``;

first with the NumPy reference implementations (the code before the kernels,
``grainlab._kernels.numpy_reference()``), then with the compiled kernels, and
checks that both give the same pairs, lambda, Z, Z_m and a. Medians of
``--repeat`` runs are printed side by side; the last line is one JSON object.

    python benchmarks/analysis_large.py                 # 16 x 16 tiles, 3 repeats
    python benchmarks/analysis_large.py --tiles 4 --repeat 5
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np

from grainlab import _kernels
from grainlab.analysis import ContactAnisotropy, CoordinationNumber, StabilityIndex
from grainlab.snapshot import Snapshot

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from throughput import PACKING, tiled_packing  # noqa: E402

STAGES = ("detection", "lambda", "Z + a")


def one_run(positions, radii, box) -> tuple[dict[str, float], dict[str, object]]:
    """Seconds per stage and the results, on a fresh snapshot."""
    seconds = {}
    start = time.perf_counter()
    snap = Snapshot.from_geometry(positions, radii, box=box, periodic=(True, True))
    seconds["detection"] = time.perf_counter() - start
    start = time.perf_counter()
    lam = StabilityIndex().compute(snap)
    seconds["lambda"] = time.perf_counter() - start
    start = time.perf_counter()
    z = CoordinationNumber().compute(snap)
    a = ContactAnisotropy().compute(snap)
    seconds["Z + a"] = time.perf_counter() - start
    seconds["total"] = sum(seconds[s] for s in STAGES)
    out = {
        "i": snap.contact_i,
        "j": snap.contact_j,
        "lambda": lam.stability_index,
        "Z": z.coordination_number,
        "Z_m": z.mechanical_coordination_number,
        "a": a.anisotropy,
        "theta_a": a.direction,
        "a_binned": a.anisotropy_binned,
    }
    return seconds, out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--tiles", type=int, default=16)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args(argv)
    if args.tiles < 1 or args.repeat < 1:
        parser.error("--tiles and --repeat must be >= 1")

    positions, radii, box = tiled_packing(args.tiles)
    print(
        f"{len(radii):,} disks ({PACKING.name} tiled {args.tiles} x {args.tiles}), "
        f"{os.cpu_count()} cores, {args.repeat} repetitions"
    )
    paths = {"numpy": _kernels.numpy_reference, "compiled": contextlib.nullcontext}
    samples: dict[str, dict[str, list[float]]] = {
        p: {s: [] for s in (*STAGES, "total")} for p in paths
    }
    last: dict[str, dict[str, object]] = {}
    for rep in range(args.repeat):
        for name, context in paths.items():  # alternate, so that machine noise hits both
            with context():
                seconds, last[name] = one_run(positions, radii, box)
            for stage, value in seconds.items():
                samples[name][stage].append(value)
            print(
                f"run {rep + 1} {name:>8}: "
                + "  ".join(f"{s} {seconds[s]:.3f}" for s in (*STAGES, "total")),
                flush=True,
            )

    old, new = last["numpy"], last["compiled"]
    same_pairs = np.array_equal(old["i"], new["i"]) and np.array_equal(old["j"], new["j"])
    lam_diff = float(np.max(np.abs(old["lambda"] - new["lambda"]), initial=0.0))
    print()
    print(
        f"contacts {new['i'].size:,} (same pairs: {same_pairs}); Z {new['Z']:.6f} / {old['Z']:.6f}, "
        f"Z_m {new['Z_m']:.6f} / {old['Z_m']:.6f}, a {new['a']:.12f} / {old['a']:.12f}, "
        f"max |lambda difference| {lam_diff:.1e}"
    )
    medians = {p: {s: statistics.median(v) for s, v in samples[p].items()} for p in paths}
    print(f"medians of {args.repeat} runs, seconds:")
    print(f"  {'stage':<10} {'NumPy':>8} {'compiled':>9} {'speed-up':>9}")
    for stage in (*STAGES, "total"):
        o, c = medians["numpy"][stage], medians["compiled"][stage]
        print(f"  {stage:<10} {o:>8.3f} {c:>9.3f} {o / c:>8.1f}x")
    print(json.dumps({"disks": len(radii), "contacts": int(new["i"].size), **medians}))
    agree = (
        same_pairs
        and lam_diff < 1e-12
        and new["Z"] == old["Z"]
        and new["Z_m"] == old["Z_m"]
        and abs(new["a"] - old["a"]) < 1e-12
    )
    if not agree:
        print("the two paths disagree", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
