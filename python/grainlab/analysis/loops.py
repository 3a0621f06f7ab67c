r"""The loops of the contact network: cyclomatic number and minimal loops (docs/fabric.md,
"Loops of the contact network").
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from grainlab.analysis._compute import Compute, Computed
from grainlab.analysis.fabric import rattlers
from grainlab.snapshot import Snapshot

__all__ = ["ContactLoops"]


class ContactLoops(Compute):
    """Independent cycles (the cyclomatic number) and minimal loops (the bounded faces of
    the planar contact network): docs/fabric.md, "Loops of the contact network".

    Parameters
    ----------
    remove_rattlers : bool, default True
        Remove the rattlers (fewer than 2 contacts, iteratively) first.

    Example
    -------
    >>> import numpy as np
    >>> from grainlab.snapshot import Snapshot
    >>> x, y = np.meshgrid(np.arange(4.0), np.arange(4.0))
    >>> snap = Snapshot.from_geometry(np.c_[x.ravel(), y.ravel()], np.full(16, 0.5), tolerance=1e-9)
    >>> loops = ContactLoops().compute(snap)  # a 4 x 4 square patch: 9 squares
    >>> loops.cyclomatic_number, loops.loop_sizes.tolist()
    (9, [4, 4, 4, 4, 4, 4, 4, 4, 4])
    """

    _parameters = ("remove_rattlers",)

    def __init__(self, remove_rattlers: bool = True) -> None:
        self.remove_rattlers = bool(remove_rattlers)

    def compute(self, snapshot: Snapshot) -> ContactLoops:
        """Trace the loops of ``snapshot``'s contact graph; returns ``self``."""
        from scipy.sparse import coo_matrix
        from scipy.sparse.csgraph import connected_components

        n = snapshot.n_particles
        sample = snapshot.is_sample
        grain_grain = ~snapshot.is_boundary_contact
        ci = np.asarray(snapshot.contact_i)[grain_grain]
        cj = np.asarray(snapshot.contact_j)[grain_grain]
        keep = sample.copy()
        if self.remove_rattlers:
            keep &= ~rattlers(ci, cj, n, min_contacts=2, candidates=sample)
        edge = keep[ci] & keep[cj]
        ci, cj = ci[edge], cj[edge]
        d = snapshot.minimum_image(
            np.asarray(snapshot.positions)[cj] - np.asarray(snapshot.positions)[ci]
        )
        n_edges = int(ci.size)
        graph = coo_matrix((np.ones(n_edges), (ci, cj)), shape=(n, n))
        labels = connected_components(graph, directed=False)[1]
        n_components = int(np.unique(labels[keep]).size)
        cyclomatic = n_edges - int(keep.sum()) + n_components
        # half-edges: h < E runs i -> j, h + E runs j -> i
        tail = np.concatenate([ci, cj])
        head = np.concatenate([cj, ci])
        direction = np.concatenate([d, -d])
        phi = np.arctan2(direction[:, 1], direction[:, 0])
        m = tail.size
        twin = np.concatenate([np.arange(n_edges, m), np.arange(n_edges)])
        order = np.lexsort((phi, tail))  # around each grain, counter-clockwise
        place = np.empty(m, dtype=np.int64)
        place[order] = np.arange(m)
        degree = np.bincount(tail, minlength=n)
        start = np.concatenate([[0], np.cumsum(degree)])[:-1]
        at = place[twin]  # the reverse half-edge v -> u in v's order
        v = head
        before = np.where(at > start[v], at - 1, start[v] + degree[v] - 1)
        following = order[before]
        faces = coo_matrix((np.ones(m), (np.arange(m), following)), shape=(m, m))
        n_faces, face = connected_components(faces, directed=False)
        turn = np.angle(np.exp(1j * (phi[following] - phi)))
        turn = np.where(np.isclose(np.abs(turn), np.pi), np.pi, turn)  # a U-turn turns left
        winding = np.bincount(face, weights=turn, minlength=n_faces)
        size = np.bincount(face, minlength=n_faces)
        bounded = winding > np.pi
        loop_sizes = size[bounded].astype(np.int64)
        on = bounded[face]
        total = np.bincount(tail[on], weights=size[face[on]], minlength=n)
        count = np.bincount(tail[on], minlength=n)
        with np.errstate(invalid="ignore", divide="ignore"):
            grain_loop = np.where(count > 0, total / count, np.nan)
        self._store(
            _snapshot=snapshot,
            in_graph=keep,
            cyclomatic_number=cyclomatic,
            loop_sizes=loop_sizes,
            grain_loop_size=grain_loop,
            n_edges=n_edges,
            n_components=n_components,
        )
        return self

    _snapshot = Computed[Snapshot]("The snapshot measured (drawn by plot).")
    cyclomatic_number = Computed[int]("L = E - V + C, the independent cycles of the graph used.")
    loop_sizes = Computed[NDArray[np.int64]]("(F,) the size of each minimal loop (bounded face).")

    @property
    def n_loops(self) -> int:
        """Number of minimal loops."""
        return int(self.loop_sizes.size)

    @property
    def mean_loop_size(self) -> float:
        """Mean size of the minimal loops (NaN without loops)."""
        return float(self.loop_sizes.mean()) if self.loop_sizes.size else float("nan")

    @property
    def size_distribution(self) -> NDArray[np.float64]:
        """Fraction of the loops of size 0, 1, 2, ...."""
        counts = np.bincount(self.loop_sizes).astype(np.float64)
        return counts / counts.sum() if counts.sum() else counts

    grain_loop_size = Computed[NDArray[np.float64]](
        "(N,) mean size of the loops each grain sits on, NaN for none."
    )
    in_graph = Computed[NDArray[np.bool_]](
        "(N,) the grains of the graph (the sample, less the rattlers by default)."
    )
    n_edges = Computed[int]("E, the contacts of the graph.")
    n_components = Computed[int]("C, its connected components.")

    def summary(self) -> dict[str, Any]:
        """The loops' numbers: L, the loops' count, mean size and size fractions."""
        return {
            "cyclomatic_number": self.cyclomatic_number,
            "n_loops": self.n_loops,
            "mean_loop_size": self.mean_loop_size,
            "loop_size_distribution": [float(f) for f in self.size_distribution],
        }

    def plot(self, ax: Any = None) -> Any:
        """Particle map coloured by the mean size of each grain's loops; returns the axes."""
        from grainlab import plot

        snap = self._snapshot
        return plot.particle_map(
            snap.positions,
            snap.radii,
            self.grain_loop_size,
            ax=ax,
            cmap="viridis",
            vmin=3.0,
            label="mean size of the grain's loops",
        )
