"""Griffe extension of the API reference: grainlab's docstrings as the site shows them.

What the package's documentation says in ways griffe does not read by itself:

- Doctest blocks outside an ``Examples`` section would read as Markdown: they are
  fenced as code.
- Sphinx roles (``:class:`Snapshot```, ``:func:`~grainlab.analysis.stability_index```)
  become cross-references: a link where the name is documented on the site, the name in
  code type where it is not (a private helper, a NumPy function). The name is resolved in
  the scope of the object whose docstring holds it, as Python would resolve it there.
- A measure's results are declared once, ``name = Computed[type]("doc")``
  (``grainlab.analysis._compute``): the string becomes the attribute's docstring.
- Constants are documented by ``#:`` comments above them (as Sphinx reads them), and a
  few are assigned together (``FIX_X, FIX_Y, FIX_ROTATION = 1, 2, 4``): each name of
  such an assignment becomes an attribute, and the comment its docstring.

Loaded by mkdocstrings (``extensions:`` in mkdocs.yml); ``roles_to_markdown`` also serves
the examples' pages (docs/hooks/grainlab_site.py).
"""

from __future__ import annotations

import ast
import re
from collections.abc import Callable, Iterator
from typing import Any

import griffe

ROLE = re.compile(r":(?:py:)?(?:class|func|mod|meth|attr|data|obj|exc|const):`(~?)([^`<>]+?)`")
MATH = re.compile(r":math:`([^`]+)`")


def roles_to_markdown(text: str, resolve: Callable[[str], str] = str) -> str:
    """``text`` with each Sphinx role turned into an optional cross-reference.

    ``resolve`` gives a name's full path (the name itself when it cannot). A ``~``
    before the name shows only its last part, as in Sphinx.

    >>> roles_to_markdown("see :func:`~grainlab.cli.main`")
    'see <autoref identifier="grainlab.cli.main" optional><code>main</code></autoref>'
    """

    def link(match: re.Match[str]) -> str:
        short, name = match.group(1) == "~", match.group(2).strip()
        shown = name.rsplit(".", 1)[-1] if short else name
        shown = shown + "()" if match.group(0).startswith((":func:", ":meth:")) and not shown.endswith(")") else shown
        return f'<autoref identifier="{resolve(name.removesuffix("()"))}" optional><code>{shown}</code></autoref>'

    return MATH.sub(r"`\1`", ROLE.sub(link, text))


def fence_doctests(text: str) -> str:
    """``text`` with each doctest block (``>>>`` lines and their output, up to a blank
    line) in a fenced ``pycon`` block, so that Markdown shows it as code, in whatever
    section it stands.

    >>> fence_doctests("Example:\\n\\n>>> 1 + 1\\n2\\n\\nDone.")
    'Example:\\n\\n```pycon\\n>>> 1 + 1\\n2\\n```\\n\\nDone.'
    """
    out: list[str] = []
    indent: str | None = None
    for line in text.split("\n"):
        if indent is None and line.lstrip().startswith(">>>"):
            indent = line[: len(line) - len(line.lstrip())]
            out.append(f"{indent}```pycon")
        elif indent is not None and not line.strip():
            out.append(f"{indent}```")
            indent = None
        out.append(line)
    if indent is not None:
        out.append(f"{indent}```")
    return "\n".join(out)


def _resolver(obj: griffe.Object) -> Callable[[str], str]:
    """A name's full path as seen from ``obj``'s scope: its members, its module's names,
    its parents'; a dotted name by its first part; else the name as written."""

    def resolve(name: str) -> str:
        head, _, rest = name.partition(".")
        for scope in (obj, *_parents(obj)):
            try:
                path = scope.resolve(head)
            except (griffe.NameResolutionError, AttributeError):
                continue
            return f"{path}.{rest}" if rest else path
        return name

    return resolve


def _parents(obj: griffe.Object) -> Iterator[griffe.Object]:
    parent = obj.parent
    while parent is not None:
        yield parent
        parent = parent.parent


def _objects(obj: griffe.Object) -> Iterator[griffe.Object]:
    """``obj`` and every object defined in it (aliases are documented where they live)."""
    yield obj
    for member in obj.members.values():
        if not member.is_alias:
            yield from _objects(member)  # type: ignore[arg-type]


def _computed_doc(attribute: griffe.Attribute) -> str | None:
    """The doc string of ``name = Computed[type]("doc")``, else None."""
    value = attribute.value
    if not isinstance(value, griffe.ExprCall) or not value.arguments:
        return None
    function = value.function
    base = function.left if isinstance(function, griffe.ExprSubscript) else function
    if str(base) != "Computed" or not isinstance(value.arguments[0], str):
        return None
    text = value.arguments[0]
    return text[1:-1] if text[:1] in "'\"" else None


def _comment_doc(attribute: griffe.Attribute) -> str | None:
    """The ``#:`` comment lines just above an attribute's assignment, else None."""
    if attribute.lineno is None or attribute.filepath is None or isinstance(attribute.filepath, list):
        return None
    collection = attribute.lines_collection
    lines = collection[attribute.filepath] if attribute.filepath in collection else []
    found: list[str] = []
    index = attribute.lineno - 2
    while 0 <= index < len(lines) and lines[index].strip().startswith("#:"):
        found.insert(0, lines[index].strip()[2:].strip())
        index -= 1
    return "\n".join(found) or None


class GrainlabDocstrings(griffe.Extension):
    """Roles to cross-references, ``Computed`` results, ``#:`` comments and tuple
    assignments documented (module docstring)."""

    def on_module_members(self, *, node: ast.AST | griffe.ObjectNode, mod: griffe.Module, **kwargs: Any) -> None:
        if not isinstance(node, ast.Module):
            return
        for statement in node.body:
            if not (isinstance(statement, ast.Assign) and len(statement.targets) == 1):
                continue
            names, values = statement.targets[0], statement.value
            if not (isinstance(names, ast.Tuple) and isinstance(values, ast.Tuple)):
                continue
            for name, value in zip(names.elts, values.elts, strict=False):
                if isinstance(name, ast.Name) and name.id not in mod.members:
                    mod.set_member(name.id, griffe.Attribute(
                        name.id, value=ast.unparse(value), lineno=statement.lineno, endlineno=statement.end_lineno,
                    ))

    def on_package(self, *, pkg: griffe.Module, **kwargs: Any) -> None:
        for obj in _objects(pkg):
            if isinstance(obj, griffe.Attribute) and obj.docstring is None:
                doc = _computed_doc(obj) or _comment_doc(obj)
                if doc is not None:
                    obj.docstring = griffe.Docstring(doc, parent=obj)
            if obj.docstring is not None:
                obj.docstring.value = fence_doctests(roles_to_markdown(obj.docstring.value, _resolver(obj)))
