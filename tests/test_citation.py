"""The citation is one: CITATION.cff, grainlab.citation (the report's footer,
``grainlab --version``), the package's version and the README say the same."""

from __future__ import annotations

import subprocess
import sys
import tomllib
from pathlib import Path

import yaml

import grainlab
from grainlab._html import footer
from grainlab.citation import ARTICLE, TITLE, how_to_cite

ROOT = Path(__file__).resolve().parents[1]


def _cff() -> dict:
    return yaml.safe_load((ROOT / "CITATION.cff").read_text(encoding="utf-8"))


def test_the_version_is_one_in_citation_cff_the_package_cargo_and_grainlab_version():
    version = str(_cff()["version"])
    cargo = tomllib.loads((ROOT / "Cargo.toml").read_text(encoding="utf-8"))["workspace"]["package"]["version"]
    pyproject = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    assert "version" in pyproject["project"]["dynamic"]  # maturin takes it from Cargo.toml
    assert version == grainlab.__version__ == cargo
    printed = subprocess.run([sys.executable, "-m", "grainlab", "--version"], capture_output=True,
                             text=True, check=True).stdout.splitlines()
    assert printed[0] == f"grainlab {version}"
    assert printed[1] == how_to_cite()


def test_citation_cff_is_well_formed():
    cff = _cff()
    assert cff["cff-version"] == "1.2.0"
    assert cff["type"] == "software"
    assert cff["message"].strip() and cff["title"] == TITLE
    assert cff["license"] == tomllib.loads((ROOT / "Cargo.toml").read_text("utf-8"))["workspace"]["package"]["license"]
    for person in [*cff["authors"], *(a for ref in cff["references"] for a in ref["authors"])]:
        assert person.get("name") or person.get("family-names"), person


def test_the_reference_is_the_article_grainlab_reproduces():
    (reference,) = _cff()["references"]
    assert reference["type"] == "article"
    fields = {key: reference[key] for key in ("title", "journal", "year", "volume", "issue", "start", "end", "doi")}
    assert fields == {
        "title": ARTICLE.title, "journal": ARTICLE.journal, "year": ARTICLE.year, "volume": ARTICLE.volume,
        "issue": ARTICLE.issue, "start": ARTICLE.start, "end": ARTICLE.end, "doi": ARTICLE.doi,
    }
    assert str(ARTICLE) == ('"An Introduction to the Geometrical Stability Index: A Fabric Quantity", '
                            "Geotechnics 2022, 2(2), 297-316, doi:10.3390/geotechnics2020013")


def test_the_report_footer_and_the_readme_cite_grainlab_and_the_article():
    assert how_to_cite() in footer() and f"grainlab {grainlab.__version__}" in footer()
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    assert "CITATION.cff" in readme
    assert ARTICLE.title in readme and ARTICLE.doi in readme
