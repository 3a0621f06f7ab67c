"""The programs some tests need beyond Python's packages, and the one skip rule for them:
a test skips when its program is missing, and fails instead when the environment variable
that requires the program is 1 (as .ci/run sets them). Debian's chromium (driven by
Playwright, which downloads no browser of its own) for the tests that open pages, with a
folder served on the loopback address; qemu-user for the wheel's test without AVX2."""

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


def tool_or_skip(command: str, required_by: str, install: str) -> str:
    """The path of ``command``; else skip the test, or fail it when the environment
    variable ``required_by`` is 1 (CI)."""
    path = shutil.which(command)
    if path is None:
        if os.environ.get(required_by) == "1":
            pytest.fail(f"{required_by}=1 but no {command} on PATH ({install})")
        pytest.skip(f"no {command} on PATH (Debian: {install})")
    return path


def chromium_or_skip() -> str:
    """Debian's chromium, or skip (fail when GRAINLAB_REQUIRE_BROWSER=1, as in CI)."""
    try:
        import playwright.sync_api  # noqa: F401
    except ImportError:
        if os.environ.get("GRAINLAB_REQUIRE_BROWSER") == "1":
            pytest.fail("GRAINLAB_REQUIRE_BROWSER=1 but Playwright is not installed (pip install '.[test]')")
        pytest.skip("Playwright is not installed")
    return tool_or_skip("chromium", "GRAINLAB_REQUIRE_BROWSER", "apt-get install chromium")


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
