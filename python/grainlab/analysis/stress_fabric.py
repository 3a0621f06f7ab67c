r"""Satake's fabric tensor and Rothenburg and Bathurst's stress-force-fabric relation.

Definitions, fits, signs and known answers: docs/fabric.md, "Fabric tensor
(Satake)" and "Stress-force-fabric relation".
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from grainlab.analysis._compute import Compute, Computed
from grainlab.analysis._util import (
    axial_direction,
    grain_contacts,
    principal_stresses,
)
from grainlab.snapshot import Snapshot

__all__ = ["Anisotropies", "FabricTensor", "StressForceFabric", "force_anisotropies"]


@dataclass(frozen=True)
class Anisotropies:
    """Rothenburg and Bathurst's anisotropies of a set of contacts (module
    docstring): ``a``, ``a_n``, ``a_t`` and their directions (rad, [0, pi)),
    ``f0`` the fitted mean normal force (N), ``n_contacts``; ``a_l``,
    ``theta_l`` and ``l0`` (m) of the branch lengths when they were given."""

    n_contacts: int
    a: float
    theta_a: float
    a_n: float
    theta_n: float
    a_t: float
    theta_t: float
    f0: float
    a_l: float = float("nan")
    theta_l: float = float("nan")
    l0: float = float("nan")

    def as_dict(self, prefix: str = "") -> dict[str, float | int]:
        """The numbers by name, angles in degrees (``theta_a_deg``, ...)."""
        out: dict[str, float | int] = {f"{prefix}n_contacts": self.n_contacts}
        for name in ("a", "a_n", "a_t", "a_l"):
            out[prefix + name] = getattr(self, name)
            theta = getattr(self, "theta" + (name[1:] if name != "a" else "_a"))
            out[f"{prefix}theta{name[1:] if name != 'a' else '_a'}_deg"] = float(np.degrees(theta))
        out[prefix + "f0"] = self.f0
        return out


def force_anisotropies(
    angles: NDArray[np.float64],
    normal_force: NDArray[np.float64] | None,
    shear_force: NDArray[np.float64] | None,
    branch_length: NDArray[np.float64] | None = None,
) -> Anisotropies:
    """:class:`Anisotropies` of contacts at ``angles`` (rad) with these forces
    (N; None: the force terms NaN) and branch lengths (m; None: a_l NaN)."""
    th = np.asarray(angles, dtype=np.float64)
    nan = float("nan")
    if th.size == 0:
        return Anisotropies(0, nan, nan, nan, nan, nan, nan, nan)
    moment = np.mean(np.exp(2j * th))
    a, theta_a = float(2.0 * abs(moment)), float(axial_direction(np.angle(moment)))
    a_n = theta_n = a_t = theta_t = f0 = nan
    c2, s2 = np.cos(2.0 * th), np.sin(2.0 * th)
    design = np.column_stack([np.ones_like(th), c2, s2])
    if normal_force is not None and np.linalg.matrix_rank(design) == 3:
        c, *_ = np.linalg.lstsq(design, np.asarray(normal_force, dtype=np.float64), rcond=None)
        f0 = float(c[0])
        if f0 > 0.0:
            a_n = float(np.hypot(c[1], c[2]) / f0)
            theta_n = float(axial_direction(np.arctan2(c[2], c[1])))
            if shear_force is not None:
                d, *_ = np.linalg.lstsq(
                    design[:, 1:], np.asarray(shear_force, dtype=np.float64), rcond=None
                )
                a_t = float(np.hypot(d[0], d[1]) / f0)
                theta_t = float(axial_direction(np.arctan2(-d[0], d[1])))
    a_l = theta_l = l0 = nan
    if branch_length is not None and np.linalg.matrix_rank(design) == 3:
        b, *_ = np.linalg.lstsq(design, np.asarray(branch_length, dtype=np.float64), rcond=None)
        if b[0] > 0.0:
            l0 = float(b[0])
            a_l = float(np.hypot(b[1], b[2]) / b[0])
            theta_l = float(axial_direction(np.arctan2(b[2], b[1])))
    return Anisotropies(
        int(th.size), a, theta_a, a_n, theta_n, a_t, theta_t, f0, a_l, theta_l, l0
    )


def _normal_products(normals: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Sums of n (x) n (2, 2) and of n (x) n (x) n (x) n (2, 2, 2, 2) over the normals."""
    second = np.einsum("ci,cj->ij", normals, normals)
    fourth = np.einsum("ci,cj,ck,cl->ijkl", normals, normals, normals, normals)
    return second, fourth


class FabricTensor(Compute):
    """Satake's fabric tensor, its fourth-order companion and its strong and weak parts
    (split at the mean normal force), with a and b_4: docs/fabric.md, "Fabric tensor (Satake)".

    Parameters
    ----------
    include_boundary : bool, default False
        Add the grains' contacts with walls and membrane disks.

    Example
    -------
    >>> import numpy as np
    >>> from grainlab.snapshot import Snapshot
    >>> x, y = np.meshgrid(np.arange(6.0), np.arange(6.0))
    >>> snap = Snapshot.from_geometry(np.c_[x.ravel(), y.ravel()], np.full(36, 0.5),
    ...                               box=[[0, 6], [0, 6]], periodic=(True, True), tolerance=1e-9)
    >>> fabric = FabricTensor().compute(snap)  # a square lattice
    >>> fabric.tensor.round(12).tolist(), round(float(fabric.fourth_order[0, 0, 0, 0]), 12)
    ([[0.5, 0.0], [0.0, 0.5]], 0.5)
    """

    _parameters = ("include_boundary",)

    def __init__(self, include_boundary: bool = False) -> None:
        self.include_boundary = bool(include_boundary)

    def compute(self, snapshot: Snapshot) -> FabricTensor:
        """Compute the fabric tensors of ``snapshot``; returns ``self``."""
        used = grain_contacts(snapshot, self.include_boundary)
        normals = np.asarray(snapshot.contact_normals())[used]
        n_c = int(normals.shape[0])
        nan2, nan4 = np.full((2, 2), np.nan), np.full((2, 2, 2, 2), np.nan)
        second, fourth = _normal_products(normals)
        tensor = second / n_c if n_c else nan2
        fourth = fourth / n_c if n_c else nan4
        angles = np.asarray(snapshot.contact_angles())[used]
        anisotropy = harmonic = direction = float("nan")
        if n_c:
            s1, s2, major = principal_stresses(tensor)
            anisotropy, direction = float(2.0 * (s1 - s2)), float(major)
            harmonic = float(abs(np.mean(np.exp(4j * angles))))
        strong = weak = None
        if snapshot.normal_force is not None and n_c:
            fn = np.asarray(snapshot.normal_force)[used]
            strong_mask = fn > fn.mean()
            strong = _normal_products(normals[strong_mask])[0] / n_c
            weak = _normal_products(normals[~strong_mask])[0] / n_c
        self._store(
            tensor=tensor,
            fourth_order=fourth,
            anisotropy=anisotropy,
            direction=direction,
            fourth_harmonic=harmonic,
            strong_part=strong,
            weak_part=weak,
            n_contacts=n_c,
            _angles=angles,
        )
        return self

    _angles = Computed[NDArray[np.float64]]("(Nc,) the contact angles used, rad (drawn by plot).")
    tensor = Computed[NDArray[np.float64]]("(2, 2) phi_ij, trace 1.")
    fourth_order = Computed[NDArray[np.float64]](
        "(2, 2, 2, 2) phi_ijkl, its contractions phi_ijkk = phi_ij."
    )
    anisotropy = Computed[float]("a = 2 (phi_1 - phi_2).")
    direction = Computed[float]("theta_a, the major direction of phi, rad in [0, pi).")
    fourth_harmonic = Computed[float](
        "b_4 = |mean of exp(4 i theta)|: 0 for a hexagonal lattice, 1 for a square one."
    )
    strong_part = Computed[NDArray[np.float64] | None](
        "(2, 2) phi^s, the strong contacts' share of phi (None without forces)."
    )
    weak_part = Computed[NDArray[np.float64] | None](
        "(2, 2) phi^w = phi - phi^s (None without forces)."
    )
    n_contacts = Computed[int]("N_c, the contacts used.")

    def plot(self, ax: Any = None) -> Any:
        """Rose diagram of the contact normals with the fitted E(theta); returns the axes."""
        from grainlab import plot
        from grainlab.analysis.fabric import angular_histogram

        values, _ = angular_histogram(self._angles, 18)
        return plot.polar_distribution(
            values, anisotropy=self.anisotropy, direction=self.direction, ax=ax
        )


class StressForceFabric(Compute):
    """Rothenburg and Bathurst's stress-force-fabric relation, with its residual.

    The measured q/p of the contacts used (their contact form,
    :func:`~grainlab.analysis.stress.contact_stress`) against the prediction from
    the anisotropies fitted to the same contacts; :attr:`residual` is measured −
    predicted (docs/fabric.md, "Stress-force-fabric relation"). Needs normal
    forces; shear forces optional (without them a_t is NaN and left out of the sum).

    Parameters
    ----------
    include_boundary : bool, default False
        Add the grains' contacts with walls and membrane disks.

    Example
    -------
    A hexagonal lattice loaded along y only (a = 0, a_n = 2, q/p = 1):

    >>> import numpy as np
    >>> from grainlab.snapshot import Snapshot
    >>> x, y = np.meshgrid(np.arange(4.0), np.arange(4.0) * 3**0.5)
    >>> pos = np.r_[np.c_[x.ravel(), y.ravel()], np.c_[x.ravel() + 0.5, y.ravel() + 3**0.5 / 2]]
    >>> snap = Snapshot.from_geometry(pos[:, ::-1], np.full(32, 0.5), tolerance=1e-9,
    ...     box=[[0, 4 * 3**0.5], [0, 4]], periodic=(True, True))
    >>> vertical = np.abs(snap.contact_normals()[:, 1]) > 0.99
    >>> rb = StressForceFabric().compute(snap.with_contacts(
    ...     snap.contact_i, snap.contact_j, normal_force=np.where(vertical, 1.0, 0.0)))
    >>> round(rb.stress_ratio, 12), round(rb.anisotropies.a_n, 12), round(rb.residual, 12)
    (1.0, 2.0, 0.0)
    """

    _parameters = ("include_boundary",)

    def __init__(self, include_boundary: bool = False) -> None:
        self.include_boundary = bool(include_boundary)

    def compute(self, snapshot: Snapshot) -> StressForceFabric:
        """Compute both sides of the relation for ``snapshot``; returns ``self``."""
        from grainlab.analysis.stress import contact_stress

        if snapshot.normal_force is None:
            raise ValueError("normal_force: the snapshot has no contact forces (needed here)")
        used = grain_contacts(snapshot, self.include_boundary)
        angles = np.asarray(snapshot.contact_angles())[used]
        fs = None if snapshot.shear_force is None else np.asarray(snapshot.shear_force)[used]
        from grainlab.analysis.stress import branch_vectors

        lengths = np.hypot(*branch_vectors(snapshot)[used].T)
        rb = force_anisotropies(angles, np.asarray(snapshot.normal_force)[used], fs, lengths)
        stress = contact_stress(snapshot, used)
        s1, s2, direction = principal_stresses(stress)
        ratio = float((s1 - s2) / (s1 + s2)) if s1 + s2 > 0 else float("nan")
        terms = [
            k * np.cos(2.0 * (t - direction))
            for k, t in ((rb.a, rb.theta_a), (rb.a_n, rb.theta_n), (rb.a_t, rb.theta_t))
            if np.isfinite(k)
        ]
        predicted = float(0.5 * np.sum(terms)) if np.isfinite(rb.a_n) else float("nan")
        self._store(
            anisotropies=rb,
            stress=stress,
            stress_direction=float(direction),
            stress_ratio=ratio,
            predicted_stress_ratio=predicted,
        )
        return self

    anisotropies = Computed["Anisotropies"](
        "a, a_n, a_t, their directions and f0 (:class:`Anisotropies`)."
    )
    stress = Computed[NDArray[np.float64]](
        "(2, 2) the contacts' stress, Pa (over the snapshot's region)."
    )
    stress_direction = Computed[float](
        "theta_sigma, the major principal direction of :attr:`stress`, rad."
    )
    stress_ratio = Computed[float]("q/p = (sigma_1 - sigma_2) / (sigma_1 + sigma_2), measured.")
    predicted_stress_ratio = Computed[float](
        "(1/2) sum of the anisotropies projected on theta_sigma."
    )

    @property
    def residual(self) -> float:
        """Measured minus predicted q/p."""
        return self.stress_ratio - self.predicted_stress_ratio

    @property
    def predicted_with_branch_length(self) -> float:
        """The predicted q/p plus (1/2) a_l cos 2(theta_l - theta_sigma)."""
        rb = self.anisotropies
        extra = 0.5 * rb.a_l * np.cos(2.0 * (rb.theta_l - self.stress_direction))
        return float(self.predicted_stress_ratio + (extra if np.isfinite(extra) else 0.0))

    @property
    def residual_with_branch_length(self) -> float:
        """Measured q/p minus :attr:`predicted_with_branch_length`."""
        return self.stress_ratio - self.predicted_with_branch_length

    @property
    def sigma_ratio(self) -> float:
        """sigma_1 / sigma_2 measured."""
        x = self.stress_ratio
        return float((1.0 + x) / (1.0 - x)) if x < 1.0 else float("inf")

    @property
    def predicted_sigma_ratio(self) -> float:
        """sigma_1 / sigma_2 from the predicted q/p."""
        x = self.predicted_stress_ratio
        return float((1.0 + x) / (1.0 - x)) if x < 1.0 else float("inf")

    def plot(self, ax: Any = None) -> Any:
        """Bars: each anisotropy's share of q/p and the measured q/p; returns the axes."""
        from grainlab.plot import new_axes
        from grainlab.plot.files import paper_style

        rb = self.anisotropies
        th = self.stress_direction
        parts = [
            (name, 0.5 * k * np.cos(2.0 * (t - th)) if np.isfinite(k) else 0.0)
            for name, k, t in (
                ("a/2", rb.a, rb.theta_a), ("a_n/2", rb.a_n, rb.theta_n), ("a_t/2", rb.a_t, rb.theta_t)
            )
        ]
        ax = new_axes(ax)
        with paper_style():
            bottom = 0.0
            for k, (name, value) in enumerate(parts):
                ax.bar(0, value, bottom=bottom, color=f"C{k}", label=name, width=0.6)
                bottom += value
            ax.bar(1, self.stress_ratio, color="0.4", width=0.6, label="measured")
            ax.set_xticks([0, 1], ["predicted", "measured"])
            ax.set_ylabel("q / p")
            ax.set_title(f"residual {self.residual:+.3f}")
            ax.legend(frameon=False, fontsize=7)
        return ax
