"""Speed of the stability index and the fabric measures on large snapshots.

Goal: lambda and the fabric measures for 1,000,000 particles with 4
contacts each in under 2 s. The snapshot is a square lattice with jittered
positions (every particle has exactly 4 contacts, 2 contacts per particle),
normal forces on every contact; contact normals are computed from the
positions once (cached on the snapshot), as they would be for a file that
does not store them.

Prints, for each N, the median of ``--repeat`` runs of each measure and the
total, side by side.

    python benchmarks/analysis_speed.py                # N = 1e4, 1e5, 1e6
    python benchmarks/analysis_speed.py --sizes 1000000 --repeat 7
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable

import numpy as np

from grainlab.analysis import ContactAnisotropy, CoordinationNumber, StabilityIndex
from grainlab.snapshot import Snapshot


def square_lattice_snapshot(n_target: int, seed: int = 0) -> Snapshot:
    """~n_target particles on a periodic square lattice, 4 contacts each."""
    side = int(round(np.sqrt(n_target)))
    n = side * side
    rng = np.random.default_rng(seed)
    idx = np.arange(n).reshape(side, side)
    right = np.roll(idx, -1, axis=1)
    up = np.roll(idx, -1, axis=0)
    i = np.concatenate([idx.ravel(), idx.ravel()])
    j = np.concatenate([right.ravel(), up.ravel()])
    d = 1e-3
    yy, xx = np.divmod(np.arange(n), side)
    pos = np.c_[xx * d, yy * d] + rng.normal(0.0, 0.05 * d, (n, 2))
    box = [[-0.5 * d, (side - 0.5) * d], [-0.5 * d, (side - 0.5) * d]]
    return Snapshot(
        pos,
        np.full(n, 0.5 * d),
        contact_i=i,
        contact_j=j,
        normal_force=rng.uniform(0.0, 100.0, i.size),
        box=box,
        periodic=(True, True),
    )


def median_time(fn: Callable[[], object], repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[10_000, 100_000, 1_000_000])
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()

    measures: dict[str, Callable[[Snapshot], object]] = {
        "normals": lambda s: s.contact_angles(),
        "lambda": lambda s: StabilityIndex().compute(s),
        "Z + Zm": lambda s: CoordinationNumber().compute(s),
        "a (Eq.7+Fourier)": lambda s: ContactAnisotropy().compute(s),
        "a_n (forces)": lambda s: ContactAnisotropy(weight="normal_force").compute(s),
    }
    header = (
        f"{'N':>10} {'contacts':>10} "
        + " ".join(f"{name:>17}" for name in measures)
        + f" {'total':>9}"
    )
    print(f"median of {args.repeat} runs, seconds")
    print(header)
    for n in args.sizes:
        snap = square_lattice_snapshot(n)
        row = []
        for name, fn in measures.items():
            if name == "normals":
                # the first call computes and caches; time a fresh snapshot each run
                t = median_time(
                    lambda fn=fn, snap=snap: fn(square_lattice_snapshot_copy(snap)), args.repeat
                )
            else:
                fn(snap)  # warm-up (and cache the normals)
                t = median_time(lambda fn=fn, snap=snap: fn(snap), args.repeat)
            row.append(t)
        total = sum(row)
        print(
            f"{snap.n_particles:>10} {snap.n_contacts:>10} "
            + " ".join(f"{t:>17.3f}" for t in row)
            + f" {total:>9.3f}"
        )
        if snap.n_particles >= 1_000_000:
            verdict = "meets" if total < 2.0 else "misses"
            print(f"  -> {verdict} the 2 s goal for 1e6 particles (total {total:.2f} s)")


def square_lattice_snapshot_copy(snap: Snapshot) -> Snapshot:
    """Same data, empty cache (so contact normals are recomputed)."""
    return Snapshot(
        snap.positions,
        snap.radii,
        contact_i=snap.contact_i,
        contact_j=snap.contact_j,
        normal_force=snap.normal_force,
        box=snap.box,
        periodic=snap.periodic,
    )


if __name__ == "__main__":
    main()
