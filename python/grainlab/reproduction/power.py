"""How many seeds a band-against-rest claim needs: a power estimate from the first seeds.

``python -m grainlab.reproduction.power [CAMPAIGN] [CLAIM ...]`` prints the table
(docs/reproduction.md, "How many seeds").
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Sequence

import numpy as np
from scipy import stats

__all__ = ["interval_half_width", "power_to_exclude_zero", "probability_within", "seed_table"]


def interval_half_width(sd: float, n: int) -> float:
    """Half-width of the 95 % t-interval of a mean of ``n`` values of standard deviation ``sd``."""
    if n < 2:
        raise ValueError(f"n: a t-interval needs at least 2 values, got {n}")
    return float(stats.t.ppf(0.975, n - 1) * sd / math.sqrt(n))


def power_to_exclude_zero(sd: float, effect: float, n: int) -> float:
    """Probability that the 95 % t-interval of ``n`` seeds lies above 0 when the
    true mean is ``effect`` and the per-seed standard deviation ``sd``."""
    if n < 2:
        raise ValueError(f"n: a t-interval needs at least 2 values, got {n}")
    if not sd > 0:
        raise ValueError(f"sd: expected a positive standard deviation, got {sd}")
    t = stats.t.ppf(0.975, n - 1)
    return float(stats.nct.sf(t, n - 1, effect * math.sqrt(n) / sd))


def probability_within(sd: float, width: float, n: int, *, samples: int = 20000, seed: int = 0) -> float:
    """Probability that the 95 % t-interval of ``n`` seeds lies inside ``+-width``
    when the true mean is 0 (normal seeds, ``samples`` draws)."""
    if n < 2:
        raise ValueError(f"n: a t-interval needs at least 2 values, got {n}")
    draws = np.random.default_rng(seed).normal(0.0, sd, (samples, n))
    half = stats.t.ppf(0.975, n - 1) * draws.std(axis=1, ddof=1) / math.sqrt(n)
    return float(np.mean(np.abs(draws.mean(axis=1)) + half <= width))


def seed_table(per_seed: Sequence[float | None], counts: Sequence[int], *, effects: Sequence[float],
               width: float) -> list[dict[str, float]]:
    """One row per ensemble size in ``counts``: the half-width, the power to exclude 0
    at each of ``effects`` and the chance of lying within ``+-width`` at 0, with the
    standard deviation of the finite ``per_seed`` values."""
    values = np.array([v for v in per_seed if v is not None and math.isfinite(v)], dtype=np.float64)
    if values.size < 2:
        raise ValueError(f"per_seed: a standard deviation needs at least 2 values, got {values.size}")
    sd = float(values.std(ddof=1))
    rows = []
    for n in counts:
        row = {"n": float(n), "sd": sd, "half_width": interval_half_width(sd, n)}
        for effect in effects:
            row[f"power_{effect:g}"] = power_to_exclude_zero(sd, effect, n)
        row[f"within_{width:g}"] = probability_within(sd, width, n)
        rows.append(row)
    return rows


def main(argv: Sequence[str] | None = None) -> int:
    from grainlab.reproduction.stored import CAMPAIGNS, stored_claims

    parser = argparse.ArgumentParser(prog="python -m grainlab.reproduction.power", description=__doc__.splitlines()[0])
    parser.add_argument("campaign", nargs="?", default="main", choices=CAMPAIGNS)
    parser.add_argument("claims", nargs="*", default=["band_lambda_above_rest_all", "band_lambda_above_rest"])
    parser.add_argument("--seeds", type=int, nargs="+", default=[5, 10, 12, 15, 16, 20, 25, 30])
    parser.add_argument("--first", type=int, default=5, help="use the first N seeds' values (default 5)")
    args = parser.parse_args(argv)
    doc = stored_claims(args.campaign)
    if not doc:
        parser.error(f"no stored campaign {args.campaign!r}")
    rows = {r["id"]: r for r in doc["claims"]}
    for claim in args.claims:
        if claim not in rows:
            parser.error(f"{claim!r}: not a claim of {args.campaign!r}")
        values = rows[claim]["per_seed"][: args.first]
        table = seed_table(values, args.seeds, effects=(0.03, 0.022, 0.015), width=0.015)
        finite = [v for v in values if v is not None]
        print(f"{claim}: {len(finite)} seeds, mean {np.mean(finite):+.4f}, sd {table[0]['sd']:.4f}")
        print("   n  half-width  P(>0 | 0.03)  P(>0 | 0.022)  P(>0 | 0.015)  P(within +-0.015 | 0)")
        for r in table:
            print(f"  {int(r['n']):2d}  {r['half_width']:10.4f}  {r['power_0.03']:12.2f}  {r['power_0.022']:13.2f}"
                  f"  {r['power_0.015']:13.2f}  {r['within_0.015']:21.2f}")
    return 0


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
