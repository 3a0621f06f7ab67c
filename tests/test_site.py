"""The documentation site (mkdocs.yml, docs/hooks/): built strictly, with no warning, from
docs/, the docstrings, the command-line parsers and the examples; links written for
GitHub open the site's pages; the API pages of ``Simulation`` and ``StabilityIndex``
found from the site's search in a real browser.

The build takes about 15 s: the tests that need it are ``slow`` (CI runs them)."""

from __future__ import annotations

import html
import importlib.util
import os
import re
import subprocess
import sys
from pathlib import Path
from types import ModuleType

import pytest
import yaml
from external_tools import chromium_or_skip, served

from grainlab.cli import build_parser

ROOT = Path(__file__).resolve().parents[1]
HOOKS = ROOT / "docs" / "hooks"


def _hook(name: str) -> ModuleType:
    """A module of docs/hooks/, loaded as MkDocs loads a hook (its folder on the path)."""
    if name in sys.modules:
        return sys.modules[name]
    sys.path.insert(0, str(HOOKS))
    try:
        spec = importlib.util.spec_from_file_location(name, HOOKS / f"{name}.py")
        assert spec is not None and spec.loader is not None
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        spec.loader.exec_module(module)
    finally:
        sys.path.remove(str(HOOKS))
    return module


def _text(page: Path) -> str:
    """A built page's text, tags dropped."""
    return html.unescape(re.sub(r"<[^>]+>", "", page.read_text(encoding="utf-8")))


@pytest.fixture(scope="module")
def site(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, str]:
    """The site built as ``make docs`` builds it, into a temporary folder: (folder, output)."""
    folder = tmp_path_factory.mktemp("site")
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}
    done = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(folder)],
                          cwd=ROOT, env=env, capture_output=True, text=True, timeout=600)
    output = done.stdout + done.stderr
    assert done.returncode == 0, output
    return folder, output


# ----------------------------------------------------------------------------- the build
def test_the_build_is_strict_and_checks_every_link_and_anchor():
    config = yaml.safe_load((ROOT / "mkdocs.yml").read_text(encoding="utf-8"))
    assert config["strict"] is True
    for key in ("omitted_files", "absolute_links", "unrecognized_links", "anchors"):
        assert config["validation"][key] == "warn", key  # a warning fails the strict build
    makefile = (ROOT / "Makefile").read_text(encoding="utf-8")
    assert "mkdocs build --strict" in makefile


@pytest.mark.slow
def test_the_site_builds_with_no_warning(site):
    folder, output = site
    assert "WARNING" not in output and "Aborted" not in output, output
    assert (folder / "index.html").exists() and (folder / "search" / "search_index.json").exists()
    index = (folder / "search" / "search_index.json").read_text(encoding="utf-8")
    assert "grainlab.analysis.stability.StabilityIndex" in index and "grainlab.simulation.Simulation" in index


@pytest.mark.slow
def test_every_public_module_has_its_api_page(site):
    folder, _ = site
    pages = _hook("api_pages").api_pages(ROOT / "python")
    modules = {page.module for page in pages}
    assert {"grainlab", "grainlab.simulation", "grainlab.analysis", "grainlab.analysis.stability"} <= modules
    assert not any(part.startswith("_") for m in modules for part in m.split("."))
    missing = [m for m in modules if not (folder / "reference" / "api" / m / "index.html").exists()]
    assert not missing
    simulation = (folder / "reference/api/grainlab.simulation/index.html").read_text(encoding="utf-8")
    assert 'id="grainlab.simulation.Simulation"' in simulation
    assert 'id="grainlab.simulation.Simulation.run"' in simulation
    stability = (folder / "reference/api/grainlab.analysis.stability/index.html").read_text(encoding="utf-8")
    assert 'id="grainlab.analysis.stability.StabilityIndex"' in stability
    # a result declared once (Computed("doc")) is documented by its doc string
    assert 'id="grainlab.analysis.stability.StabilityIndex.mean"' in stability


@pytest.mark.slow
def test_a_name_is_documented_once_and_linked_from_where_it_is_exported(site):
    folder, _ = site
    top = (folder / "reference/api/grainlab/index.html").read_text(encoding="utf-8")
    assert 'href="../grainlab.simulation/#grainlab.simulation.Simulation"' in top
    assert 'id="grainlab.Simulation"' not in top
    # defined in the private compiled module: rendered where grainlab exports it
    assert 'id="grainlab.SimulationUnstableError"' in top


@pytest.mark.slow
def test_the_cli_page_has_every_command_and_option(site):
    folder, _ = site
    text = _text(folder / "reference" / "cli" / "index.html")
    subparsers = next(a for a in build_parser()._actions if a.__class__.__name__ == "_SubParsersAction")
    for command, parser in subparsers.choices.items():
        assert f"grainlab {command}" in text, command
        for action in parser._actions:
            if action.option_strings == ["-h", "--help"]:
                continue  # --help is on every command: the page leaves it out
            for option in action.option_strings:
                assert option in text, (command, option)


@pytest.mark.slow
def test_every_example_has_its_page_with_its_code(site):
    folder, _ = site
    scripts = sorted((ROOT / "examples").glob("[0-9][0-9]_*.py"))
    assert scripts
    for script in scripts:
        page = folder / "examples" / script.stem / "index.html"
        last_line = [line for line in script.read_text(encoding="utf-8").splitlines() if line.strip()][-1]
        assert last_line.strip() in _text(page), script.name


@pytest.mark.slow
def test_links_written_for_github_open_the_sites_pages(site):
    folder, _ = site
    protocols = (folder / "protocols" / "index.html").read_text(encoding="utf-8")
    assert 'href="../examples/08_custom_protocol/"' in protocols
    assert 'href="../reference/api/grainlab.protocols.oedometer/"' in protocols
    engine = (folder / "engine" / "index.html").read_text(encoding="utf-8")
    assert 'href="../project/ARCHITECTURE/' in engine
    readme = (folder / "project" / "index.html").read_text(encoding="utf-8")
    assert 'href="../biaxial/#the-strain-rate"' in readme
    assert 'src="../images/default_run_stability_index.png"' in readme


# ----------------------------------------------------------------------------- the hooks
def test_links_are_pointed_at_the_sites_pages_or_left_for_the_strict_build():
    hooks = _hook("grainlab_site")
    hooks.GENERATED = hooks._make_pages()
    rewrite = hooks.rewrite_link
    assert rewrite("../ARCHITECTURE.md", "docs/engine.md", "engine.md") == "project/ARCHITECTURE.md"
    assert rewrite("../examples/08_custom_protocol.py", "docs/protocols.md", "protocols.md") == (
        "examples/08_custom_protocol.md"
    )
    assert rewrite("docs/biaxial.md#the-strain-rate", "README.md", "project/README.md") == "../biaxial.md#the-strain-rate"
    assert rewrite("fabric.md#shear-band", "docs/analysis.md", "analysis.md") == "fabric.md#shear-band"
    assert rewrite("CITATION.cff", "README.md", "project/README.md") == "citation.md"
    # no page for it in the site: left as written, so that the strict build fails on it
    assert rewrite("../crates/grainlab-core/src/law/mod.rs", "docs/engine.md", "engine.md") == (
        "../crates/grainlab-core/src/law/mod.rs"
    )
    assert rewrite("../python/grainlab/_core.pyi", "docs/engine.md", "engine.md") == "../python/grainlab/_core.pyi"
    assert rewrite("https://doi.org/10.3390/x", "README.md", "project/README.md") == "https://doi.org/10.3390/x"


def test_the_sites_anchors_are_githubs():
    slug = _hook("grainlab_site").github_slug
    assert slug("The snapshot (`grainlab.snapshot.Snapshot`)") == "the-snapshot-grainlabsnapshotsnapshot"
    assert slug("Contact-normal distribution and anisotropy (Eq. 6–8)") == "contact-normal-distribution-and-anisotropy-eq-68"
    assert slug("`/snapshots/<name>` — full snapshots") == "snapshotsname--full-snapshots"
    assert slug("The stability index λ") == "the-stability-index-λ"


def test_docstrings_read_as_markdown():
    griffe_grainlab = _hook("griffe_grainlab")
    assert griffe_grainlab.roles_to_markdown(":class:`~grainlab.snapshot.Snapshot`") == (
        '<autoref identifier="grainlab.snapshot.Snapshot" optional><code>Snapshot</code></autoref>'
    )
    assert griffe_grainlab.roles_to_markdown(":math:`45° + \\varphi/2`") == "`45° + \\varphi/2`"
    fenced = griffe_grainlab.fence_doctests("Example\n-------\n>>> f(1)\n[1, 2]\n\nAfter.")
    assert fenced == "Example\n-------\n```pycon\n>>> f(1)\n[1, 2]\n```\n\nAfter."


# ----------------------------------------------------------------------------- in a browser
def _find_by_search(page, base: str, query: str, anchor: str) -> dict:
    """Types ``query`` in the site's search box, opens the result that links to ``anchor``
    and returns what that page shows there."""
    page.goto(base, wait_until="load")
    page.locator("label.md-search__icon, .md-search__input").first.click()
    page.locator("input.md-search__input").fill(query)
    # the results are grouped by page: the anchor's link may sit under "N more on this page"
    item = page.locator(".md-search-result__item", has=page.locator(f'a[href*="#{anchor}"]')).first
    item.wait_for(timeout=20_000)
    if item.locator("summary").count():
        item.locator("summary").first.click()
    item.locator(f'a[href*="#{anchor}"]').first.click()
    page.wait_for_url(re.compile(re.escape(anchor)), timeout=20_000)
    heading = page.locator(f'[id="{anchor}"]')
    heading.wait_for(timeout=20_000)
    return {"url": page.url, "heading": heading.inner_text(), "title": page.title(),
            "text": page.locator("article").inner_text()}


@pytest.mark.slow
def test_the_api_pages_of_simulation_and_stability_index_are_found_from_the_search(site):
    from playwright.sync_api import sync_playwright

    chromium = chromium_or_skip()
    folder, _ = site
    problems: list[str] = []
    requests: list[str] = []
    with served(folder) as base, sync_playwright() as p:
        browser = p.chromium.launch(executable_path=chromium, args=["--no-sandbox"])
        try:
            page = browser.new_page(viewport={"width": 1280, "height": 900})
            page.on("console", lambda m: problems.append(m.text) if m.type == "error" else None)
            page.on("pageerror", lambda e: problems.append(str(e)))
            page.on("request", lambda r: requests.append(r.url))
            simulation = _find_by_search(page, base, "Simulation", "grainlab.simulation.Simulation")
            stability = _find_by_search(page, base, "StabilityIndex", "grainlab.analysis.stability.StabilityIndex")
        finally:
            browser.close()
    assert problems == []
    assert requests and all(url.startswith(base) for url in requests), requests  # nothing from elsewhere
    assert "/reference/api/grainlab.simulation/" in simulation["url"]
    assert simulation["heading"].startswith("Simulation")
    assert "run" in simulation["text"] and "positions" in simulation["text"]
    assert "/reference/api/grainlab.analysis.stability/" in stability["url"]
    assert stability["heading"].startswith("StabilityIndex")
    assert "Geometrical stability index" in stability["text"]
