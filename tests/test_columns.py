"""The time-series columns' one home (grainlab.columns): the records the
protocols write, the docs' tables and the readers agree with it."""

from __future__ import annotations

import pickle
from pathlib import Path

import pytest

from grainlab.columns import AXIAL_STRAIN, BIAXIAL, BY_KIND, Column, Columns, update_markdown
from grainlab.io.hdf5 import read_results

DOCS = Path(__file__).resolve().parents[1] / "docs" / "file-formats.md"


def test_a_column_is_its_name_with_a_unit_and_a_meaning():
    record = {"axial_strain": 0.01}
    assert record[AXIAL_STRAIN] == 0.01 and AXIAL_STRAIN == "axial_strain"
    assert (AXIAL_STRAIN.unit, "compression positive" in AXIAL_STRAIN.meaning) == ("1", True)
    copy = pickle.loads(pickle.dumps(AXIAL_STRAIN))  # figure workers receive columns
    assert (copy, copy.unit, copy.meaning) == (AXIAL_STRAIN, AXIAL_STRAIN.unit, AXIAL_STRAIN.meaning)


def test_a_column_listed_twice_is_refused():
    twice = Column("step", "1", "again")
    with pytest.raises(ValueError, match="listed twice"):
        Columns("broken", (twice,), (twice,))


def test_the_docs_tables_are_made_from_the_schema():
    text = DOCS.read_text(encoding="utf-8")
    assert update_markdown(text) == text, "run: python -m grainlab.columns docs/file-formats.md"
    for kind in BY_KIND:
        assert f"python/grainlab/columns.py: {kind} -->" in text


def test_a_generated_block_of_an_unknown_test_is_refused():
    block = "<!-- generated from python/grainlab/columns.py: triaxial -->\n<!-- end of generated block -->"
    with pytest.raises(ValueError, match="'triaxial'"):
        update_markdown(block)


def test_a_biaxial_run_records_exactly_the_schemas_columns_with_their_units(quick_biaxial_run):
    results = read_results(quick_biaxial_run / "run.h5")
    assert list(results.timeseries) == [str(c) for c in BIAXIAL]
    assert dict(results.timeseries_units) == BIAXIAL.units()
    header = (quick_biaxial_run / "timeseries.csv").read_text(encoding="utf-8").splitlines()[0]
    assert [name.split(" ")[0] for name in header.split(",")] == [str(c) for c in BIAXIAL]
