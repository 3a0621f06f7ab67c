"""Checks shared by the report tests: self-containedness of the HTML and a real browser."""

from __future__ import annotations

import base64
import io
import xml.etree.ElementTree as ET
from html.parser import HTMLParser
from pathlib import Path

from external_tools import chromium_or_skip

__all__ = ["chromium_or_skip", "check_self_contained", "open_in_browser", "parse"]

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


class _Collector(HTMLParser):
    """Every tag with its attributes, and the text of <style> and <script> elements."""

    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.tags: list[tuple[str, dict[str, str]]] = []
        self.style = ""
        self._in_style = False

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        self.tags.append((tag, {k: v or "" for k, v in attrs}))
        self._in_style = tag == "style"

    def handle_endtag(self, tag: str) -> None:
        if tag == "style":
            self._in_style = False

    def handle_data(self, data: str) -> None:
        if self._in_style:
            self.style += data


def parse(html_text: str) -> _Collector:
    collector = _Collector()
    collector.feed(html_text)
    collector.close()
    return collector


def check_self_contained(path: Path) -> list[str]:
    """Asserts the page needs nothing outside itself; returns the image kinds, in order."""
    from PIL import Image

    text = path.read_text(encoding="utf-8")
    page = parse(text)
    tags = [t for t, _ in page.tags]
    ids = [attrs["id"] for _, attrs in page.tags if "id" in attrs]
    assert len(ids) == len(set(ids)), f"duplicate ids: {sorted({i for i in ids if ids.count(i) > 1})}"
    anchors = {attrs["href"][1:] for t, attrs in page.tags if attrs.get("href", "").startswith("#")}
    assert anchors <= set(ids), f"links to missing anchors: {sorted(anchors - set(ids))}"
    assert "script" not in tags, "the report must not need scripts"
    for tag, attrs in page.tags:
        for name in ("src", "href", "srcset", "poster", "data"):
            value = attrs.get(name)
            if value is None:
                continue
            assert value.startswith(("data:", "#")), f"<{tag} {name}={value[:60]!r}> points outside the page"
        if tag == "link":
            assert attrs.get("href", "").startswith("data:"), f"<link> to {attrs.get('href')!r}"
    assert "http://" not in page.style and "https://" not in page.style and "@import" not in page.style
    assert "url(" not in page.style, "the style sheet must not load anything"
    kinds = []
    for tag, attrs in page.tags:
        if tag != "img":
            continue
        src = attrs["src"]
        header, _, payload = src.partition(",")
        if header == "data:image/png;base64":
            data = base64.b64decode(payload, validate=True)
            assert data[:8] == PNG_SIGNATURE
            with Image.open(io.BytesIO(data)) as im:
                im.verify()
            with Image.open(io.BytesIO(data)) as im:
                assert im.size[0] > 10 and im.size[1] > 10
                shown = int(attrs["width"]), int(attrs["height"])
                assert shown[0] > 0 and abs(shown[0] / shown[1] - im.size[0] / im.size[1]) < 0.01
            kinds.append("png")
        elif header.startswith("data:image/svg+xml"):
            data = base64.b64decode(payload) if header.endswith(";base64") else payload.encode()
            ET.fromstring(data)
            kinds.append("svg")
        else:
            raise AssertionError(f"<img> source is not an embedded PNG or SVG: {header[:40]!r}")
        assert attrs.get("alt"), "every figure has alt text"
    start = text.find("<svg")
    while start >= 0:
        end = text.index("</svg>", start) + len("</svg>")
        ET.fromstring(text[start:end])  # inline SVG parses
        start = text.find("<svg", end)
    return kinds


def open_in_browser(chromium: str, report: Path) -> dict:
    """Loads ``report`` from file:// in headless chromium; returns what the page did."""
    from playwright.sync_api import sync_playwright

    problems: list[str] = []
    requests: list[str] = []
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=chromium, args=["--no-sandbox"])
        try:
            page = browser.new_page(viewport={"width": 1280, "height": 900})
            page.on("console", lambda m: problems.append(f"console {m.type}: {m.text}")
                    if m.type in ("error", "warning") else None)
            page.on("pageerror", lambda e: problems.append(f"page error: {e}"))
            page.on("requestfailed", lambda r: problems.append(f"request failed: {r.url}"))
            page.on("request", lambda r: requests.append(r.url))
            page.goto(report.resolve().as_uri(), wait_until="load")
            images = page.eval_on_selector_all(
                "img", "els => els.map(e => ({w: e.naturalWidth, h: e.naturalHeight, ok: e.complete}))"
            )
            figures = page.locator("figure.figure").count()
            title = page.title()
            sections = page.eval_on_selector_all("section", "els => els.map(e => e.id)")
            height = page.evaluate("document.body.scrollHeight")
        finally:
            browser.close()
    return {
        "problems": problems,
        "requests": requests,
        "images": images,
        "figures": figures,
        "title": title,
        "sections": sections,
        "height": height,
    }
