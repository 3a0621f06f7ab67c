r"""The fabric numbers of a biaxial run, from its ``run.h5``: states, peak, shear bands.

:func:`fabric_numbers` and :func:`analyse_run` (with the computed measures, for
the figures): docs/analysis.md, "Figures of a biaxial run".
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from grainlab.analysis.fabric import ContactAnisotropy, CoordinationNumber
from grainlab.analysis.peak import nearest_snapshot, peak_is_interior, peak_record
from grainlab.analysis.per_body import BodyStabilityIndex, BodyView
from grainlab.analysis.stability import StabilityIndex
from grainlab.columns import AXIAL_STRAIN, STRESS_RATIO
from grainlab.io.hdf5 import Results, read_results, snapshot_strain
from grainlab.io.results import json_safe
from grainlab.postprocess.band import BandNumbers, BandSearch
from grainlab.postprocess.products import RunProducts
from grainlab.snapshot import Snapshot

__all__ = [
    "REQUIRED_COLUMNS",
    "FabricNumbers",
    "MissingColumnError",
    "RunAnalysis",
    "RunState",
    "StateNumbers",
    "analyse_run",
    "fabric_numbers",
]

#: Time-series columns needed, and what for.
REQUIRED_COLUMNS: dict[str, str] = {
    AXIAL_STRAIN: "the strain axis of Figs. 9 and 14",
    STRESS_RATIO: "locating the peak",
    "anisotropy": "a in Fig. 9",
    "force_anisotropy": "a_n in Fig. 9",
    "mean_stability_index": "Fig. 14",
}


class MissingColumnError(ValueError):
    """The run's time series lacks a column the figures need (the message names it)."""


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

    def _of_found_band(self, name: str) -> float:
        return float(getattr(self.band, name)) if self.band_found else math.nan

    @property
    def band_angle_deg(self) -> float:
        """Band angle at the peak snapshot, degrees (NaN when not found)."""
        return self._of_found_band("angle_deg")

    @property
    def band_thickness_diameters(self) -> float:
        """Band thickness at the peak snapshot in mean grain diameters (NaN when not found)."""
        return self._of_found_band("thickness_diameters")

    @property
    def mean_lambda_in_band(self) -> float:
        return self._of_found_band("mean_lambda_inside")

    @property
    def mean_lambda_outside_band(self) -> float:
        return self._of_found_band("mean_lambda_outside")

    def summary(self) -> dict[str, Any]:
        """JSON-ready dict (NaN as None, paths as strings)."""
        summary: dict[str, Any] = json_safe(
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
        return summary

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


@dataclass
class RunState:
    """One state of the run (initial, peak, final) with its computed measures."""

    role: str
    name: str
    strain: float
    snap: Snapshot
    stability: StabilityIndex
    normals: ContactAnisotropy
    forces: ContactAnisotropy | None
    #: How the figures name the state.
    label: str = ""
    #: The pebbles and their bodies, when ``snap`` holds a run of clumps' bodies.
    view: BodyView | None = None


@dataclass
class RunAnalysis:
    """:func:`analyse_run`'s result: the numbers, the results file, the states and the bands."""

    numbers: FabricNumbers
    results: Results
    states: dict[str, RunState]
    #: ``"peak"`` / ``"final"``.
    bands: dict[str, BandSearch]

    def band_of(self, st: RunState) -> BandSearch | None:
        """The band searched at ``st``'s snapshot (None for the initial state or when none was)."""
        for b in self.bands.values():
            if b.numbers.snapshot == st.name and st.role != "initial":
                return b
        return None


def _timeseries(results: Results) -> dict[str, NDArray[np.float64]]:
    ts = results.timeseries
    for column, purpose in REQUIRED_COLUMNS.items():
        if column not in ts:
            raise MissingColumnError(
                f"{results.path}: the time series has no column {column!r} (needed for "
                f"{purpose}); its columns are {sorted(ts)}"
            )
    if len(ts[AXIAL_STRAIN]) == 0:
        raise ValueError(f"{results.path}: the time series is empty")
    return ts


def _state(role: str, name: str, strain: float, products: RunProducts) -> RunState:
    """The state at snapshot ``name``, per body when ``products`` are (a disk's lambda when they are not)."""
    snap = products.snapshot(name)
    stability = (BodyStabilityIndex().compute(products.view(name)) if products.per_body
                 else StabilityIndex().compute(snap))
    forces = (
        ContactAnisotropy(weight="normal_force").compute(snap)
        if snap.normal_force is not None
        else None
    )
    return RunState(
        role,
        name,
        strain,
        snap,
        stability,
        ContactAnisotropy().compute(snap),
        forces,
        view=products.view(name) if products.per_body else None,
    )


def _state_numbers(st: RunState) -> StateNumbers:
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


def _band(products: RunProducts, reference: RunState, current: RunState) -> BandSearch:
    """The stored band search at ``current`` (made anew when the file holds none), labelled
    with the states' names and strain."""
    found = products.band_search(current.name)
    numbers = replace(found.numbers, snapshot=current.name, reference=reference.name, axial_strain=current.strain)
    return replace(found, numbers=numbers)


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
    return nearest_snapshot(strains, eps_peak)


def _bands(products: RunProducts, states: dict[str, RunState], k_snap: int, last: int,
           notes: list[str]) -> dict[str, BandSearch]:
    """The shear bands from the initial state to the peak and to the final state
    (snapshots ``k_snap`` and ``last``), where those differ from it; what is
    missing goes to ``notes``."""
    bands: dict[str, BandSearch] = {}
    if k_snap == 0 and last == 0:
        notes.append("only one snapshot: no displacements and no shear band")
        return bands
    if k_snap != 0:
        bands["peak"] = _band(products, states["initial"], states["peak"])
    if last not in (0, k_snap):
        bands["final"] = _band(products, states["initial"], states["final"])
    for key, b in bands.items():
        if not b.numbers.found:
            notes.append(
                f"no shear band found at {b.numbers.snapshot} ({key} state): its maps have no "
                "outline (BandNumbers.reason says why)"
            )
    return bands


def analyse_run(run_dir: str | Path, peak_snapshot: str | int | None = None) -> RunAnalysis:
    """Read ``run.h5`` of ``run_dir`` and measure its states and bands (docs/analysis.md).

    Raises :class:`MissingColumnError` when a column of :data:`REQUIRED_COLUMNS`
    is missing, ``ValueError`` for no snapshots, no finite stress ratio or an
    unknown ``peak_snapshot``.
    """
    results = read_results(run_dir)
    ts = _timeseries(results)
    names = results.snapshot_names
    if not names:
        raise ValueError(f"{results.path}: the run has no snapshots")
    # a run of clumps is measured per body (docs/fabric.md, "Measures per body")
    products = RunProducts(results, per_body=True)
    notes: list[str] = []
    eps = np.asarray(ts[AXIAL_STRAIN], dtype=np.float64)
    q = np.asarray(ts[STRESS_RATIO], dtype=np.float64)
    finite = np.isfinite(eps) & np.isfinite(q)
    if not finite.any():
        raise ValueError(
            f"{results.path}: no record has both a finite axial_strain and a finite stress_ratio"
        )
    rows = np.flatnonzero(finite)
    k_peak = peak_record(eps, q)
    interior = peak_is_interior(eps, q)
    eps_peak = float(eps[k_peak])
    if not interior:
        where = "last" if k_peak == rows[-1] else "first"
        notes.append(
            f"the stress ratio is largest at the {where} record ({100 * eps_peak:.2f} %): no peak "
            "inside the record; that record stands for the peak"
        )

    strains = [snapshot_strain(info) for info in results.snapshots]
    k_snap = _select_peak(results, strains, eps_peak, peak_snapshot)
    if peak_snapshot is None and math.isfinite(strains[k_snap]):
        gap = abs(strains[k_snap] - eps_peak)
        if gap > max(0.002, 0.25 * abs(eps_peak)):
            notes.append(
                f"no snapshot near the stress-ratio peak ({100 * eps_peak:.2f} %): the closest, "
                f"{names[k_snap]}, is at {100 * strains[k_snap]:.2f} %"
            )

    cache: dict[int, RunState] = {}

    def state(role: str, k: int) -> RunState:
        if k not in cache:
            cache[k] = _state(role, names[k], strains[k], products)
        st = cache[k]
        label = {"initial": "initial", "peak": "nearest the peak", "final": "final"}[role]
        if role == "peak" and peak_snapshot is not None:
            label = "chosen peak state"
        return replace(st, role=role, label=label)

    last = len(names) - 1
    states = {"initial": state("initial", 0), "peak": state("peak", k_snap)}
    states["final"] = state("final", last)
    if states["peak"].snap.normal_force is None:
        notes.append(f"{names[k_snap]} has no contact forces: no normal-force diagram data")

    bands = _bands(products, states, k_snap, last, notes)
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
    return RunAnalysis(numbers, results, states, bands)


def fabric_numbers(run_dir: str | Path, *, peak_snapshot: str | int | None = None) -> FabricNumbers:
    """The numbers of :func:`~grainlab.postprocess.figures.fabric_figures` without drawing anything."""
    return analyse_run(run_dir, peak_snapshot).numbers
