r"""Figures of a biaxial run: the paper's Figs. 6, 7, 9, 11, 12, 13 and 14 from ``run.h5``.

:func:`fabric_figures` reads a run folder (or its ``run.h5``), draws the
micro-scale figures of Sec. 6 as PNG + SVG and returns the files together
with the numbers it computed (:class:`FabricNumbers`), so that a summary or
report can print them. :func:`fabric_numbers` computes the numbers alone.

States
    *initial* is the first snapshot written, *final* the last, and *peak* the
    snapshot (other than the first) whose axial strain is closest to the peak
    of the ``stress_ratio`` time series (``peak_snapshot=`` overrides it).

Shear band
    Found on each pair (initial, peak) and (initial, final) with
    :class:`~grainlab.analysis.LocalStrain` and
    :class:`~grainlab.analysis.ShearBand`, computed on the **grains only**
    (membrane disks are much smaller than the grains and are not part of the
    sample: they would set the neighbour radius and the background strain).
    Grains whose centre lies within one mean diameter of the boundary
    (membrane disk centres and platen contact points; the grains' bounding box
    when there are neither) are left out of the search, since their one-sided
    neighbourhoods give spurious strains; they still belong to the band when
    they lie inside it. The candidate band is accepted when it

    1. passes ShearBand's own tests (:attr:`ShearBand.found
       <grainlab.analysis.ShearBand.found>`): at least one mean grain
       diameter thick, and its excess strain over the background at least
       twice the largest excess elsewhere on the profile across it,
    2. crosses the sample: the centre line's chord through the grains is at
       least 3/4 of the sample's smaller side and the band's grains cover at
       least 3/4 of that chord (a slab that cuts off a corner is not a band),
    3. explains more of the strain variance (adjusted eta², as ShearBand
       scores it) than the band found in each of 19 random rearrangements of
       the same strain values over the same grains (p <= 0.05, fixed seed).

    Otherwise the band is "not found": the maps are drawn without an outline,
    the panel title says so and :attr:`BandNumbers.reason` says why. A found
    band's panel titles give its inclination to the horizontal and thickness.

    The **second band** (ShearBand's second pass, without the first band's
    grains and at least 20 degrees away from its direction: the conjugate
    band of a biaxial test) is reported in the ``second_*`` fields of
    :class:`BandNumbers` and outlined dotted when it passes tests 1 and 2
    (and the first band was found).

Stability index
    lambda with the library's default: contacts with membrane disks and
    platens count as the boundary contacts of the grains; membrane disks get
    NaN and are drawn light grey on every map. Means in and out of the band are
    over grains with at least 2 contacts (the paper's 0.34 vs 0.31).
"""

from __future__ import annotations

import json
import math
import re
import string
from collections.abc import Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import EngFormatter, MaxNLocator
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from grainlab import plot
from grainlab.analysis.fabric import ContactAnisotropy, CoordinationNumber
from grainlab.analysis.shear_band import ShearBand
from grainlab.analysis.stability import StabilityIndex
from grainlab.analysis.strain import LocalStrain
from grainlab.io.hdf5 import Results, read_results
from grainlab.snapshot import Snapshot

__all__ = [
    "FIGURES",
    "REQUIRED_COLUMNS",
    "BandNumbers",
    "FabricFigures",
    "FabricNumbers",
    "MissingColumnError",
    "StateNumbers",
    "fabric_figures",
    "fabric_numbers",
    "band_labels",
]

#: Figure names (file stems), in the paper's order.
FIGURES: tuple[str, ...] = (
    "fig06_contact_normals",
    "fig07_normal_forces",
    "fig09_anisotropy",
    "fig11_displacement",
    "fig12_stability_index",
    "fig13_contact_count",
    "fig14_mean_stability_index",
)

#: Time-series columns needed, and what for.
REQUIRED_COLUMNS: dict[str, str] = {
    "axial_strain": "the strain axis of Figs. 9 and 14",
    "stress_ratio": "locating the peak",
    "anisotropy": "a in Fig. 9",
    "force_anisotropy": "a_n in Fig. 9",
    "mean_stability_index": "Fig. 14",
}

#: Band acceptance: minimum thickness (mean diameters), crossing fractions, permutations.
_MIN_THICKNESS_D = 1.0
_CROSSING = 0.75
_N_PERMUTATIONS = 19
_EDGE_D = 1.0

_NAME_STRAIN = re.compile(r"strain_([-+]?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?)$")


class MissingColumnError(ValueError):
    """The run's time series lacks a column the figures need (the message names it)."""


# ----------------------------------------------------------------------------- numbers
@dataclass(frozen=True)
class StateNumbers:
    """Fabric of one snapshot (grains only, boundary contacts excluded from a, a_n, Z)."""

    #: ``"initial"``, ``"peak"`` or ``"final"``.
    role: str
    #: Snapshot name in ``run.h5``.
    snapshot: str
    #: Axial strain of the snapshot (fraction; NaN when not recorded).
    axial_strain: float
    #: Contact-normal anisotropy a and direction theta_a (exact, unbinned; degrees).
    a: float
    theta_a_deg: float
    #: Normal-force anisotropy a_n and its direction (NaN without forces).
    a_n: float
    theta_n_deg: float
    #: Mean lambda over grains with >= 2 contacts (boundary contacts included).
    mean_lambda: float
    #: Coordination number Z = 2 Nc / Np of the grains.
    coordination_number: float


@dataclass(frozen=True)
class BandNumbers:
    """The shear band between the initial snapshot and ``snapshot``."""

    #: Snapshot compared with ``reference``.
    snapshot: str
    reference: str
    axial_strain: float
    #: Whether the band passed the acceptance tests (module docstring).
    found: bool
    #: Why it was not accepted ("" when found); names the candidate's numbers.
    reason: str
    #: Band direction, degrees in [0, 180), CCW from +x (NaN when not found).
    angle_deg: float
    #: Inclination to the horizontal (the sigma_3 direction), degrees in [0, 90].
    inclination_deg: float
    thickness_m: float
    thickness_diameters: float
    #: (peak - background) / peak of the strain profile.
    contrast: float
    #: Grains whose centre lies inside the band.
    n_grains: int
    #: Mean lambda of grains with >= 2 contacts inside / outside the band.
    mean_lambda_inside: float
    mean_lambda_outside: float
    #: Permutation p-value of the band's eta² (1/20 is the smallest possible).
    p_value: float
    #: Band excess strain / largest excess elsewhere on its profile (ShearBand.prominence).
    prominence: float = math.nan
    #: The second (conjugate) band: accepted or not, and its numbers (NaN when
    #: there is no candidate); same conventions as the first band's fields.
    second_found: bool = False
    second_reason: str = ""
    second_angle_deg: float = math.nan
    second_inclination_deg: float = math.nan
    second_thickness_diameters: float = math.nan
    second_contrast: float = math.nan
    second_prominence: float = math.nan


@dataclass
class FabricNumbers:
    """The numbers behind the figures of one biaxial run."""

    #: The results file read.
    results_path: Path
    #: Row of the time series with the largest stress ratio, and its values.
    peak_row: int
    peak_stress_ratio: float
    peak_axial_strain: float
    #: False when the largest stress ratio is at the first or last record.
    peak_in_interior: bool
    #: a, a_n and mean lambda of the time series at the peak row.
    a_at_peak: float
    a_n_at_peak: float
    mean_lambda_at_peak: float
    #: Fabric of the initial, peak and final snapshots (keys ``initial``, ``peak``, ``final``).
    states: dict[str, StateNumbers]
    #: The band at the peak snapshot and at the final one (None: only one snapshot,
    #: or, for ``band_final``, when the final snapshot is the peak snapshot).
    band: BandNumbers | None
    band_final: BandNumbers | None
    #: Anything worth telling a reader (no interior peak, band not found, ...).
    notes: list[str] = field(default_factory=list)

    @property
    def peak_snapshot(self) -> str:
        """Name of the snapshot used as the peak state."""
        return self.states["peak"].snapshot

    @property
    def band_found(self) -> bool:
        return self.band is not None and self.band.found

    @property
    def band_angle_deg(self) -> float:
        """Band angle at the peak snapshot, degrees (NaN when not found)."""
        return self.band.angle_deg if self.band_found else math.nan  # type: ignore[union-attr]

    @property
    def band_thickness_diameters(self) -> float:
        """Band thickness at the peak snapshot in mean grain diameters (NaN when not found)."""
        return self.band.thickness_diameters if self.band_found else math.nan  # type: ignore[union-attr]

    @property
    def mean_lambda_in_band(self) -> float:
        return self.band.mean_lambda_inside if self.band_found else math.nan  # type: ignore[union-attr]

    @property
    def mean_lambda_outside_band(self) -> float:
        return self.band.mean_lambda_outside if self.band_found else math.nan  # type: ignore[union-attr]

    def summary(self) -> dict[str, Any]:
        """JSON-ready dict (NaN as None, paths as strings)."""
        return _jsonable(
            {
                "results_path": str(self.results_path),
                "peak_row": self.peak_row,
                "peak_stress_ratio": self.peak_stress_ratio,
                "peak_axial_strain": self.peak_axial_strain,
                "peak_in_interior": self.peak_in_interior,
                "peak_snapshot": self.peak_snapshot,
                "a_at_peak": self.a_at_peak,
                "a_n_at_peak": self.a_n_at_peak,
                "mean_lambda_at_peak": self.mean_lambda_at_peak,
                "band_found": self.band_found,
                "band_angle_deg": self.band_angle_deg,
                "band_thickness_diameters": self.band_thickness_diameters,
                "mean_lambda_in_band": self.mean_lambda_in_band,
                "mean_lambda_outside_band": self.mean_lambda_outside_band,
                "states": {k: asdict(v) for k, v in self.states.items()},
                "band": asdict(self.band) if self.band else None,
                "band_final": asdict(self.band_final) if self.band_final else None,
                "notes": list(self.notes),
            }
        )

    def lines(self) -> list[str]:
        """Human-readable lines for a summary or report."""

        def pct(x: float) -> str:
            return "n/a" if not np.isfinite(x) else f"{100 * x:.2f} %"

        out = [
            f"peak stress ratio {self.peak_stress_ratio:.3g} at axial strain "
            f"{pct(self.peak_axial_strain)}"
            + ("" if self.peak_in_interior else " (at the end of the record: no interior peak)"),
            (
                f"at peak: a = {self.a_at_peak:.3f}, a_n = {self.a_n_at_peak:.3f}, "
                f"mean lambda = {self.mean_lambda_at_peak:.3f}"
            ),
        ]
        shown: set[str] = set()
        for s in self.states.values():
            if s.snapshot in shown:
                out.append(f"{s.role} snapshot: {s.snapshot}, as above")
                continue
            shown.add(s.snapshot)
            out.append(
                f"{s.role} snapshot {s.snapshot} ({pct(s.axial_strain)}): a = {s.a:.3f} "
                f"(theta_a {s.theta_a_deg:.1f} deg), a_n = {s.a_n:.3f}, "
                f"mean lambda = {s.mean_lambda:.3f}, Z = {s.coordination_number:.2f}"
            )
        for label, b in (("shear band", self.band), ("shear band at the end", self.band_final)):
            if b is None:
                continue
            if b.found:
                out.append(
                    f"{label} ({b.snapshot}): angle {b.angle_deg:.1f} deg (inclination "
                    f"{b.inclination_deg:.1f} deg), thickness {b.thickness_diameters:.1f} mean "
                    f"diameters, contrast {b.contrast:.2f}, {b.n_grains} grains, mean lambda "
                    f"inside {b.mean_lambda_inside:.3f} / outside {b.mean_lambda_outside:.3f}"
                )
                if b.second_found:
                    out.append(
                        f"second (conjugate) band: angle {b.second_angle_deg:.1f} deg "
                        f"(inclination {b.second_inclination_deg:.1f} deg), thickness "
                        f"{b.second_thickness_diameters:.1f} mean diameters, contrast "
                        f"{b.second_contrast:.2f}"
                    )
                elif b.second_reason:
                    out.append(f"no second band: {b.second_reason}")
            else:
                out.append(f"{label} ({b.snapshot}): not found: {b.reason}")
        out += [f"note: {n}" for n in self.notes]
        return out

    def __str__(self) -> str:
        return "\n".join(self.lines())


class FabricFigures(dict[str, list[Path]]):
    """Figure name -> files written (PNG, SVG), with the numbers in :attr:`numbers`.

    A plain dict of the figures (equality compares the files only) that also
    carries the :class:`FabricNumbers` the figures show.
    """

    def __init__(self, files: dict[str, list[Path]], numbers: FabricNumbers) -> None:
        super().__init__(files)
        self.numbers = numbers

    @property
    def paths(self) -> list[Path]:
        """Every file written, in figure order."""
        return [p for files in self.values() for p in files]


# ----------------------------------------------------------------------------- analysis
@dataclass
class _State:
    role: str
    name: str
    strain: float
    snap: Snapshot
    stability: StabilityIndex
    normals: ContactAnisotropy
    forces: ContactAnisotropy | None
    label: str = ""  # how the figures name the state


@dataclass
class _Band:
    numbers: BandNumbers
    band: ShearBand | None  # the accepted band (None when not found)
    displacement: NDArray[np.float64]  # (N,) of the snapshot, NaN for membrane disks
    second: ShearBand | None = None  # the accepted second band (None when not found)


@dataclass
class _Analysis:
    numbers: FabricNumbers
    results: Results
    states: dict[str, _State]
    bands: dict[str, _Band]  # "peak" / "final"


def _jsonable(value: Any) -> Any:
    if isinstance(value, dict):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_jsonable(v) for v in value]
    if isinstance(value, Path):
        return str(value)
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def _snapshot_strain(info: Any) -> float:
    if info.axial_strain is not None and math.isfinite(info.axial_strain):
        return float(info.axial_strain)
    m = _NAME_STRAIN.search(info.name)
    return float(m.group(1)) if m else math.nan


def _timeseries(results: Results) -> dict[str, NDArray[np.float64]]:
    ts = results.timeseries
    for column, purpose in REQUIRED_COLUMNS.items():
        if column not in ts:
            raise MissingColumnError(
                f"{results.path}: the time series has no column {column!r} (needed for "
                f"{purpose}); its columns are {sorted(ts)}"
            )
    if len(ts["axial_strain"]) == 0:
        raise ValueError(f"{results.path}: the time series is empty")
    return ts


def _grains(snap: Snapshot) -> Snapshot:
    """The sample grains alone (no contacts): what the local strain is fitted on."""
    g = snap.is_sample
    return Snapshot(
        snap.positions[g],
        snap.radii[g],
        snap.ids[g],
        kind=snap.kind[g],
        box=snap.box,
        periodic=snap.periodic,
    )


def _interior(snap: Snapshot, d_mean: float) -> NDArray[np.bool_]:
    """(N_grains,) grains farther than ``_EDGE_D`` mean diameters from the boundary."""
    g = snap.is_sample
    pos = snap.positions[g]
    points = [snap.positions[~g]]
    wall = np.asarray(snap.contact_j) < 0
    if wall.any():
        if snap.contact_point is not None:
            points.append(np.asarray(snap.contact_point)[wall])
        else:
            owner = np.asarray(snap.contact_i)[wall]
            normals = np.asarray(snap.contact_normals())[wall]
            points.append(snap.positions[owner] + snap.radii[owner][:, None] * normals)
    boundary = np.vstack(points)
    if boundary.shape[0]:
        dist, _ = cKDTree(boundary).query(pos)
        return np.asarray(dist > _EDGE_D * d_mean)
    inside = np.ones(pos.shape[0], bool)
    for axis in (0, 1):
        if not snap.periodic[axis] and pos.shape[0]:
            x = pos[:, axis]
            inside &= np.minimum(x - x.min(), x.max() - x) > _EDGE_D * d_mean
    return inside


def _eta2(
    pos: NDArray[np.float64], gamma: NDArray[np.float64], normal: NDArray[np.float64], width: float
) -> float:
    """Adjusted correlation ratio of ``gamma`` with bins across the slab (as ShearBand scores)."""
    s = pos @ normal
    b = ((s - s.min()) / width).astype(np.int64)
    counts = np.bincount(b)
    sums = np.bincount(b, weights=gamma)
    occupied = counts > 0
    m = gamma.size
    mean = float(gamma.mean())
    total = float(((gamma - mean) ** 2).sum())
    if total <= 0.0:
        return 0.0
    between = float((sums[occupied] ** 2 / counts[occupied]).sum()) - m * mean**2
    n_bins = int(occupied.sum())
    return 1.0 - (1.0 - between / total) * (m - 1) / max(m - n_bins, 1)


def _find_band(reference: _State, current: _State) -> _Band:
    snap = current.snap
    g = snap.is_sample
    grains = _grains(snap)
    strain = LocalStrain().compute(_grains(reference.snap), grains)
    displacement = np.full(snap.n_particles, np.nan)
    displacement[g] = strain.displacement_magnitude
    pos, rad = grains.positions, grains.radii
    d_mean = float(np.mean(2.0 * rad)) if rad.size else math.nan
    gamma = strain.excess_shear_strain
    interior = _interior(snap, d_mean)
    valid = interior & np.isfinite(gamma)
    lam = current.stability.stability_index[g]
    counts = current.stability.n_contacts[g]

    def missing(reason: str, **numbers: Any) -> _Band:
        values: dict[str, Any] = {
            "angle_deg": math.nan,
            "inclination_deg": math.nan,
            "thickness_m": math.nan,
            "thickness_diameters": math.nan,
            "contrast": math.nan,
            "n_grains": 0,
            "mean_lambda_inside": math.nan,
            "mean_lambda_outside": math.nan,
            "p_value": math.nan,
        }
        values.update(numbers)
        return _Band(
            BandNumbers(current.name, reference.name, current.strain, False, reason, **values),
            None,
            displacement,
        )

    if int(valid.sum()) < 10:
        return missing(
            f"only {int(valid.sum())} grains away from the boundary have a local strain "
            "(at least 10 are needed)"
        )
    band = ShearBand(min_thickness=_MIN_THICKNESS_D).compute(pos, gamma, rad, mask=interior)
    side = float(np.ptp(pos, axis=0).min())
    # significance against random rearrangements of the same strain values
    width = band.bin_width * float(np.mean(2.0 * rad[interior]))
    eta = _eta2(pos[valid], gamma[valid], band.normal, width)
    rng = np.random.default_rng(20240611)
    shuffled = gamma.copy()
    null = np.empty(_N_PERMUTATIONS)
    for k in range(_N_PERMUTATIONS):
        shuffled[valid] = rng.permutation(gamma[valid])
        trial = ShearBand(second=False).compute(pos, shuffled, rad, mask=interior)
        null[k] = _eta2(pos[valid], shuffled[valid], trial.normal, width)
    p_value = float((1 + np.sum(null >= eta)) / (_N_PERMUTATIONS + 1))

    problems = _band_problems(band, pos, d_mean, side)
    if p_value > 0.05:
        problems.append(
            f"not significant (p = {p_value:.2f} against {_N_PERMUTATIONS} random "
            "rearrangements of the strain values)"
        )
    members = _slab_members(band, pos)
    use = counts >= 2
    numbers: dict[str, Any] = {
        "angle_deg": band.angle_degrees,
        "inclination_deg": band.inclination_degrees,
        "thickness_m": band.thickness,
        "thickness_diameters": band.thickness_diameters,
        "contrast": band.contrast,
        "n_grains": int(members.sum()),
        "mean_lambda_inside": _finite_mean(lam, use & members),
        "mean_lambda_outside": _finite_mean(lam, use & ~members),
        "p_value": p_value,
        "prominence": band.prominence,
    }
    if problems:
        return missing(
            f"best candidate at {band.angle_degrees:.1f} deg, {band.thickness_diameters:.1f} "
            "mean diameters thick: " + "; ".join(problems),
            p_value=p_value,
            prominence=band.prominence,
        )
    second = band.second
    accepted_second = None
    if second is not None:
        second_problems = _band_problems(second, pos, d_mean, side)
        numbers.update(
            second_found=not second_problems,
            second_reason=(
                f"best candidate at {second.angle_degrees:.1f} deg, "
                f"{second.thickness_diameters:.1f} mean diameters thick: "
                + "; ".join(second_problems)
                if second_problems
                else ""
            ),
            second_angle_deg=second.angle_degrees,
            second_inclination_deg=second.inclination_degrees,
            second_thickness_diameters=second.thickness_diameters,
            second_contrast=second.contrast,
            second_prominence=second.prominence,
        )
        accepted_second = None if second_problems else second
    return _Band(
        BandNumbers(current.name, reference.name, current.strain, True, "", **numbers),
        band,
        displacement,
        accepted_second,
    )


def _slab_members(band: ShearBand, pos: NDArray[np.float64]) -> NDArray[np.bool_]:
    """Grains whose centre lies inside the band's slab (boundary grains included)."""
    return np.asarray(np.abs((pos - band.center) @ band.normal) <= 0.5 * band.thickness)


def _band_problems(
    band: ShearBand, pos: NDArray[np.float64], d_mean: float, side: float
) -> list[str]:
    """Why a candidate band fails acceptance tests 1 and 2 (module docstring); [] if it passes."""
    problems = [band.reason] if not band.found else []
    tangent = np.array([np.cos(band.angle), np.sin(band.angle)])
    s = (pos - band.center) @ band.normal
    members = np.abs(s) <= 0.5 * band.thickness
    # crossing: chord of the centre line through the grains and the members' cover of it
    near = np.abs(s) <= max(0.5 * band.thickness, d_mean)
    chord = float(np.ptp(pos[near] @ tangent)) if near.sum() > 1 else 0.0
    span = float(np.ptp(pos[members] @ tangent)) if members.sum() > 1 else 0.0
    if chord < _CROSSING * side or span < _CROSSING * chord:
        problems.append(
            f"does not cross the sample (its grains span {span / d_mean:.1f} mean diameters "
            f"of a {chord / d_mean:.1f}-diameter chord; the sample's smaller side is "
            f"{side / d_mean:.1f})"
        )
    return problems


def _finite_mean(values: NDArray[np.float64], mask: NDArray[np.bool_]) -> float:
    ok = mask & np.isfinite(values)
    return float(values[ok].mean()) if ok.any() else math.nan


def _state(role: str, name: str, strain: float, snap: Snapshot) -> _State:
    forces = (
        ContactAnisotropy(weight="normal_force").compute(snap)
        if snap.normal_force is not None
        else None
    )
    return _State(
        role,
        name,
        strain,
        snap,
        StabilityIndex().compute(snap),
        ContactAnisotropy().compute(snap),
        forces,
    )


def _state_numbers(st: _State) -> StateNumbers:
    z = CoordinationNumber().compute(st.snap)
    return StateNumbers(
        role=st.role,
        snapshot=st.name,
        axial_strain=st.strain,
        a=st.normals.anisotropy,
        theta_a_deg=float(np.degrees(st.normals.direction)),
        a_n=st.forces.anisotropy if st.forces else math.nan,
        theta_n_deg=float(np.degrees(st.forces.direction)) if st.forces else math.nan,
        mean_lambda=st.stability.mean,
        coordination_number=z.coordination_number,
    )


def _select_peak(
    results: Results, strains: list[float], eps_peak: float, peak_snapshot: str | int | None
) -> int:
    names = results.snapshot_names
    if peak_snapshot is not None:
        if isinstance(peak_snapshot, str):
            if peak_snapshot not in names:
                raise ValueError(
                    f"peak_snapshot: {peak_snapshot!r} is not a snapshot of {results.path} "
                    f"(snapshots: {names})"
                )
            return names.index(peak_snapshot)
        k = int(peak_snapshot)
        if not -len(names) <= k < len(names):
            raise ValueError(
                f"peak_snapshot: index {k} out of range for {len(names)} snapshots {names}"
            )
        return k % len(names)
    candidates = [k for k in range(1 if len(names) > 1 else 0, len(names))]
    known = [k for k in candidates if math.isfinite(strains[k])]
    if not known or not math.isfinite(eps_peak):
        return candidates[-1]
    return min(known, key=lambda k: (abs(strains[k] - eps_peak), k))


def _analyse(run_dir: str | Path, peak_snapshot: str | int | None) -> _Analysis:
    results = read_results(run_dir)
    ts = _timeseries(results)
    names = results.snapshot_names
    if not names:
        raise ValueError(f"{results.path}: the run has no snapshots")
    notes: list[str] = []
    eps = np.asarray(ts["axial_strain"], dtype=np.float64)
    q = np.asarray(ts["stress_ratio"], dtype=np.float64)
    finite = np.isfinite(eps) & np.isfinite(q)
    if not finite.any():
        raise ValueError(
            f"{results.path}: no record has both a finite axial_strain and a finite stress_ratio"
        )
    rows = np.flatnonzero(finite)
    k_peak = int(rows[np.argmax(q[rows])])
    interior = rows[0] < k_peak < rows[-1]
    eps_peak = float(eps[k_peak])
    if not interior:
        where = "last" if k_peak == rows[-1] else "first"
        notes.append(
            f"the stress ratio is largest at the {where} record ({100 * eps_peak:.2f} %): no peak "
            "inside the record; that record stands for the peak"
        )

    strains = [_snapshot_strain(info) for info in results.snapshots]
    k_snap = _select_peak(results, strains, eps_peak, peak_snapshot)
    if peak_snapshot is None and math.isfinite(strains[k_snap]):
        gap = abs(strains[k_snap] - eps_peak)
        if gap > max(0.002, 0.25 * abs(eps_peak)):
            notes.append(
                f"no snapshot near the stress-ratio peak ({100 * eps_peak:.2f} %): the closest, "
                f"{names[k_snap]}, is at {100 * strains[k_snap]:.2f} %"
            )

    cache: dict[int, _State] = {}

    def state(role: str, k: int) -> _State:
        if k not in cache:
            cache[k] = _state(role, names[k], strains[k], results.snapshot(names[k]))
        st = cache[k]
        label = {"initial": "initial", "peak": "nearest the peak", "final": "final"}[role]
        if role == "peak" and peak_snapshot is not None:
            label = "chosen peak state"
        return _State(role, st.name, st.strain, st.snap, st.stability, st.normals, st.forces, label)

    last = len(names) - 1
    states = {"initial": state("initial", 0), "peak": state("peak", k_snap)}
    states["final"] = state("final", last)
    if states["peak"].snap.normal_force is None:
        notes.append(f"{names[k_snap]} has no contact forces: no normal-force diagram data")

    bands: dict[str, _Band] = {}
    if k_snap == 0 and last == 0:
        notes.append("only one snapshot: no displacements and no shear band")
    else:
        if k_snap != 0:
            bands["peak"] = _find_band(states["initial"], states["peak"])
        if last not in (0, k_snap):
            bands["final"] = _find_band(states["initial"], states["final"])
    for key, b in bands.items():
        if not b.numbers.found:
            notes.append(
                f"no shear band found at {b.numbers.snapshot} ({key} state): its maps have no "
                "outline (BandNumbers.reason says why)"
            )

    numbers = FabricNumbers(
        results_path=results.path,
        peak_row=k_peak,
        peak_stress_ratio=float(q[k_peak]),
        peak_axial_strain=eps_peak,
        peak_in_interior=bool(interior),
        a_at_peak=float(ts["anisotropy"][k_peak]),
        a_n_at_peak=float(ts["force_anisotropy"][k_peak]),
        mean_lambda_at_peak=float(ts["mean_stability_index"][k_peak]),
        states={k: _state_numbers(v) for k, v in states.items()},
        band=bands["peak"].numbers if "peak" in bands else None,
        band_final=bands["final"].numbers if "final" in bands else None,
        notes=notes,
    )
    return _Analysis(numbers, results, states, bands)


def band_labels(reference: Snapshot, current: Snapshot) -> NDArray[np.int32]:
    """(N,) per particle of ``current``: 1 inside the accepted shear band, 2
    inside its accepted conjugate band, 0 elsewhere (membrane disks, and every
    particle when no band passes the tests): the bands the figures outline,
    found in the grains' local strain since ``reference``."""
    found = _find_band(_state("initial", "", 0.0, reference), _state("current", "", math.nan, current))
    labels = np.zeros(current.n_particles, np.int32)
    grains = np.flatnonzero(current.is_sample)
    pos = current.positions[grains]
    if found.band is not None:
        labels[grains[_slab_members(found.band, pos)]] = 1
        if found.second is not None:
            second = grains[_slab_members(found.second, pos)]
            labels[second[labels[second] == 0]] = 2
    return labels


def fabric_numbers(run_dir: str | Path, *, peak_snapshot: str | int | None = None) -> FabricNumbers:
    """The numbers of :func:`fabric_figures` without drawing anything."""
    return _analyse(run_dir, peak_snapshot).numbers


# ----------------------------------------------------------------------------- drawing
def _percent(strain: float) -> str:
    return (
        "unknown strain"
        if not math.isfinite(strain)
        else rf"$\varepsilon_{{11}}$ = {100 * strain:.2f} %"
    )


def _title(k: int, st: _State) -> str:
    return f"({string.ascii_lowercase[k]}) {st.label}, {_percent(st.strain)}"


def _distinct(states: Sequence[_State]) -> list[_State]:
    seen: set[str] = set()
    out = []
    for st in states:
        if st.name not in seen:
            seen.add(st.name)
            out.append(st)
    return out


def _new_figure(figsize: tuple[float, float]) -> Figure:
    with plot.paper_style():
        return Figure(figsize=figsize, layout="constrained")


def _polar_figure(states: list[_State], forces: bool) -> Figure:
    fig = _new_figure((3.3 * len(states), 3.6))
    axes = []
    with plot.paper_style():
        for k, st in enumerate(states):
            ax = fig.add_subplot(1, len(states), k + 1, projection="polar")
            fabric = st.forces if forces else st.normals
            title = _title(k, st)
            if fabric is None:
                ax.set_title(title + "\nno contact forces recorded")
                ax.set_yticks([])
            else:
                fabric.plot(ax=ax, title=title)
            axes.append(ax)
        if not forces:
            # contact counts compare directly: one radial scale for both states
            top = max(ax.get_ylim()[1] for ax in axes)
            for ax in axes:
                ax.set_ylim(0.0, top)
        for ax in axes:
            ax.yaxis.set_major_locator(MaxNLocator(4, integer=not forces))
            if forces:
                ax.yaxis.set_major_formatter(EngFormatter(unit="N", places=0))
        fig.suptitle(
            "Normal contact force distribution (summed normal force per bin)"
            if forces
            else "Contact normal distribution (contacts per bin)"
        )
    return fig


def _band_of(analysis: _Analysis, st: _State) -> _Band | None:
    for b in analysis.bands.values():
        if b.numbers.snapshot == st.name and st.role != "initial":
            return b
    return None


#: Maps are drawn in millimetres (a sample is a few centimetres across).
_MM = 1.0e3
#: Contact counts at or above this share the top colour of Fig. 13.
_COUNT_CAP = 6


def _annotate_band(ax: Any, band: _Band | None) -> None:
    if band is None:
        return
    if band.band is None:
        ax.set_title(ax.get_title() + "\nno shear band found")
        return
    b = band.numbers
    text = f"band {b.inclination_deg:.0f}° to horizontal, {b.thickness_diameters:.1f} d"
    if band.second is not None:
        text += (
            f"\nsecond band {b.second_inclination_deg:.0f}°, {b.second_thickness_diameters:.1f} d"
        )
    ax.set_title(ax.get_title() + "\n" + text)
    for found, style, label in (
        (band.band, "--", "shear band"),
        (band.second, ":", "second band"),
    ):
        if found is None:
            continue
        for k, seg in enumerate(found.outline()):
            ax.plot(
                _MM * seg[:, 0],
                _MM * seg[:, 1],
                color="crimson",
                linestyle=style,
                linewidth=1.0,
                label=label if k == 0 else None,
            )


def _map_size(snap: Snapshot, n: int, colorbars: int) -> tuple[float, float]:
    pos = snap.positions
    aspect = float(np.ptp(pos[:, 1]) / max(np.ptp(pos[:, 0]), 1e-300)) if len(pos) else 1.0
    panel_w = 2.2 if n > 1 else 2.8
    width = n * panel_w + 0.8 * colorbars + 0.4
    height = float(np.clip(panel_w * aspect, 1.8, 6.0)) + 1.1
    return (min(width, 10.0), height)


def _draw_map(ax: Any, k: int, st: _State, values: NDArray[np.float64], **kwargs: Any) -> None:
    plot.particle_map(_MM * st.snap.positions, _MM * st.snap.radii, values, ax=ax, **kwargs)
    ax.set_title(_title(k, st))
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)" if k == 0 else "")


def _displacement_figure(analysis: _Analysis) -> Figure | None:
    panels = [
        st
        for st in _distinct([analysis.states["peak"], analysis.states["final"]])
        if _band_of(analysis, st) is not None
    ]
    if not panels:
        return None
    fig = _new_figure(_map_size(panels[0].snap, len(panels), len(panels)))
    with plot.paper_style():
        for k, st in enumerate(panels):
            band = _band_of(analysis, st)
            assert band is not None
            ax = fig.add_subplot(1, len(panels), k + 1)
            # each state on its own scale: displacements grow by an order of magnitude
            _draw_map(
                ax, k, st, _MM * band.displacement, vmin=0.0, label="displacement magnitude (mm)"
            )
            _annotate_band(ax, band)
        fig.suptitle(
            f"Particle displacements since the initial state ({analysis.states['initial'].name})"
        )
    return fig


def _shared_map_figure(
    analysis: _Analysis,
    values: Any,
    *,
    label: str,
    suptitle: str,
    discrete: bool = False,
    vmin: float | None = None,
    vmax: float | None = None,
    cmap: str = "viridis",
) -> Figure:
    panels = _distinct([analysis.states[r] for r in ("initial", "peak", "final")])
    vals = [np.asarray(values(st), dtype=np.float64) for st in panels]
    finite = np.concatenate([v[np.isfinite(v)] for v in vals])
    lo = vmin if vmin is not None else (float(finite.min()) if finite.size else 0.0)
    hi = vmax if vmax is not None else (float(finite.max()) if finite.size else 1.0)
    fig = _new_figure(_map_size(panels[0].snap, len(panels), 1))
    with plot.paper_style():
        axes = [fig.add_subplot(1, len(panels), k + 1) for k in range(len(panels))]
        for k, (ax, st, v) in enumerate(zip(axes, panels, vals, strict=True)):
            _draw_map(ax, k, st, v, cmap=cmap, vmin=lo, vmax=hi, discrete=discrete, colorbar=False)
            _annotate_band(ax, _band_of(analysis, st))
        cb = fig.colorbar(axes[0].collections[0], ax=axes, shrink=0.8, label=label)
        if discrete:
            ticks = np.arange(round(lo), round(hi) + 1)
            cb.set_ticks(ticks)
            names = [str(t) for t in ticks]
            if hi >= _COUNT_CAP:
                names[-1] = f"≥ {ticks[-1]}"
            cb.set_ticklabels(names)
            cb.minorticks_off()
        fig.suptitle(suptitle)
    return fig


def _series_figure(analysis: _Analysis, which: str) -> Figure:
    ts = analysis.results.timeseries
    eps = ts["axial_strain"]
    fig = _new_figure((4.2, 3.0))
    with plot.paper_style():
        ax = fig.add_subplot()
        if which == "anisotropy":
            plot.anisotropy_series(
                eps, ts["anisotropy"], normal_force=ts["force_anisotropy"], ax=ax
            )
        else:
            plot.mean_lambda_series(
                eps, ts["mean_stability_index"], mean_lambda_all=ts.get("mean_stability_index_all"), ax=ax
            )
        if len(eps) > 60:  # markers only clutter a long record
            for line in ax.get_lines():
                line.set_marker("")
        n = analysis.numbers
        ax.axvline(
            100 * n.peak_axial_strain,
            color="0.5",
            linestyle=":",
            linewidth=0.9,
            label=rf"peak $\sigma_1/\sigma_3$ ({100 * n.peak_axial_strain:.2f} %)",
        )
        ax.legend(frameon=False)
        ax.set_xlim(left=min(0.0, 100 * float(np.nanmin(eps))))
    return fig


def _contact_counts(st: _State) -> NDArray[np.float64]:
    counts = np.minimum(st.stability.n_contacts, _COUNT_CAP).astype(np.float64)
    return np.where(st.snap.is_sample, counts, np.nan)


def fabric_figures(
    run_dir: str | Path,
    out_dir: str | Path | None = None,
    *,
    peak_snapshot: str | int | None = None,
) -> FabricFigures:
    """Draw the paper's Figs. 6, 7, 9, 11, 12, 13, 14 of a biaxial run, PNG + SVG.

    Parameters
    ----------
    run_dir
        A run folder holding ``run.h5``, or the ``run.h5`` file itself.
    out_dir
        Where to write the figures; default the run folder.
    peak_snapshot
        The snapshot standing for the peak state, by name or position;
        default the snapshot (other than the first) closest in axial strain
        to the peak of ``stress_ratio``.

    Returns
    -------
    FabricFigures
        ``{figure name: [png, svg]}`` for the names in :data:`FIGURES`
        (``fig11_displacement`` is absent when the run has a single snapshot),
        with the numbers in ``.numbers`` (:class:`FabricNumbers`).

    Raises
    ------
    MissingColumnError
        A column of :data:`REQUIRED_COLUMNS` is missing from the time series.
    ValueError
        No snapshots, no finite stress ratio, or an unknown ``peak_snapshot``.
    """
    analysis = _analyse(run_dir, peak_snapshot)
    out = Path(out_dir) if out_dir is not None else analysis.results.path.parent
    out.mkdir(parents=True, exist_ok=True)
    states = analysis.states
    polar_states = _distinct([states["initial"], states["peak"]])
    lam_label = r"geometrical stability index $\lambda$"
    drawn: dict[str, Figure | None] = {
        "fig06_contact_normals": _polar_figure(polar_states, forces=False),
        "fig07_normal_forces": _polar_figure(polar_states, forces=True),
        "fig09_anisotropy": _series_figure(analysis, "anisotropy"),
        "fig11_displacement": _displacement_figure(analysis),
        "fig12_stability_index": _shared_map_figure(
            analysis,
            lambda st: st.stability.stability_index,
            label=lam_label,
            suptitle=r"Geometrical stability index $\lambda$ of the grains",
            vmin=0.0,
            vmax=1.0,
        ),
        "fig13_contact_count": _shared_map_figure(
            analysis,
            _contact_counts,
            label="number of contacts",
            discrete=True,
            suptitle="Number of contacts per grain (boundary contacts included)",
            vmin=0.0,
        ),
        "fig14_mean_stability_index": _series_figure(analysis, "lambda"),
    }
    files: dict[str, list[Path]] = {}
    for name, fig in drawn.items():
        if fig is not None:
            files[name] = plot.save_figure(fig, out / name)
    return FabricFigures(files, analysis.numbers)


def _main(argv: Sequence[str] | None = None) -> int:  # pragma: no cover - convenience
    import sys

    args = list(sys.argv[1:] if argv is None else argv)
    figs = fabric_figures(args[0], args[1] if len(args) > 1 else None)
    print(figs.numbers)
    print(json.dumps({k: [str(p) for p in v] for k, v in figs.items()}, indent=1))
    return 0


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(_main())
