r"""Force chains by the criterion of Peters et al. (2005) (docs/fabric.md, "Force chains")."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from grainlab.analysis._compute import Compute, Computed
from grainlab.analysis._util import axial_direction
from grainlab.analysis.stress import GrainStress, branch_vectors
from grainlab.snapshot import Snapshot

__all__ = ["ForceChains"]


class ForceChains(Compute):
    """Force chains: highly stressed grains linked along their major principal directions,
    in chains of at least ``min_grains`` grains (docs/fabric.md, "Force chains").

    Parameters
    ----------
    angle : float, degrees, default 45
        Largest angle between the branch vector and each grain's major
        principal direction.
    min_grains : int, default 3
        Fewest grains in a chain.

    Example
    -------
    A loaded vertical column of 5 grains in a square lattice loaded at 1 % of it:

    >>> import numpy as np
    >>> from grainlab.snapshot import Snapshot
    >>> x, y = np.meshgrid(np.arange(5.0), np.arange(5.0))
    >>> snap = Snapshot.from_geometry(np.c_[x.ravel(), y.ravel()], np.full(25, 0.5), tolerance=1e-9)
    >>> n = snap.contact_normals()
    >>> column = (np.abs(n[:, 1]) > 0.99) & (snap.positions[snap.contact_i, 0] == 2.0)
    >>> chains = ForceChains().compute(snap.with_contacts(
    ...     snap.contact_i, snap.contact_j, normal_force=np.where(column, 100.0, 1.0)))
    >>> chains.n_chains, chains.lengths.tolist(), round(float(np.degrees(chains.orientations[0])), 9)
    (1, [5], 90.0)
    """

    _parameters = ("angle", "min_grains")

    def __init__(self, angle: float = 45.0, min_grains: int = 3) -> None:
        if not 0.0 <= angle <= 90.0:
            raise ValueError(f"angle: must be in [0, 90] degrees, got {angle!r}")
        if int(min_grains) != min_grains or min_grains < 2:
            raise ValueError(f"min_grains: must be an integer >= 2, got {min_grains!r}")
        self.angle = float(angle)
        self.min_grains = int(min_grains)

    def compute(self, snapshot: Snapshot, stress: GrainStress | None = None) -> ForceChains:
        """Find the chains of ``snapshot`` (with its grains' stress, computed here
        unless given); returns ``self``."""
        from scipy.sparse import coo_matrix
        from scipy.sparse.csgraph import connected_components

        grains = stress if stress is not None else GrainStress().compute(snapshot)
        n = snapshot.n_particles
        sample = snapshot.is_sample
        major = grains.major
        threshold = float(major[sample].mean()) if sample.any() else float("nan")
        # above the mean beyond round-off (grains loaded alike differ in the last bits)
        high = sample & (major > threshold + 1e-9 * abs(threshold))
        ci = np.asarray(snapshot.contact_i)
        cj = np.asarray(snapshot.contact_j)
        pp = ~snapshot.is_boundary_contact
        cjs = np.where(cj >= 0, cj, 0)
        branch = branch_vectors(snapshot)
        unit = branch / np.maximum(np.hypot(branch[:, 0], branch[:, 1]), 1e-300)[:, None]
        m = np.column_stack([np.cos(grains.major_direction), np.sin(grains.major_direction)])
        limit = np.cos(np.radians(self.angle)) - 1e-12
        aligned_i = np.abs(np.sum(unit * m[ci], axis=1)) >= limit
        aligned_j = np.abs(np.sum(unit * m[cjs], axis=1)) >= limit
        links = pp & high[ci] & high[cjs] & aligned_i & aligned_j
        graph = coo_matrix((np.ones(int(links.sum())), (ci[links], cjs[links])), shape=(n, n))
        _, label = connected_components(graph, directed=False)
        size = np.bincount(label, minlength=n)
        linked = np.zeros(n, bool)
        linked[ci[links]] = True
        linked[cjs[links]] = True
        member = linked & (size[label] >= self.min_grains)
        # chains numbered by decreasing length (then by their first grain)
        roots = np.unique(label[member])
        order = np.lexsort((roots, -size[roots]))
        number = np.full(label.max(initial=-1) + 1, -1, dtype=np.int64)
        number[roots[order]] = np.arange(roots.size)
        chain = np.where(member, number[label], -1).astype(np.int64)
        lengths = size[roots[order]].astype(np.int64)
        links &= chain[ci] >= 0
        theta = np.arctan2(unit[links, 1], unit[links, 0])
        k = chain[ci[links]]
        sums = np.bincount(k, weights=np.cos(2 * theta), minlength=roots.size) + 1j * np.bincount(
            k, weights=np.sin(2 * theta), minlength=roots.size
        )
        orientations = axial_direction(np.angle(sums))
        self._store(
            _snapshot=snapshot,
            major_stress=major,
            highly_stressed=high,
            links=links,
            chain=chain,
            lengths=lengths,
            orientations=orientations.astype(np.float64),
        )
        return self

    _snapshot = Computed[Snapshot]("The snapshot measured (drawn by plot).")
    chain = Computed[NDArray[np.int64]](
        "(N,) chain number of each grain (longest first), -1 outside chains."
    )
    lengths = Computed[NDArray[np.int64]]("(n_chains,) grains in each chain, longest first.")
    orientations = Computed[NDArray[np.float64]](
        "(n_chains,) axial mean direction of each chain's links, rad in [0, pi)."
    )

    @property
    def n_chains(self) -> int:
        """Number of chains."""
        return int(self.lengths.size)

    @property
    def mean_length(self) -> float:
        """Mean grains per chain (NaN without chains)."""
        return float(self.lengths.mean()) if self.lengths.size else float("nan")

    @property
    def fraction_in_chains(self) -> float:
        """Fraction of the sample grains that belong to a chain."""
        snap = self._snapshot
        sample = snap.is_sample
        return float((self.chain[sample] >= 0).mean()) if sample.any() else float("nan")

    @property
    def mean_orientation(self) -> float:
        """Axial mean of the chains' orientations weighted by their lengths, rad in [0, pi)."""
        if not self.lengths.size:
            return float("nan")
        s = np.sum(self.lengths * np.exp(2j * self.orientations))
        return float(axial_direction(np.angle(s)))

    major_stress = Computed[NDArray[np.float64]]("(N,) each grain's major principal stress, Pa.")
    highly_stressed = Computed[NDArray[np.bool_]](
        "(N,) grains with sigma_1 above the mean over the sample grains."
    )
    links = Computed[NDArray[np.bool_]]("(Nc,) the contacts joining two grains of one chain.")

    def summary(self) -> dict[str, float | int]:
        """The chains' numbers: count, mean and longest length, fraction of grains,
        mean orientation (degrees)."""
        return {
            "n_chains": self.n_chains,
            "mean_length": self.mean_length,
            "max_length": int(self.lengths.max(initial=0)),
            "fraction_in_chains": self.fraction_in_chains,
            "mean_orientation_deg": float(np.degrees(self.mean_orientation)),
        }

    def plot(self, ax: Any = None) -> Any:
        """The chains' links over the grains, one colour per chain; returns the axes."""
        from grainlab.plot import networks

        snap = self._snapshot
        links = self.links
        start = np.asarray(snap.positions)[np.asarray(snap.contact_i)[links]]
        k = self.chain[np.asarray(snap.contact_i)[links]]
        colours = [f"C{int(c) % 10}" for c in k]
        return networks.contact_network(
            start,
            start + branch_vectors(snap)[links],
            np.full(start.shape[0], 1.5),
            color=colours,
            positions=snap.positions,
            radii=snap.radii,
            ax=ax,
            title=f"{self.n_chains} force chains (Peters et al. 2005, {self.angle:g}°)",
        )
