"""The examples' pages: each numbered script of examples/ as its docstring, then its code.

The scripts are not run here: the test suite runs every one of them
(tests/test_docs.py checks that a test names each). The notebook gets a page of its
cells, its outputs left out.
"""

from __future__ import annotations

import ast
import json
from pathlib import Path

from griffe_grainlab import roles_to_markdown

#: Where the examples' pages go in the site.
EXAMPLES_DIR = "examples"


def example_uri(script: Path) -> str:
    return f"{EXAMPLES_DIR}/{script.stem}.md"


def _title_and_text(docstring: str) -> tuple[str, str]:
    head, _, rest = docstring.strip().partition("\n")
    return head.strip().rstrip("."), roles_to_markdown(rest.strip())


def script_markdown(script: Path) -> tuple[str, str]:
    """(title, page) of one script: the docstring's first line as the title, the rest of
    it as the text, then the code that follows the docstring."""
    source = script.read_text(encoding="utf-8")
    tree = ast.parse(source)
    docstring = ast.get_docstring(tree) or script.name
    body = source.splitlines()[tree.body[0].end_lineno or 0 :] if ast.get_docstring(tree) else source.splitlines()
    title, text = _title_and_text(docstring)
    code = "\n".join(body).strip("\n")
    page = f"# {title}\n\n`examples/{script.name}`\n\n{text}\n\n```python\n{code}\n```\n"
    return title, page


def notebook_markdown(notebook: Path) -> tuple[str, str]:
    """(title, page) of a notebook: its markdown cells as they are, its code cells as code."""
    cells = json.loads(notebook.read_text(encoding="utf-8"))["cells"]
    parts = [f"`examples/{notebook.name}` (its outputs are made when it runs)"]
    title = notebook.stem
    for cell in cells:
        text = "".join(cell["source"]).strip("\n")
        if cell["cell_type"] == "markdown":
            if text.startswith("# ") and title == notebook.stem:
                title = text.splitlines()[0][2:].strip()
                text = "\n".join(text.splitlines()[1:]).strip("\n")
            parts.append(text)
        elif cell["cell_type"] == "code":
            parts.append(f"```python\n{text}\n```")
    return title, f"# {title}\n\n" + "\n\n".join(parts) + "\n"


def example_pages(folder: Path) -> list[tuple[str, str, str, str]]:
    """(repository path, site path, short title, page) of every numbered example, in order."""
    pages = []
    for path in sorted(folder.glob("[0-9][0-9]_*")):
        if path.suffix == ".py":
            title, page = script_markdown(path)
        elif path.suffix == ".ipynb":
            title, page = notebook_markdown(path)
        else:
            continue
        pages.append((f"examples/{path.name}", example_uri(path), title.split(":")[0], page))
    return pages


def examples_index(pages: list[tuple[str, str, str, str]]) -> str:
    """The examples' index page: one line per example."""
    lines = ["# Examples", "", "Runnable scripts in `examples/`, each run by the test suite:", ""]
    lines += [f"- [{title}]({Path(uri).name}) (`{path}`)" for path, uri, title, _ in pages]
    return "\n".join(lines) + "\n"
