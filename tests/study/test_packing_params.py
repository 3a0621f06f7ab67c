"""PackingParams: the generation friction, fixed or searched, and its checks."""

import math

import pytest

from grainlab.study import PackingParams, run_packing
from grainlab.study.packing import GENERATION_FRICTION_SEARCH


def test_the_default_searches_and_a_number_fixes_the_generation_friction():
    default = PackingParams()
    assert default.generation_friction == GENERATION_FRICTION_SEARCH == "search"
    assert default.searches_friction and default.friction == 0.9
    assert (default.search_stress_min, default.search_stress_max) == (1.0e5, 3.0e5)
    for value in (0, 0.0, 0.9):
        fixed = PackingParams.from_mapping({"generation_friction": value})
        assert fixed.generation_friction == float(value) and not fixed.searches_friction
    assert PackingParams.from_mapping({"generation_friction": "search"}).searches_friction


@pytest.mark.parametrize(
    ("values", "field"),
    [
        ({"generation_friction": "Search"}, "generation_friction"),
        ({"generation_friction": True}, "generation_friction"),
        ({"generation_friction": -0.2}, "generation_friction"),
        ({"generation_friction": math.nan}, "generation_friction"),
        ({"generation_friction": [0.1]}, "generation_friction"),
        ({"search_stress_min": 0.0}, "search_stress_min"),
        ({"search_stress_min": 3e5, "search_stress_max": 3e5}, "search_stress_min"),
        ({"search_stress_max": 6e6}, "search_stress_max"),  # above max_stress (5 MPa)
        ({"friction": 0.0}, "friction"),  # the search's bracket [0, friction] would be empty
    ],
)
def test_bad_values_name_the_field(values, field):
    with pytest.raises(ValueError, match=field):
        PackingParams.from_mapping(values)


def test_the_search_settings_do_not_apply_to_a_lattice():
    # a lattice is built, not generated: a zero friction is no empty search bracket for it
    p = PackingParams.from_mapping({"kind": "hexagonal", "friction": 0.0})
    assert p.kind == "hexagonal"
    row = run_packing({"kind": "hexagonal", "porosity": 0.12, "width": 0.02, "height": 0.04})
    assert math.isnan(row["generation_friction"]) and row["generation_expansions"] == 0
    assert row["friction_search"] == "" and row["seed"] == 0
