"""Results declared once: the Computed descriptor and the Compute base."""

import pickle

import numpy as np
import pytest

from grainlab.analysis import CoordinationNumber, ShearBand
from grainlab.analysis._compute import Compute, Computed
from grainlab.analysis._util import NotComputedError
from grainlab.snapshot import Snapshot


class _Pair(Compute):
    total = Computed[float]("The sum, m.")
    product = Computed[float]("The product, m^2.")

    def compute(self, a: float, b: float) -> "_Pair":
        self._store(total=a + b, product=a * b)
        return self


def test_a_result_raises_until_computed_naming_the_measure_and_the_result():
    with pytest.raises(NotComputedError, match=r"_Pair\.product is not available: call compute"):
        _ = _Pair().product
    pair = _Pair().compute(2.0, 3.0)
    assert (pair.total, pair.product) == (5.0, 6.0)


def test_the_declaration_is_the_doc_and_is_read_only():
    assert _Pair.total.__doc__ == "The sum, m."
    assert CoordinationNumber.rattlers.__doc__ == "(N,) mask of the rattlers."
    pair = _Pair().compute(1.0, 1.0)
    with pytest.raises(AttributeError, match="set by compute"):
        pair.total = 3.0


def test_compute_must_store_every_declared_result_and_no_other():
    with pytest.raises(TypeError):
        _Pair()._store(total=1.0)
    with pytest.raises(TypeError):
        _Pair()._store(total=1.0, product=1.0, mean=1.0)


def test_a_reading_inherits_the_slab_results_and_adds_its_own():
    names = set(ShearBand._record.__dataclass_fields__)
    assert {"found", "angle", "thickness", "members", "prominence", "second"} <= names
    x, y = np.meshgrid(np.arange(6.0), np.arange(6.0))
    snap = Snapshot.from_geometry(np.c_[x.ravel(), y.ravel()], np.full(36, 0.5),
                                  box=[[0, 6], [0, 6]], periodic=(True, True), tolerance=1e-9)
    z = CoordinationNumber().compute(snap)
    assert z.coordination_number == 4.0 and z.n_contacts.shape == (36,)


def test_a_computed_measure_pickles_with_its_results():
    """Measures travel to worker processes (the figure pool) with their results."""
    x, y = np.meshgrid(np.arange(6.0), np.arange(6.0))
    snap = Snapshot.from_geometry(np.c_[x.ravel(), y.ravel()], np.full(36, 0.5),
                                  box=[[0, 6], [0, 6]], periodic=(True, True), tolerance=1e-9)
    z = pickle.loads(pickle.dumps(CoordinationNumber().compute(snap)))
    assert z.coordination_number == 4.0 and np.array_equal(z.n_contacts, np.full(36, 4))


def test_the_repr_shows_the_declared_parameters_under_their_constructor_names():
    assert repr(ShearBand(second=False, min_fill=0.25)) == (
        "ShearBand(bin_width=0.5, max_points=20000, min_fill=0.25, min_thickness=1.0, "
        "min_prominence=2.0, second=False)"
    )
    assert repr(CoordinationNumber(3, True, "each")) == (
        "CoordinationNumber(min_contacts=3, include_boundary=True, boundary='each')"
    )
    assert repr(_Pair()) == "_Pair()"
