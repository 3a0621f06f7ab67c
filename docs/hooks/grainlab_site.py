"""MkDocs hooks of the documentation site (mkdocs.yml, ``hooks:``).

docs/*.md are written for GitHub: they link to each other, and to files outside docs/
(``../ARCHITECTURE.md``, ``../examples/08_custom_protocol.py``, a package folder under
``../python/``). The site holds more than docs/, made when it is built:

- the API reference, one page per public module (``api_pages``),
- the command-line reference, made from the parsers (``cli_page``),
- the examples, each script's docstring and code (``example_pages``),
- the repository's README, ARCHITECTURE, CHANGELOG and CITATION.cff.

Every page knows the repository file it comes from, so a relative link is resolved
as GitHub resolves it, against that file, and then pointed at the site's page for the
target: a link to ``examples/X.py`` opens the example's page, a link into
``python/grainlab/`` the module's API page. A link whose target the site does not
hold is left as it is written, and the strict build fails on it: no broken link is
hidden.
"""

from __future__ import annotations

import posixpath
import re
from pathlib import Path
from typing import Any

from api_pages import api_nav, api_pages, page_uri
from cli_page import CLI_URI, cli_markdown
from example_pages import example_pages, examples_index
from mkdocs.structure.files import File, Files

ROOT = Path(__file__).resolve().parents[2]

#: The repository's own files in the site: repository path -> (site path, title).
ROOT_FILES = {
    "README.md": ("project/README.md", "README"),
    "ARCHITECTURE.md": ("project/ARCHITECTURE.md", "Architecture"),
    "CHANGELOG.md": ("project/CHANGELOG.md", "Changelog"),
}
CITATION_URI = "project/citation.md"

# a link's target in a markdown link or image; inline code is matched first and kept
LINK = re.compile(r"(`+)[^`]*?\1|(\]\()([^)\s]+)(\))")
FENCE = re.compile(r"^(```|~~~).*?^\1", re.S | re.M)


class Generated:
    """The generated pages of one build: site path -> (markdown, repository path)."""

    def __init__(self) -> None:
        self.pages: dict[str, tuple[str, str | None]] = {}
        self.nav: list[Any] = []

    def add(self, uri: str, markdown: str, source: str | None) -> None:
        self.pages[uri] = (markdown, source)


GENERATED = Generated()


def _citation_page() -> str:
    text = (ROOT / "CITATION.cff").read_text(encoding="utf-8")
    return (
        "# Citing grainlab\n\nThe repository's `CITATION.cff` (GitHub shows it as \"Cite this "
        "repository\"; `cffconvert` turns it into BibTeX or APA):\n\n"
        f"```yaml\n{text.strip()}\n```\n"
    )


def _make_pages() -> Generated:
    from grainlab.cli import build_parser

    made = Generated()
    api = api_pages(ROOT / "python")
    for page in api:
        made.add(page.src_uri, page.markdown, f"python/{page.module.replace('.', '/')}")
    made.add(CLI_URI, cli_markdown(build_parser()), None)
    examples = example_pages(ROOT / "examples")
    made.add("examples/README.md", examples_index(examples), None)
    for path, uri, _, markdown in examples:
        made.add(uri, markdown, path)
    for path, (uri, _) in ROOT_FILES.items():
        made.add(uri, (ROOT / path).read_text(encoding="utf-8"), path)
    made.add(CITATION_URI, _citation_page(), "CITATION.cff")
    made.nav = [
        {"Examples": ["examples/README.md", *({title: uri} for _, uri, title, _ in examples)]},
        {"Reference": [{"Command line": CLI_URI}, {"API": api_nav(api)}]},
        {"Project": [*({title: uri} for uri, title in ROOT_FILES.values()), {"Citing grainlab": CITATION_URI}]},
    ]
    return made


def github_slug(heading: str, separator: str = "-") -> str:
    """GitHub's anchor for a heading (lower case, punctuation dropped, each space a
    hyphen), so that a link written for GitHub finds its heading in the site too.

    >>> github_slug("`/snapshots/<name>` — full snapshots")
    'snapshotsname--full-snapshots'
    """
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", separator)


def on_config(config: Any) -> Any:
    global GENERATED
    GENERATED = _make_pages()
    config["nav"] = [*config["nav"], *GENERATED.nav]
    config["mdx_configs"].setdefault("toc", {})["slugify"] = github_slug
    return config


def on_files(files: Files, config: Any) -> Files:
    for uri, (markdown, _) in GENERATED.pages.items():
        files.append(File.generated(config, uri, content=markdown))
    return files


# ----------------------------------------------------------------------------- links
def site_path(repo_path: str) -> str | None:
    """The site page or file that stands for a repository path, None when it has none."""
    path = repo_path.rstrip("/")
    if path.startswith("docs/"):
        return path.removeprefix("docs/")
    if path in ROOT_FILES:
        return ROOT_FILES[path][0]
    if path == "CITATION.cff":
        return CITATION_URI
    if path.startswith("examples/") and path.count("/") == 1:
        uri = f"examples/{Path(path).stem}.md"
        return uri if uri in GENERATED.pages else None
    if path.startswith("python/grainlab"):
        module = path.removeprefix("python/").removesuffix(".py").removesuffix("/__init__").replace("/", ".")
        return page_uri(module) if page_uri(module) in GENERATED.pages else None
    return None


def _source_of(src_uri: str) -> str:
    """The repository file a site page comes from."""
    if src_uri in GENERATED.pages:
        return GENERATED.pages[src_uri][1] or f"docs/{src_uri}"
    return f"docs/{src_uri}"


def rewrite_link(target: str, source: str, src_uri: str) -> str:
    """``target`` as written in the repository file ``source``, pointed at the site's
    page for it from the site page ``src_uri``; unchanged when it needs no change or
    the site has no page for it."""
    if re.match(r"^[a-z][a-z0-9+.-]*:", target) or target.startswith(("#", "/")):
        return target
    path, hash_, anchor = target.partition("#")
    repo_path = posixpath.normpath(posixpath.join(posixpath.dirname(source), path))
    if repo_path.startswith("../") or (source.startswith("docs/") and repo_path.startswith("docs/")):
        return target  # outside the repository, or docs/ to docs/: MkDocs resolves it as written
    site = site_path(repo_path)
    if site is None:
        return target
    return posixpath.relpath(site, posixpath.dirname(src_uri) or ".") + hash_ + anchor


def _rewrite(text: str, source: str, src_uri: str) -> str:
    def one(match: re.Match[str]) -> str:
        if match.group(1):
            return match.group(0)
        return f"]({rewrite_link(match.group(3), source, src_uri)})"

    return LINK.sub(one, text)


def on_page_markdown(markdown: str, page: Any, config: Any, files: Files) -> str:
    src_uri = page.file.src_uri
    source = _source_of(src_uri)
    pieces, last = [], 0
    for fence in FENCE.finditer(markdown):
        pieces += [_rewrite(markdown[last : fence.start()], source, src_uri), fence.group(0)]
        last = fence.end()
    pieces.append(_rewrite(markdown[last:], source, src_uri))
    return "".join(pieces)
