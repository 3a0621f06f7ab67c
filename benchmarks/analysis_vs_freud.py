"""Analysis of a large disk packing, grainlab and freud side by side.

freud (``pip install freud-analysis``; skipped with a one-line message when it
is missing) is the particle-analysis library of the simulation field. Both
analyse the same positions: the common throughput packing
(``benchmarks/data/dense-4000-disks.xyr``, 4,000 dense disks in a periodic
square cell, diameters 0.5-3 mm) tiled ``--tiles`` x ``--tiles`` times into
one periodic cell (16: 1,024,000 disks; 5: 100,000). The shared steps:

* contacts: the pairs with centre distance ``< r_i + r_j`` (tolerance 0),
  periodic in x and y. grainlab: ``Snapshot.from_geometry`` (the cell list of
  ``detect_contacts``). freud has one cut-off per query, so it queries a ball
  of the largest diameter (``AABBQuery``, ``mode="ball"``, to a
  ``NeighborList``) and keeps the pairs below their radius sum
  (``NeighborList.filter``); the filter is in freud's time.
* coordination: contacts per particle and Z. grainlab:
  ``CoordinationNumber().compute`` (which also gives Z_m, the rattlers and the
  count distribution); freud: ``NeighborList.neighbor_counts`` and its mean.
* Voronoi cells: freud's ``locality.Voronoi`` (voro++) is the Voronoi
  tessellation of the centres, which ignores the radii; grainlab's power
  cells (``analysis.tessellation.power_cells``) with every radius equal are the
  same tessellation, so both are timed on the centres.

grainlab's power cells with the real radii (the radical tessellation that
``LocalPorosity`` uses) are timed too; freud has no counterpart. Neither has a
counterpart of the other's remaining measures (λ, Z_m, the contact anisotropy
and fabric tensor are grainlab's; freud's ``order.Hexatic`` and
``order.Nematic`` describe other quantities).

freud gets the same positions in its own convention (untimed): (N, 3) with
z = 0, shifted to a box centred on the origin, and scaled by a power of two
(exact) so that the mean diameter is about 1: its 2D Voronoi runs voro++ in a
3D container whose thickness does not scale with the box, and with metres it
took 39 s for the 4,000 disks against 0.11 s at this scale. Each library runs
on ``--threads`` threads (grainlab's kernel pool, ``freud.parallel``); SciPy's
Qhull under grainlab's cells has one thread. Steps alternate between the two,
the first of the pair swapped every repetition; medians of ``--repeat`` runs.
After the runs the results are compared (``agreement``): the same pairs up to
exactly touching ones (freud stores positions and distances in float32, and
the packing has pairs touching to round-off), per-particle counts that differ
only at those pairs, cells that tile the box and agree to float32 precision.

    python benchmarks/analysis_vs_freud.py                 # 1,024,000 disks, 1 and 2 threads
    python benchmarks/analysis_vs_freud.py --tiles 5 --repeat 5 --threads 2
    python benchmarks/analysis_vs_freud.py --json vs_freud.json
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from grainlab import _kernels
from grainlab.analysis import CoordinationNumber
from grainlab.analysis.tessellation import power_cells
from grainlab.snapshot import Snapshot

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from throughput import PACKING, tiled_packing  # noqa: E402

SHARED = ("contacts", "coordination", "Voronoi cells")
GRAINLAB_ONLY = ("power cells",)


@dataclass(frozen=True)
class Packing:
    """One packing in grainlab's form and in freud's."""

    positions: np.ndarray  # (N, 2) m
    radii: np.ndarray  # (N,) m
    box: np.ndarray  # [[xlo, xhi], [ylo, yhi]] m
    scale: float  # freud length units per metre, a power of two
    freud_points: np.ndarray  # (N, 3), z = 0, box centred on the origin, freud units
    freud_radii: np.ndarray  # (N,) freud units

    @property
    def lengths(self) -> np.ndarray:
        return self.box[:, 1] - self.box[:, 0]


def packing(positions: np.ndarray, radii: np.ndarray, box: np.ndarray) -> Packing:
    """The packing, with its positions in freud's convention (module docstring)."""
    box = np.asarray(box, dtype=np.float64)
    lengths = box[:, 1] - box[:, 0]
    scale = 2.0 ** round(float(np.log2(1.0 / np.mean(2.0 * radii))))
    wrapped = np.mod(positions - box[:, 0], lengths)
    points = np.zeros((len(radii), 3))
    points[:, :2] = (wrapped - 0.5 * lengths) * scale
    return Packing(positions, radii, box, scale, points, radii * scale)


def freud_box(pack: Packing) -> Any:
    import freud

    lx, ly = pack.lengths * pack.scale
    return freud.box.Box(lx, ly, is2D=True)


# ----------------------------------------------------------------------------- the steps
def grainlab_contacts(pack: Packing) -> Snapshot:
    return Snapshot.from_geometry(pack.positions, pack.radii, box=pack.box, periodic=(True, True))


def freud_contacts(pack: Packing) -> Any:
    """freud's neighbour list of the contacts (both directions of each pair)."""
    import freud

    reach = 2.0 * float(pack.freud_radii.max())
    query = freud.locality.AABBQuery(freud_box(pack), pack.freud_points)
    nlist = query.query(
        pack.freud_points, {"mode": "ball", "r_max": reach * (1.0 + 1e-6), "exclude_ii": True}
    ).toNeighborList()
    r = pack.freud_radii
    nlist.filter(nlist.distances < r[nlist.query_point_indices] + r[nlist.point_indices])
    return nlist


def grainlab_coordination(snap: Snapshot) -> tuple[np.ndarray, float]:
    z = CoordinationNumber().compute(snap)
    return z.n_contacts, z.coordination_number


def freud_coordination(nlist: Any) -> tuple[np.ndarray, float]:
    counts = np.asarray(nlist.neighbor_counts)
    return counts, float(counts.mean())


def grainlab_voronoi(pack: Packing) -> np.ndarray:
    """Cell areas (N,) m^2 of the centres' Voronoi tessellation: power cells, radii equal."""
    equal = np.full(len(pack.radii), float(np.mean(pack.radii)))
    snap = Snapshot(pack.positions, equal, box=pack.box, periodic=(True, True))
    return power_cells(snap).area


def freud_voronoi(pack: Packing) -> np.ndarray:
    """Cell areas (N,) m^2 from freud's Voronoi (voro++) of the centres."""
    import freud

    voronoi = freud.locality.Voronoi()
    voronoi.compute((freud_box(pack), pack.freud_points))
    return np.asarray(voronoi.volumes, dtype=np.float64) / pack.scale**2


def grainlab_power_cells(snap: Snapshot) -> np.ndarray:
    return power_cells(snap).area


# ----------------------------------------------------------------------------- agreement
def pair_gaps(pack: Packing, i: np.ndarray, j: np.ndarray) -> np.ndarray:
    """Centre distance minus radius sum (float64, minimum image), m."""
    d = pack.positions[i] - pack.positions[j]
    d -= pack.lengths * np.round(d / pack.lengths)
    return np.hypot(d[:, 0], d[:, 1]) - pack.radii[i] - pack.radii[j]


def float32_reach(pack: Packing) -> float:
    """A bound, in m, on how far freud's float32 distances can put a pair from its
    float64 gap: a few units in the last place of the largest coordinate."""
    largest = float(np.abs(pack.freud_points).max())
    return 8.0 * float(np.finfo(np.float32).eps) * largest / pack.scale


def agreement(
    pack: Packing,
    contacts: tuple[np.ndarray, np.ndarray],
    nlist: Any,
    counts: tuple[np.ndarray, np.ndarray],
    areas: tuple[np.ndarray, np.ndarray] | None = None,
) -> dict[str, Any]:
    """Compare the two libraries' results; ``ok`` is True when they agree.

    ``contacts`` are grainlab's (i, j), ``nlist`` freud's neighbour list,
    ``counts`` (grainlab's, freud's) per-particle contacts, ``areas``
    (grainlab's, freud's) Voronoi cell areas. Pairs found by one library
    only must be touching to within freud's float32 resolution
    (:func:`float32_reach`), and the counts must differ by exactly those pairs.
    """
    n = len(pack.radii)
    gi, gj = (np.asarray(a, dtype=np.int64) for a in contacts)
    a = np.asarray(nlist.query_point_indices, dtype=np.int64)
    b = np.asarray(nlist.point_indices, dtype=np.int64)
    fi, fj = np.minimum(a, b), np.maximum(a, b)
    both_ways = bool(np.array_equal(np.sort(a * n + b), np.sort(b * n + a)))
    keys_g = gi * n + gj
    keys_f = np.unique(fi * n + fj)
    freud_only = np.setdiff1d(keys_f, keys_g)
    grainlab_only = np.setdiff1d(keys_g, keys_f)
    odd = np.concatenate([freud_only, grainlab_only])
    gaps = pair_gaps(pack, odd // n, odd % n)
    reach = float32_reach(pack)
    shift = np.zeros(n, dtype=np.int64)
    for keys, sign in ((freud_only, 1), (grainlab_only, -1)):
        shift += sign * np.bincount(keys // n, minlength=n)
        shift += sign * np.bincount(keys % n, minlength=n)
    counts_g, counts_f = counts
    out: dict[str, Any] = {
        "pairs grainlab": int(gi.size),
        "pairs freud": int(keys_f.size),
        "freud only": int(freud_only.size),
        "grainlab only": int(grainlab_only.size),
        "largest |gap| of those, m": float(np.abs(gaps).max(initial=0.0)),
        "float32 reach, m": reach,
        "Z grainlab": float(counts_g.mean()),
        "Z freud": float(counts_f.mean()),
    }
    ok = (
        both_ways
        and keys_f.size * 2 == a.size
        and bool(np.all(np.abs(gaps) <= reach))
        and bool(np.array_equal(np.asarray(counts_f, np.int64) - counts_g, shift))
    )
    if areas is not None:
        area_g, area_f = areas
        box_area = float(np.prod(pack.lengths))
        out["cells sum / box, grainlab"] = float(area_g.sum() / box_area)
        out["cells sum / box, freud"] = float(area_f.sum() / box_area)
        out["largest |cell difference| / mean cell"] = float(
            np.abs(area_g - area_f).max() / area_g.mean()
        )
        ok = (
            ok
            and abs(out["cells sum / box, grainlab"] - 1.0) < 1e-9
            and abs(out["cells sum / box, freud"] - 1.0) < 1e-5
            and out["largest |cell difference| / mean cell"] < 1e-3
        )
    out["ok"] = bool(ok)
    return out


# ----------------------------------------------------------------------------- the run
def timed(fn: Callable[[], Any]) -> tuple[float, Any]:
    start = time.perf_counter()
    result = fn()
    return time.perf_counter() - start, result


def one_repetition(pack: Packing, threads: int, grainlab_first: bool) -> tuple[dict, dict]:
    """Seconds per (library, step) and the results, the libraries alternating."""
    import freud

    freud.parallel.set_num_threads(threads)
    seconds: dict[tuple[str, str], float] = {}
    results: dict[str, Any] = {}
    with _kernels.kernel_threads(threads):
        steps: list[tuple[str, str, Callable[[], Any]]] = [
            ("grainlab", "contacts", lambda: grainlab_contacts(pack)),
            ("freud", "contacts", lambda: freud_contacts(pack)),
            (
                "grainlab",
                "coordination",
                lambda: grainlab_coordination(results["grainlab contacts"]),
            ),
            ("freud", "coordination", lambda: freud_coordination(results["freud contacts"])),
            ("grainlab", "Voronoi cells", lambda: grainlab_voronoi(pack)),
            ("freud", "Voronoi cells", lambda: freud_voronoi(pack)),
            ("grainlab", "power cells", lambda: grainlab_power_cells(results["grainlab contacts"])),
        ]
        if not grainlab_first:  # swap each shared pair
            for k in range(0, 6, 2):
                steps[k], steps[k + 1] = steps[k + 1], steps[k]
        for library, step, fn in steps:
            seconds[(library, step)], results[f"{library} {step}"] = timed(fn)
    return seconds, results


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--tiles", type=int, default=16, help="16: 1,024,000 disks; 5: 100,000")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--json", type=Path, help="also write the medians and checks here")
    args = parser.parse_args(argv)
    if args.tiles < 1 or args.repeat < 1 or min(args.threads) < 1:
        parser.error("--tiles, --repeat and --threads must be >= 1")
    try:
        import freud
    except ImportError:
        print("freud not found: nothing to compare (pip install freud-analysis)")
        return 0

    pack = packing(*tiled_packing(args.tiles))
    print(
        f"{len(pack.radii):,} disks ({PACKING.name} tiled {args.tiles} x {args.tiles}), "
        f"freud {freud.__version__}, {os.cpu_count()} cores, threads {args.threads}, "
        f"{args.repeat} repetitions; freud length unit 1/{pack.scale:g} m"
    )
    rows = [(lib, step) for step in SHARED for lib in ("grainlab", "freud")]
    rows += [("grainlab", step) for step in GRAINLAB_ONLY]
    samples = {t: {row: [] for row in rows} for t in args.threads}
    checks: dict[int, dict[str, Any]] = {}
    for rep in range(args.repeat):
        for threads in args.threads:
            seconds, results = one_repetition(pack, threads, grainlab_first=rep % 2 == 0)
            for row, value in seconds.items():
                samples[threads][row].append(value)
            print(
                f"run {rep + 1}, {threads} thread(s): "
                + "  ".join(f"{lib} {step} {seconds[(lib, step)]:.3f}" for lib, step in rows),
                flush=True,
            )
            if rep == 0:
                snap = results["grainlab contacts"]
                checks[threads] = agreement(
                    pack,
                    (snap.contact_i, snap.contact_j),
                    results["freud contacts"],
                    (results["grainlab coordination"][0], results["freud coordination"][0]),
                    (results["grainlab Voronoi cells"], results["freud Voronoi cells"]),
                )
            del results

    medians = {
        t: {f"{lib} {step}": statistics.median(v) for (lib, step), v in samples[t].items()}
        for t in args.threads
    }
    for threads in args.threads:
        print()
        print(f"agreement, {threads} thread(s): " + json.dumps(checks[threads]))
        print(f"medians of {args.repeat} runs, {threads} thread(s), seconds:")
        print(f"  {'step':<14} {'grainlab':>9} {'freud':>9} {'freud / grainlab':>17}")
        m = medians[threads]
        for step in SHARED:
            g, f = m[f"grainlab {step}"], m[f"freud {step}"]
            print(f"  {step:<14} {g:>9.3f} {f:>9.3f} {f / g:>16.2f}x")
        for step in GRAINLAB_ONLY:
            print(f"  {step:<14} {m[f'grainlab {step}']:>9.3f} {'-':>9}")
    summary = {
        "disks": len(pack.radii),
        "freud": freud.__version__,
        "repeat": args.repeat,
        "medians": {str(t): medians[t] for t in args.threads},
        "agreement": {str(t): checks[t] for t in args.threads},
    }
    print(json.dumps(summary))
    if args.json:
        args.json.write_text(json.dumps(summary, indent=2) + "\n")
    if not all(c["ok"] for c in checks.values()):
        print("grainlab and freud disagree beyond float32 round-off", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
