"""A real browser for the tests that open pages: Debian's chromium driven by Playwright
(which downloads no browser of its own), and a folder served on the loopback address.

The skip rule of every browser test: skipped when chromium or Playwright is missing,
failed instead when GRAINLAB_REQUIRE_BROWSER=1 (as .ci/run sets it)."""

from __future__ import annotations

import contextlib
import functools
import http.server
import os
import shutil
import threading
from collections.abc import Iterator
from pathlib import Path

import pytest


def chromium_or_skip() -> str:
    """Debian's chromium, or skip (fail when GRAINLAB_REQUIRE_BROWSER=1, as in CI)."""
    required = os.environ.get("GRAINLAB_REQUIRE_BROWSER") == "1"
    try:
        import playwright.sync_api  # noqa: F401
    except ImportError:
        if required:
            pytest.fail("GRAINLAB_REQUIRE_BROWSER=1 but Playwright is not installed (pip install '.[test]')")
        pytest.skip("Playwright is not installed")
    path = shutil.which("chromium")
    if path is None:
        if required:
            pytest.fail("GRAINLAB_REQUIRE_BROWSER=1 but no chromium on PATH (apt-get install chromium)")
        pytest.skip("no chromium on PATH (Debian: apt-get install chromium)")
    return path


class _QuietHandler(http.server.SimpleHTTPRequestHandler):
    def log_message(self, format: str, *args: object) -> None:  # noqa: A002 (the base class's name)
        pass


@contextlib.contextmanager
def served(folder: Path) -> Iterator[str]:
    """``folder`` served over HTTP on 127.0.0.1 (a free port) while the block runs; yields
    its base URL. A site whose search fetches its index needs HTTP, not file://."""
    handler = functools.partial(_QuietHandler, directory=str(folder))
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}/"
    finally:
        server.shutdown()
        server.server_close()
        thread.join(timeout=10)
