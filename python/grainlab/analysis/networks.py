r"""The strong and weak force networks (Radjai et al. 1998), split at the mean normal
force, each with its anisotropies, stress and shares: docs/fabric.md, "Strong and
weak networks".
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from grainlab.analysis._compute import Compute, Computed
from grainlab.analysis._util import grain_contacts, principal_stresses
from grainlab.analysis.stress import branch_vectors, contact_stress
from grainlab.analysis.stress_fabric import Anisotropies, force_anisotropies
from grainlab.snapshot import Snapshot

__all__ = ["ForceNetworks", "Network"]


@dataclass(frozen=True, eq=False)
class Network:
    """One network's measures (see :mod:`grainlab.analysis.networks`).

    ``contacts`` (Nc,) bool marks its contacts in the snapshot's list;
    ``anisotropies`` (:class:`Anisotropies`); ``stress`` (2, 2) Pa;
    ``mean_stress`` p and ``deviatoric_stress`` q = (sigma_1 - sigma_2)/2, Pa;
    ``deviatoric_share`` chi and ``mean_stress_share`` p_k / p.
    """

    contacts: NDArray[np.bool_]
    anisotropies: Anisotropies
    stress: NDArray[np.float64]
    mean_stress: float
    deviatoric_stress: float
    deviatoric_share: float
    mean_stress_share: float

    @property
    def n_contacts(self) -> int:
        """Contacts in the network."""
        return int(self.contacts.sum())

    def summary(self, prefix: str) -> dict[str, float | int]:
        """The scalars by name, angles in degrees, each name with ``prefix``."""
        out = self.anisotropies.as_dict(prefix)
        out.update(
            {
                f"{prefix}mean_stress_pa": self.mean_stress,
                f"{prefix}deviatoric_stress_pa": self.deviatoric_stress,
                f"{prefix}deviatoric_share": self.deviatoric_share,
                f"{prefix}mean_stress_share": self.mean_stress_share,
            }
        )
        return out


def _deviator(s: NDArray[np.float64]) -> NDArray[np.float64]:
    return np.asarray(s - 0.5 * np.trace(s) * np.eye(2), dtype=np.float64)


class ForceNetworks(Compute):
    """The strong and weak force networks split at the mean normal force, each with its
    anisotropies, stress and shares of the deviatoric and mean stress, which sum to 1
    over the two networks (docs/fabric.md, "Strong and weak networks").

    Parameters
    ----------
    include_boundary : bool, default False
        Add the grains' contacts with walls and membrane disks.
    area : float, m^2, optional
        For the stresses (default the snapshot's region); the shares do not
        depend on it.

    Example
    -------
    A hexagonal lattice whose horizontal contacts carry 3 N and the others 1 N:

    >>> import numpy as np
    >>> from grainlab.snapshot import Snapshot
    >>> x, y = np.meshgrid(np.arange(4.0), np.arange(4.0) * 3**0.5)
    >>> pos = np.r_[np.c_[x.ravel(), y.ravel()], np.c_[x.ravel() + 0.5, y.ravel() + 3**0.5 / 2]]
    >>> snap = Snapshot.from_geometry(pos, np.full(32, 0.5), tolerance=1e-9,
    ...     box=[[0, 4], [0, 4 * 3**0.5]], periodic=(True, True))
    >>> flat = np.abs(snap.contact_normals()[:, 0]) > 0.99
    >>> nets = ForceNetworks().compute(snap.with_contacts(
    ...     snap.contact_i, snap.contact_j, normal_force=np.where(flat, 3.0, 1.0)))
    >>> round(nets.strong.deviatoric_share, 12), round(nets.weak.deviatoric_share, 12)
    (1.5, -0.5)
    """

    _parameters = ("include_boundary", "area")

    def __init__(self, include_boundary: bool = False, area: float | None = None) -> None:
        if area is not None and not area > 0:
            raise ValueError(f"area: must be > 0, got {area}")
        self.include_boundary = bool(include_boundary)
        self.area = area

    def compute(self, snapshot: Snapshot) -> ForceNetworks:
        """Split the contacts of ``snapshot`` and measure both networks; returns ``self``."""
        if snapshot.normal_force is None:
            raise ValueError("normal_force: the snapshot has no contact forces (needed here)")
        used = grain_contacts(snapshot, self.include_boundary)
        fn = np.asarray(snapshot.normal_force)
        mean = float(fn[used].mean()) if used.any() else float("nan")
        strong = used & (fn > mean)
        weak = used & ~strong
        whole_stress = contact_stress(snapshot, used, self.area)
        dev = _deviator(whole_stress)
        dev_norm = float(np.sum(dev * dev))
        p_whole = 0.5 * float(np.trace(whole_stress))
        angles = np.asarray(snapshot.contact_angles())
        fs = snapshot.shear_force
        lengths = np.hypot(*branch_vectors(snapshot).T)

        def network(mask: NDArray[np.bool_]) -> Network:
            stress = contact_stress(snapshot, mask, self.area)
            s1, s2, _ = principal_stresses(stress)
            p = 0.5 * float(np.trace(stress))
            return Network(
                contacts=mask,
                anisotropies=force_anisotropies(
                    angles[mask],
                    fn[mask],
                    None if fs is None else np.asarray(fs)[mask],
                    lengths[mask],
                ),
                stress=stress,
                mean_stress=p,
                deviatoric_stress=float(0.5 * (s1 - s2)),
                deviatoric_share=float(np.sum(_deviator(stress) * dev) / dev_norm)
                if dev_norm > 0
                else float("nan"),
                mean_stress_share=p / p_whole if p_whole != 0 else float("nan"),
            )

        n = snapshot.n_particles
        ci = np.asarray(snapshot.contact_i)
        cj = np.asarray(snapshot.contact_j)
        touched = np.bincount(ci[strong], minlength=n) + np.bincount(
            cj[strong & (cj >= 0)], minlength=n
        )
        self._store(
            _snapshot=snapshot,
            mean_normal_force=mean,
            strong=network(strong),
            weak=network(weak),
            whole=network(used),
            in_strong_network=(touched > 0) & snapshot.is_sample,
        )
        return self

    _snapshot = Computed[Snapshot]("The snapshot measured (drawn by plot).")
    mean_normal_force = Computed[float]("<f_n> over the contacts used, N: the threshold.")
    strong = Computed["Network"]("The strong network, f_n > <f_n>.")
    weak = Computed["Network"]("The weak network, f_n <= <f_n>.")
    whole = Computed["Network"]("All the contacts used, measured the same way.")
    in_strong_network = Computed[NDArray[np.bool_]](
        "(N,) sample grains with at least one strong contact."
    )

    def summary(self) -> dict[str, float | int]:
        """Every scalar by name (``strong_a_n``, ``weak_deviatoric_share``, ...)."""
        out: dict[str, float | int] = {"mean_normal_force_n": self.mean_normal_force}
        out.update(self.strong.summary("strong_"))
        out.update(self.weak.summary("weak_"))
        return out

    def plot(self, ax: Any = None) -> Any:
        """The force network: each contact a line of width proportional to f_n,
        strong black, weak grey; returns the axes."""
        from grainlab.plot import networks

        snap = self._snapshot
        used = self.whole.contacts
        start = np.asarray(snap.positions)[np.asarray(snap.contact_i)[used]]
        fn = np.asarray(snap.normal_force)[used]
        width = 2.5 * fn / fn.max() if fn.size and fn.max() > 0 else np.zeros(fn.size)
        color = np.where(self.strong.contacts[used], "k", "0.6")
        return networks.contact_network(
            start,
            start + branch_vectors(snap)[used],
            width,
            color=list(color),
            positions=snap.positions,
            radii=snap.radii,
            ax=ax,
            title=f"force network (strong: f_n > {self.mean_normal_force:.3g} N)",
            legend=[("strong", "k"), ("weak", "0.6")],
        )
