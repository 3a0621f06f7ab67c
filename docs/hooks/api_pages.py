"""The API reference's pages: one page per public module of ``grainlab``.

A module's page renders (mkdocstrings) what the module defines and exports; a name it
only re-exports is listed in a table that links to the page of the module defining it,
so that every object is documented once. A name re-exported from a private module
(``grainlab._core``, the compiled engine, whose types come from ``_core.pyi``) is
rendered where it is exported. Which modules exist is read from the source tree
(griffe, no import): a new module gets its page with no change here.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import griffe
from griffe_grainlab import GrainlabDocstrings, roles_to_markdown

#: Where the API pages go in the site.
API_DIR = "reference/api"


@dataclass(frozen=True)
class ApiPage:
    """One module's page: its site path and its text."""

    module: str
    src_uri: str
    markdown: str


def is_public(path: str) -> bool:
    """Whether a module's dotted path has no private part (``_core``, ``__main__``)."""
    return not any(part.startswith("_") for part in path.split("."))


def page_uri(module: str) -> str:
    return f"{API_DIR}/{module}.md"


def load_package(source: Path) -> griffe.Module:
    """The ``grainlab`` package read from ``source`` (the folder holding it)."""
    extensions = griffe.load_extensions(GrainlabDocstrings())
    package = griffe.load(
        "grainlab", search_paths=[str(source)], extensions=extensions, resolve_aliases=True, resolve_external=False
    )
    assert isinstance(package, griffe.Module)
    return package


def public_modules(package: griffe.Module) -> list[griffe.Module]:
    """The package and every public module under it, parents before children."""
    found = [package]
    for member in package.modules.values():
        if isinstance(member, griffe.Module) and is_public(member.path):
            found += public_modules(member)
    return found


def _exported_names(module: griffe.Module) -> list[str]:
    if module.exports is not None:
        return [str(name) for name in module.exports]
    return [name for name, member in module.members.items() if not name.startswith("_") and not member.is_alias]


def _summary(obj: griffe.Object | griffe.Alias) -> str:
    """The first sentence of an object's docstring, for a table cell."""
    text = obj.docstring.value if obj.docstring is not None else ""
    first = text.strip().split("\n\n", 1)[0].replace("\n", " ")
    return roles_to_markdown(first).replace("|", "\\|")


def _documented_at_home(target: griffe.Object, public: set[str]) -> bool:
    """Whether the page of the module defining ``target`` renders it (the module is public
    and exports it)."""
    home = target.module
    return home.path in public and target.name in _exported_names(home)


def _split(module: griffe.Module, public: set[str]) -> tuple[list[str], list[tuple[str, str, str]]]:
    """(names rendered on the module's page, (name, home path, summary) of the names
    documented on another public module's page)."""
    own: list[str] = []
    elsewhere: list[tuple[str, str, str]] = []
    for name in _exported_names(module):
        member = module.members.get(name)
        if member is None or member.is_module:
            continue
        if isinstance(member, griffe.Alias):
            target = member.final_target
            if _documented_at_home(target, public) and target.module.path != module.path:
                elsewhere.append((name, target.path, _summary(target)))
                continue
        own.append(name)
    return own, elsewhere


def _page_markdown(module: griffe.Module, public: set[str]) -> str:
    own, elsewhere = _split(module, public)
    members = "\n".join(f"        - {name}" for name in own) if own else "false"
    lines = [f"::: {module.path}", "    options:", "      members:" + ("\n" + members if own else " false")]
    if elsewhere:
        lines += ["", f"## Also exported by `{module.path}`", "", "| name | what it is |", "| --- | --- |"]
        lines += [f"| [`{name}`][{home}] | {summary} |" for name, home, summary in elsewhere]
    submodules = [m.path for m in module.modules.values() if not m.is_alias and m.path in public]
    if submodules:
        lines += ["", "## Modules", ""] + [f"- [`{path}`][{path}]" for path in submodules]
    return "\n".join(lines) + "\n"


def api_pages(source: Path) -> list[ApiPage]:
    """Every public module's page, parents before children."""
    modules = public_modules(load_package(source))
    public = {m.path for m in modules}
    return [ApiPage(m.path, page_uri(m.path), _page_markdown(m, public)) for m in modules]


def api_nav(pages: list[ApiPage]) -> list[object]:
    """The API reference's navigation: a section per package, its own page first, then
    its modules and its subpackages, each by name."""
    by_parent: dict[str, list[ApiPage]] = {}
    for page in pages:
        by_parent.setdefault(page.module.rpartition(".")[0], []).append(page)

    def entry(page: ApiPage) -> object:
        children = sorted(by_parent.get(page.module, []), key=lambda c: (c.module in by_parent, c.module))
        # the full name: the page's title in the search results too
        if not children:
            return {page.module: page.src_uri}
        return {page.module: [{page.module: page.src_uri}, *(entry(child) for child in children)]}

    return [entry(page) for page in by_parent[""]]
