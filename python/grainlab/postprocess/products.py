"""The analysis products of a run, stored in its ``run.h5`` rather than found again.

:func:`store_run_products` makes them, :class:`RunProducts` reads them (made anew,
unstored, when the file lacks them), each against the run's first snapshot with
the version of its rule: docs/file-formats.md, "/analysis/<product>/<snapshot>".
``RunProducts(results, per_body=True)`` reads a run of clumps per body, made anew
(docs/file-formats.md).
"""

from __future__ import annotations

import dataclasses
import math
import os
from collections.abc import Callable, Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from grainlab.analysis.force_chains import ForceChains
from grainlab.analysis.per_body import BodyStabilityIndex, BodyView, body_view
from grainlab.analysis.shear_band import Slab
from grainlab.analysis.stability import StabilityIndex
from grainlab.analysis.tessellation import LocalPorosity
from grainlab.io.hdf5 import AnalysisItem, Results, read_results, snapshot_strain, write_analysis
from grainlab.postprocess.band import (
    BandNumbers,
    BandSearch,
    DisplacementZone,
    displacement_zone,
    find_band,
    find_field_band,
    lambda_indicator,
)
from grainlab.snapshot import Snapshot

if TYPE_CHECKING:
    from grainlab.plot.workers import FigurePool

__all__ = ["PRODUCTS", "LambdaField", "RunProducts", "store_run_products"]

#: The products a run stores, with the version of the rule that makes each (docs/file-formats.md).
PRODUCTS: dict[str, int] = {
    "stability_index": 1,
    "band_strain": 1,
    "band_lambda": 1,
    "band_displacement": 1,
    "local_porosity": 1,
    "force_chains": 1,
}

#: The products of every snapshot, the reference included (the others are against it).
_OF_EVERY_SNAPSHOT = ("stability_index", "local_porosity", "force_chains")

_NUMBER_FIELDS = tuple(f.name for f in dataclasses.fields(BandNumbers))
_SLAB_SCALARS = ("found", "angle", "thickness", "thickness_diameters")
_SLAB_ARRAYS = ("center", "normal", "extent")


@dataclasses.dataclass(frozen=True)
class LambdaField:
    """One snapshot's geometrical stability index, per particle (the stored
    ``stability_index`` product: :class:`~grainlab.analysis.StabilityIndex` defaults)."""

    #: (N,) lambda of each particle (NaN below two contacts).
    stability_index: NDArray[np.float64]
    #: (N,) contacts of each particle counted by lambda.
    n_contacts: NDArray[np.int64]


# ------------------------------------------------------------------ items of the file
def _slab_attrs(prefix: str, slab: Slab | None) -> dict[str, Any]:
    if slab is None:
        return {}
    attrs: dict[str, Any] = {f"{prefix}.{k}": getattr(slab, k) for k in _SLAB_SCALARS}
    attrs.update({f"{prefix}.{k}": np.asarray(getattr(slab, k), np.float64) for k in _SLAB_ARRAYS})
    return attrs


def _slab_of(attrs: Mapping[str, Any], prefix: str) -> Slab | None:
    if f"{prefix}.angle" not in attrs:
        return None
    scalars = {k: attrs[f"{prefix}.{k}"] for k in _SLAB_SCALARS}
    arrays = {k: np.asarray(attrs[f"{prefix}.{k}"], np.float64) for k in _SLAB_ARRAYS}
    arrays["extent"] = arrays["extent"].reshape(2, 2)
    return Slab(
        found=bool(scalars["found"]),
        angle=float(scalars["angle"]),
        thickness=float(scalars["thickness"]),
        thickness_diameters=float(scalars["thickness_diameters"]),
        **arrays,
    )


def _search_item(search: BandSearch, reference: str) -> AnalysisItem:
    attrs: dict[str, Any] = {"reference": reference}
    attrs.update({f"numbers.{k}": getattr(search.numbers, k) for k in _NUMBER_FIELDS})
    attrs.update(_slab_attrs("band", search.band))
    attrs.update(_slab_attrs("second", search.second))
    return AnalysisItem(attrs, {"displacement": search.displacement})


def _search_of(item: AnalysisItem) -> BandSearch:
    numbers = BandNumbers(**{k: item.attrs[f"numbers.{k}"] for k in _NUMBER_FIELDS})
    numbers = dataclasses.replace(
        numbers,
        found=bool(numbers.found),
        second_found=bool(numbers.second_found),
        n_grains=int(numbers.n_grains),
    )
    return BandSearch(
        numbers,
        _slab_of(item.attrs, "band"),
        np.asarray(item.arrays["displacement"], np.float64),
        _slab_of(item.attrs, "second"),
    )


def _zone_item(zone: DisplacementZone | None, reference: str) -> AnalysisItem:
    if zone is None:  # too few grains to split
        return AnalysisItem({"reference": reference, "split": False})
    attrs = {"reference": reference, "split": True, "found": zone.found, "reason": zone.reason,
             "residual_reduction": zone.residual_reduction, **_slab_attrs("zone", zone.zone)}
    return AnalysisItem(attrs, {"members": zone.members})


def _zone_of(item: AnalysisItem) -> DisplacementZone | None:
    if not item.attrs.get("split", False):
        return None
    zone = _slab_of(item.attrs, "zone")
    assert zone is not None
    return DisplacementZone(
        bool(item.attrs["found"]),
        str(item.attrs["reason"]),
        float(item.attrs["residual_reduction"]),
        zone,
        np.asarray(item.arrays["members"], np.int32),
    )


def _lambda_item(stability: StabilityIndex) -> AnalysisItem:
    return AnalysisItem(
        {},
        {
            "stability_index": np.asarray(stability.stability_index, np.float64),
            "n_contacts": np.asarray(stability.n_contacts, np.int64),
        },
    )


def _lambda_of(item: AnalysisItem) -> LambdaField:
    return LambdaField(
        np.asarray(item.arrays["stability_index"], np.float64),
        np.asarray(item.arrays["n_contacts"], np.int64),
    )


def _make_items(reference: Snapshot, current: Snapshot | BodyView, reference_name: str, name: str, strain: float,
                wanted: Sequence[str]) -> dict[str, AnalysisItem]:
    """The items ``wanted`` of one snapshot against the reference, made anew (per body
    when ``current`` is the :class:`BodyView` of a snapshot of clumps, ``reference``
    then its view's snapshot)."""
    items: dict[str, AnalysisItem] = {}
    needs_lambda = {"stability_index", "band_strain", "band_lambda"} & set(wanted)
    stability: StabilityIndex = StabilityIndex()
    if isinstance(current, BodyView):
        stability = BodyStabilityIndex().compute(current) if needs_lambda else stability
        current = current.snapshot
    elif needs_lambda:
        stability = stability.compute(current)
    if "stability_index" in wanted:
        items["stability_index"] = _lambda_item(stability)
    if "local_porosity" in wanted:
        porosity = LocalPorosity().compute(current).local_porosity
        items["local_porosity"] = AnalysisItem({}, {"local_porosity": np.asarray(porosity, np.float64)})
    if "force_chains" in wanted:
        chain = (ForceChains().compute(current).chain if current.normal_force is not None
                 else np.full(current.n_particles, -1))
        items["force_chains"] = AnalysisItem({}, {"chain": np.asarray(chain, np.int32)})
    if name == reference_name:
        return items  # no displacement against itself: no band products
    if "band_strain" in wanted:
        search = find_band(reference, current, stability, name=name, reference_name=reference_name,
                           axial_strain=strain)
        items["band_strain"] = _search_item(search, reference_name)
    if "band_lambda" in wanted:
        field = find_field_band(current, lambda_indicator(stability), stability, name=name, axial_strain=strain)
        items["band_lambda"] = _search_item(field, reference_name)
    if "band_displacement" in wanted:
        items["band_displacement"] = _zone_item(displacement_zone(reference, current), reference_name)
    return items


def _make_items_in_file(path: str, reference: str, name: str, strain: float,
                        wanted: Sequence[str]) -> tuple[str, dict[str, AnalysisItem]]:
    """:func:`_make_items` of two snapshots of the file at ``path`` (a worker's task)."""
    results = read_results(path)
    return name, _make_items(results.snapshot(reference), results.snapshot(name), reference, name, strain, wanted)


# ------------------------------------------------------------------ the run's products
class RunProducts:
    """The analysis products of one results file (docs/file-formats.md): each read from
    the file's analysis group when stored there, else made anew and kept here (not
    written: :func:`store_run_products` writes them).

    Parameters
    ----------
    results
        A :class:`~grainlab.io.hdf5.Results` or the path of a ``run.h5`` (or its folder).
    """

    def __init__(self, results: Results | str | os.PathLike[str], *, per_body: bool = False) -> None:
        self.results = results if isinstance(results, Results) else read_results(results)
        infos = list(self.results.snapshots)
        if not infos:
            raise ValueError(f"{self.results.path}: the run has no snapshots")
        self._strain = {info.name: snapshot_strain(info) for info in infos}
        #: The snapshot every product is taken against: the first written (the start of
        #: shearing, the smallest axial strain of a biaxial run).
        self.reference = min(infos, key=lambda info: info.index).name
        # the others by axial strain, the first written on ties or without strains (NaN last)
        order = sorted((k for k in range(len(infos)) if infos[k].name != self.reference),
                       key=lambda k: (math.isnan(self._strain[infos[k].name]), self._strain[infos[k].name],
                                      infos[k].index))
        #: The snapshots in order of their axial strains, the reference first.
        self.names_by_strain = [self.reference] + [infos[k].name for k in order]
        self._made: dict[tuple[str, str], AnalysisItem] = {}
        self._snapshots: dict[str, Snapshot] = {}
        self._views: dict[str, BodyView] = {}
        #: Whether the products are per body (module docstring): asked for, and the run has clumps.
        self.per_body = per_body and not self.view(self.reference).identity

    def strain(self, name: str) -> float:
        """Snapshot ``name``'s axial strain (NaN when it has none)."""
        return self._strain[name]

    def snapshot(self, name: str) -> Snapshot:
        """Snapshot ``name`` of the file (read once); its bodies' snapshot when :attr:`per_body`."""
        return self._snapshot(name)

    def view(self, name: str) -> BodyView:
        """The :func:`~grainlab.analysis.body_view` of the file's snapshot ``name`` (made once)."""
        if name not in self._views:
            if name not in self._snapshots:
                self._snapshots[name] = self.results.snapshot(name)
            self._views[name] = body_view(self._snapshots[name])
        return self._views[name]

    def _snapshot(self, name: str) -> Snapshot:
        if self.per_body:
            return self.view(name).snapshot
        if name not in self._snapshots:
            self._snapshots[name] = self.results.snapshot(name)
        return self._snapshots[name]

    def _item(self, product: str, name: str) -> AnalysisItem:
        if name not in self._strain:
            raise ValueError(f"{name!r} is not a snapshot of {self.results.path} (snapshots: {list(self._strain)})")
        key = (product, name)
        if key in self._made:
            return self._made[key]
        if not self.per_body and self.results.analysis_versions.get(product) == PRODUCTS[product]:
            stored = self.results.analysis(product, name)
            if stored is not None and stored.attrs.get("reference", self.reference) == self.reference:
                self._made[key] = stored
                return stored
        current = self.view(name) if self.per_body else self._snapshot(name)
        made = _make_items(self._snapshot(self.reference), current, self.reference, name,
                           self._strain[name], [product])
        if product not in made:
            raise ValueError(f"{name!r} is the reference snapshot of {self.results.path}: it has no {product}")
        self._made[key] = made[product]
        return made[product]

    def stability_index(self, name: str) -> LambdaField:
        """The snapshot's lambda field (``stability_index``)."""
        return _lambda_of(self._item("stability_index", name))

    def local_porosity(self, name: str) -> NDArray[np.float64]:
        """(N,) the snapshot's local porosity of each particle (``local_porosity``)."""
        return np.asarray(self._item("local_porosity", name).arrays["local_porosity"], np.float64)

    def force_chains(self, name: str) -> NDArray[np.int32]:
        """(N,) the force chain of each particle of the snapshot, -1 outside them (``force_chains``)."""
        return np.asarray(self._item("force_chains", name).arrays["chain"], np.int32)

    def band_search(self, name: str) -> BandSearch:
        """The shear band of the local strain at snapshot ``name`` since the reference (``band_strain``)."""
        return _search_of(self._item("band_strain", name))

    def lambda_band(self, name: str) -> BandSearch:
        """The band of the grains with lambda > 0.5 at snapshot ``name`` (``band_lambda``)."""
        return _search_of(self._item("band_lambda", name))

    def displacement_zone(self, name: str) -> DisplacementZone | None:
        """Fig. 11's two-block split at snapshot ``name`` (``band_displacement``; None with too few grains)."""
        return _zone_of(self._item("band_displacement", name))

    def band_labels(self, name: str, reading: str = "strain") -> NDArray[np.int32]:
        """:func:`~grainlab.postprocess.band.band_labels` of snapshot ``name`` against the
        reference, from the stored products."""
        from grainlab.postprocess.band import READINGS

        if reading not in READINGS:
            raise ValueError(f"reading: must be one of {', '.join(map(repr, READINGS))}, got {reading!r}")
        if reading == "displacement":
            zone = self.displacement_zone(name)
            return np.zeros(self._snapshot(name).n_particles, np.int32) if zone is None else zone.labels
        found = self.lambda_band(name) if reading == "lambda" else self.band_search(name)
        return found.labels(self._snapshot(name))

    def missing(self) -> dict[str, list[str]]:
        """``snapshot -> products`` that the file does not hold (under the current rules)."""
        versions = self.results.analysis_versions
        todo: dict[str, list[str]] = {}
        with self.results.analysis_reader() as stored:
            for name in self.names_by_strain:
                for product, version in PRODUCTS.items():
                    if name == self.reference and product not in _OF_EVERY_SNAPSHOT:
                        continue
                    item = stored(product, name) if versions.get(product) == version else None
                    if item is None or item.attrs.get("reference", self.reference) != self.reference:
                        todo.setdefault(name, []).append(product)
        return todo


def store_run_products(
    results: Results | str | os.PathLike[str],
    pool: FigurePool | None = None,
    *,
    progress: Callable[[int, int], None] | None = None,
) -> Results:
    """Makes the products (docs/file-formats.md) that the results file does not hold yet, one
    task per snapshot in ``pool``'s workers (in this process without one), and stores them
    in its analysis group; returns the file read again. A file that holds them all is
    left untouched. ``progress(done, total)`` is called as snapshots are finished.

    Raises :class:`~grainlab.io.hdf5.ResultsFileError` for a file that is not a complete
    run, and ``OSError`` when it cannot be written.
    """
    products = RunProducts(results)
    run = products.results
    todo = products.missing()
    if not todo:
        return run
    path = str(run.path)
    made: dict[str, dict[str, AnalysisItem]] = {}
    total = len(todo)
    if pool is not None and pool.parallel and total > 1:
        tasks = [pool.submit(_make_items_in_file, path, products.reference, name, products.strain(name), wanted)
                 for name, wanted in todo.items()]
        for task in tasks:
            name, items = task.result()
            made[name] = items
            if progress is not None:
                progress(len(made), total)
    else:
        for name, wanted in todo.items():
            made[name] = _make_items(products.snapshot(products.reference), products.snapshot(name),
                                     products.reference, name, products.strain(name), wanted)
            if progress is not None:
                progress(len(made), total)
    by_product: dict[str, dict[str, AnalysisItem]] = {}
    for name, items in made.items():
        for product, item in items.items():
            by_product.setdefault(product, {})[name] = item
    write_analysis(run.path, {p: (PRODUCTS[p], items) for p, items in by_product.items()})
    return read_results(run.path)
