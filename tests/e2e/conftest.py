"""A real headless Chromium (Debian's ``chromium``) driven by Playwright, against a live server.

The tests are skipped only when no Chromium or no Playwright is found; CI (``.ci/run``) installs both.
Every page a test opens collects its console errors and uncaught exceptions, and the test fails on any.
"""

from __future__ import annotations

import os
import re
import shutil
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from benchmarks.screenshots import CHROMIUM_ARGS
from tests.support.server import LiveServer

ROOT = Path(__file__).resolve().parents[2]
STARTUP_S = 60.0
HTTP_ERROR = re.compile(r"^Failed to load resource: the server responded with a status of 4\d\d")


def chromium_path() -> str | None:
    for candidate in (
        os.environ.get("INERTIA_CHROMIUM"),
        "/usr/bin/chromium",
        shutil.which("chromium"),
        shutil.which("chromium-browser"),
    ):
        if candidate and Path(candidate).exists():
            return candidate
    return None


class Server(LiveServer):
    """``python -m inertia serve`` on a free loopback port, one compute process unless told otherwise."""

    def __init__(self, **settings: str) -> None:
        super().__init__({"INERTIA_COMPUTE_PROCESSES": "1", **settings}, startup_s=STARTUP_S, log_name="e2e-serve")


@pytest.fixture(scope="session")
def server() -> Iterator[Server]:
    s = Server()
    yield s
    s.stop()


@pytest.fixture(scope="session")
def browser() -> Iterator[Any]:
    sync_api = pytest.importorskip("playwright.sync_api")
    path = chromium_path()
    if path is None:
        pytest.skip("no Chromium found (Debian: apt-get install chromium)")
    with sync_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path=path, args=CHROMIUM_ARGS)
        yield b
        b.close()


class Console:
    """Console errors, uncaught exceptions and any request that left the loopback host."""

    def __init__(self, page: Any, server: Server) -> None:
        self.errors: list[str] = []
        self.external: list[str] = []
        # Chromium logs every 4xx answer as a console error; a test that provokes one sets this
        self.expect_http_errors = False
        self.http_errors: list[str] = []
        page.on("console", self._message)
        page.on("pageerror", lambda e: self.errors.append(f"uncaught: {e}"))

        def route(r: Any) -> None:
            if r.request.url.startswith(server.url) or r.request.url.startswith(("blob:", "data:")):
                r.continue_()
            else:  # offline: nothing may be fetched from elsewhere (a CDN)
                self.external.append(r.request.url)
                r.abort()

        page.route("**/*", route)

    def _message(self, message: Any) -> None:
        if message.type != "error":
            return
        if HTTP_ERROR.search(message.text):
            self.http_errors.append(message.text)
        else:
            self.errors.append(f"console.{message.type}: {message.text}")


@pytest.fixture
def console_page(browser: Any, server: Server, request: pytest.FixtureRequest) -> Iterator[tuple[Any, Console]]:
    """A fresh page (desktop size, or ``@pytest.mark.parametrize``'d ``viewport``) that fails the test on
    console errors or external requests."""
    viewport = getattr(request, "param", {"width": 1280, "height": 900})
    context = browser.new_context(viewport=viewport, accept_downloads=True)
    page = context.new_page()
    page.set_default_timeout(60_000)
    console = Console(page, server)
    yield page, console
    context.close()
    assert console.errors == [], console.errors
    assert console.expect_http_errors or console.http_errors == [], console.http_errors
    assert console.external == [], console.external
