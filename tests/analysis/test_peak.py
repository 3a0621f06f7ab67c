"""The one peak rule: the largest finite stress ratio (the first of equal maxima), and
the snapshot nearest it other than the initial state."""

from __future__ import annotations

import math

import numpy as np
import pytest

from grainlab.analysis.peak import nearest_snapshot, peak_is_interior, peak_record


def test_the_peak_is_the_first_of_equal_maxima_among_finite_records():
    eps = [0.0, 0.01, 0.02, 0.03, 0.04]
    assert peak_record(eps, [1.0, 2.5, 3.0, 3.0, 2.0]) == 2
    assert peak_record(eps, [1.0, 2.5, np.nan, 3.0, np.inf]) == 3  # NaN and inf records left out
    assert peak_record([0.0, np.nan, 0.02], [1.0, 9.0, 2.0]) == 2  # a record without its strain too
    with pytest.raises(ValueError, match="no record"):
        peak_record([np.nan], [1.0])
    with pytest.raises(ValueError, match="one length"):
        peak_record([0.0, 1.0], [1.0])


def test_a_peak_at_either_end_of_the_record_is_not_interior():
    eps = [0.0, 0.01, 0.02, 0.03]
    assert peak_is_interior(eps, [1.0, 3.0, 2.0, 1.5])
    assert not peak_is_interior(eps, [1.0, 2.0, 2.5, 3.0])  # still rising at the end
    assert not peak_is_interior(eps, [1.0, 2.0, 2.5, np.nan])  # the last finite record is the end
    assert not peak_is_interior(eps, [4.0, 2.0, 2.5, 3.0])


def test_the_peak_snapshot_is_the_nearest_but_the_initial_state():
    strains = [0.0, 0.005, 0.015, 0.10]
    assert nearest_snapshot(strains, 0.012) == 2
    assert nearest_snapshot(strains, 0.0) == 1  # the initial state is never the peak's
    assert nearest_snapshot([0.0, 0.25, 0.75, 1.0], 0.5) == 1  # equal distances: the first
    assert nearest_snapshot([0.0], 0.02) == 0  # only the initial state
    assert nearest_snapshot([0.0, math.nan, 0.03], 0.002) == 2  # unknown strains left out
    assert nearest_snapshot(strains, math.nan) == 3
    with pytest.raises(ValueError, match="no snapshots"):
        nearest_snapshot([], 0.01)
