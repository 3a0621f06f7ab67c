r"""The stability index lambda against the force network, the force chains,
the local porosity and the contact loops, at a biaxial run's peak.

What is measured and how: docs/fabric.md, "Lambda, the force network and the voids";
``python -m grainlab.postprocess.lambda_fabric RUN_DIR FIGURE`` prints and draws it.
"""

from __future__ import annotations

import json
import sys
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from grainlab.analysis import (
    ContactLoops,
    ForceChains,
    ForceNetworks,
    LocalPorosity,
    StabilityIndex,
)
from grainlab.io.results import json_safe
from grainlab.snapshot import Snapshot

__all__ = ["Group", "LambdaFabric", "lambda_against_fabric", "lambda_fabric_figure", "run_lambda_fabric"]

#: Edges of the loop-size groups (the mean size of a grain's loops).
LOOP_EDGES = (3.5, 4.5, 5.5)


@dataclass(frozen=True)
class Group:
    """Lambda over one group of grains: its label, count, mean and standard error."""

    label: str
    count: int
    mean: float
    error: float


def _group(label: str, values: NDArray[np.float64]) -> Group:
    n = int(values.size)
    mean = float(values.mean()) if n else float("nan")
    error = float(values.std(ddof=1) / np.sqrt(n)) if n > 1 else float("nan")
    return Group(label, n, mean, error)


@dataclass(frozen=True)
class LambdaFabric:
    """The groups and correlations of :func:`lambda_against_fabric` (docs/fabric.md)."""

    n_grains: int
    mean_lambda: float
    strong: Group
    weak: Group
    in_chains: Group
    outside_chains: Group
    porosity: list[Group]
    porosity_edges: list[float]
    loops: list[Group]
    spearman_porosity: float
    spearman_loop_size: float
    spearman_radius: float
    spearman_radius_porosity: float
    snapshot: str = ""
    axial_strain: float = float("nan")

    def as_dict(self) -> dict[str, Any]:
        """Everything by name, NaN as None (JSON)."""
        out: dict[str, Any] = json_safe(asdict(self))
        return out


def lambda_against_fabric(snapshot: Snapshot) -> LambdaFabric:
    """The groups of lambda of ``snapshot`` (which needs contact forces)."""
    from scipy.stats import spearmanr

    stability = StabilityIndex().compute(snapshot)
    networks = ForceNetworks().compute(snapshot)
    chains = ForceChains().compute(snapshot)
    porosity = LocalPorosity().compute(snapshot).local_porosity
    loop = ContactLoops().compute(snapshot).grain_loop_size
    lam = stability.stability_index
    grains = snapshot.is_sample & (stability.n_contacts >= 2) & np.isfinite(lam)
    strong = networks.in_strong_network
    chained = chains.chain >= 0
    valued = grains & np.isfinite(porosity)
    edges = np.quantile(porosity[valued], np.linspace(0.0, 1.0, 6))
    bin_of = np.clip(np.searchsorted(edges, porosity, side="right") - 1, 0, 4)
    porosity_groups = [
        _group(f"{edges[k]:.2f}-\n{edges[k + 1]:.2f}", lam[valued & (bin_of == k)])
        for k in range(5)
    ]
    on_loops = grains & np.isfinite(loop)
    loop_bin = np.searchsorted(np.asarray(LOOP_EDGES), np.where(np.isfinite(loop), loop, 0.0))
    loop_groups = [
        _group(name, lam[on_loops & (loop_bin == k)])
        for k, name in enumerate(("~3", "~4", "~5", ">5.5"))
    ]
    loop_groups.append(_group("none", lam[grains & ~np.isfinite(loop)]))
    rho_porosity = float(spearmanr(lam[valued], porosity[valued]).statistic)
    rho_loop = float(spearmanr(lam[on_loops], loop[on_loops]).statistic)
    radius = np.asarray(snapshot.radii)
    rho_radius = float(spearmanr(lam[grains], radius[grains]).statistic)
    rho_radius_porosity = float(spearmanr(radius[valued], porosity[valued]).statistic)
    return LambdaFabric(
        n_grains=int(grains.sum()),
        mean_lambda=float(lam[grains].mean()),
        strong=_group("strong", lam[grains & strong]),
        weak=_group("weak", lam[grains & ~strong]),
        in_chains=_group("in chains", lam[grains & chained]),
        outside_chains=_group("not in chains", lam[grains & ~chained]),
        porosity=porosity_groups,
        porosity_edges=[float(e) for e in edges],
        loops=loop_groups,
        spearman_porosity=rho_porosity,
        spearman_loop_size=rho_loop,
        spearman_radius=rho_radius,
        spearman_radius_porosity=rho_radius_porosity,
    )


def run_lambda_fabric(run_dir: str | Path) -> LambdaFabric:
    """:func:`lambda_against_fabric` of the snapshot nearest the stress-ratio peak of the
    run in ``run_dir`` (its ``run.h5``)."""
    from dataclasses import replace

    from grainlab.postprocess.biaxial import analyse_run

    peak = analyse_run(run_dir).states["peak"]
    return replace(lambda_against_fabric(peak.snap), snapshot=peak.name, axial_strain=peak.strain)


def lambda_fabric_figure(result: LambdaFabric, path: str | Path) -> list[Path]:
    """Four panels of mean lambda (with standard errors and counts): strong/weak,
    chains, local porosity quintiles, loop sizes; written as PNG + SVG at ``path``."""
    from grainlab import plot
    from grainlab.plot import networks

    def panel(title: str, groups: list[Group]) -> tuple[str, list[str], Any, Any, Any]:
        return (
            title,
            [g.label for g in groups],
            [g.mean for g in groups],
            [g.error for g in groups],
            [g.count for g in groups],
        )

    figure = networks.grouped_means(
        [
            panel("force network", [result.strong, result.weak]),
            panel("force chains", [result.in_chains, result.outside_chains]),
            panel("local porosity (quintiles)", result.porosity),
            panel("mean loop size", result.loops),
        ],
        ylabel=r"mean $\lambda$",
        reference=result.mean_lambda,
    )
    return plot.save_figure(figure, path)


def main(argv: list[str] | None = None) -> int:
    """``python -m grainlab.postprocess.lambda_fabric RUN_DIR FIGURE``."""
    args = sys.argv[1:] if argv is None else argv
    if len(args) != 2:
        print("usage: python -m grainlab.postprocess.lambda_fabric RUN_DIR FIGURE", file=sys.stderr)
        return 2
    result = run_lambda_fabric(args[0])
    lambda_fabric_figure(result, args[1])
    print(json.dumps(result.as_dict(), indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
