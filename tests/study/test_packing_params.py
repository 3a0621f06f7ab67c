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


@pytest.mark.parametrize("generation_friction", [0.0, "search"])
def test_an_engine_stop_below_the_stress_bound_is_expanded_again_with_real_masses(monkeypatch,
                                                                                  generation_friction):
    import grainlab.samples
    import grainlab.samples.friction_search as friction_search
    from grainlab.samples import ExpansionError

    real = grainlab.samples.expand_to_porosity
    scaling = []

    def stops_once(*args, density_scaling=True, **kwargs):
        scaling.append(density_scaling)
        if len(scaling) == 1:  # the overlap limit, at 2 MPa: below the 5 MPa bound
            raise ExpansionError("porosity: the engine stopped", porosity=0.14, porosity_overlap_corrected=0.145,
                                 stress_pa=2.0e6, target=0.14, equilibrium=False, engine_stopped=True)
        return real(*args, density_scaling=density_scaling, **kwargs)

    monkeypatch.setattr(grainlab.samples, "expand_to_porosity", stops_once)
    monkeypatch.setattr(friction_search, "expand_to_porosity", stops_once)
    row = run_packing({"kind": "irregular", "porosity": 0.14, "width": 0.02, "height": 0.04, "seed": 3,
                       "generation_friction": generation_friction})
    assert scaling == [True, False]
    assert row["status"] == "ok" and row["porosity"] == pytest.approx(0.14, abs=1e-12)
    assert row["generation_expansions"] == 2
    assert "the first expansion stopped at the engine's overlap limit at 2 MPa" in row["note"]


def test_the_stress_bound_is_not_retried(monkeypatch):
    import grainlab.samples
    from grainlab.samples import ExpansionError

    calls = []

    def over_the_bound(*args, **kwargs):
        calls.append(kwargs)
        raise ExpansionError("porosity: over the bound", porosity=0.1, porosity_overlap_corrected=0.11,
                             stress_pa=6.0e6, target=0.08, equilibrium=True)

    monkeypatch.setattr(grainlab.samples, "expand_to_porosity", over_the_bound)
    with pytest.raises(ExpansionError):
        run_packing({"kind": "irregular", "porosity": 0.08, "width": 0.02, "height": 0.04,
                     "generation_friction": 0.0})
    # one attempt at the target, then the densest-reached fallback at 0.102 (which fails here too)
    assert len(calls) == 2 and calls[0]["density_scaling"] and calls[1]["density_scaling"]
