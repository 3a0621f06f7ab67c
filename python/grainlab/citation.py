"""How to cite grainlab: the software, and the article whose study it reproduces.

The repository's ``CITATION.cff`` is the citation (GitHub shows it as "Cite this
repository"); this module says the same inside the installed package, for the
report's footer and ``grainlab --version``. tests/test_citation.py holds the two
together, and the file's version to :data:`grainlab.__version__`.

>>> from grainlab.citation import ARTICLE
>>> ARTICLE.doi
'10.3390/geotechnics2020013'
"""

from __future__ import annotations

from dataclasses import dataclass

from grainlab._core import __version__

__all__ = ["ARTICLE", "TITLE", "Article", "how_to_cite"]

#: The software's title, as CITATION.cff gives it.
TITLE = "grainlab: a 2D discrete element laboratory for granular soils"


@dataclass(frozen=True)
class Article:
    """A journal article: what a reference to it needs."""

    title: str
    journal: str
    year: int
    volume: int
    issue: int
    start: int
    end: int
    doi: str

    def __str__(self) -> str:
        return (
            f'"{self.title}", {self.journal} {self.year}, {self.volume}({self.issue}), '
            f"{self.start}-{self.end}, doi:{self.doi}"
        )


#: The article grainlab reproduces (the geometrical stability index, its biaxial tests).
ARTICLE = Article(
    title="An Introduction to the Geometrical Stability Index: A Fabric Quantity",
    journal="Geotechnics",
    year=2022,
    volume=2,
    issue=2,
    start=297,
    end=316,
    doi="10.3390/geotechnics2020013",
)


def how_to_cite() -> str:
    """One line: this version of grainlab and the article it reproduces.

    >>> how_to_cite().startswith("Cite grainlab ")
    True
    """
    return f"Cite grainlab {__version__} (CITATION.cff) and the article it reproduces: {ARTICLE}."
