"""What the page's tests share: one Chromium (Debian's, under Playwright) a module."""

from __future__ import annotations

import os
from collections.abc import Iterator
from pathlib import Path

import pytest
from playwright.sync_api import Browser, sync_playwright

CHROMIUM = os.environ.get("APPMODE_CHROMIUM", "/usr/bin/chromium")
"""Debian's Chromium, or the browser APPMODE_CHROMIUM names (Chrome on macOS, say). The
page's tests need one: without it they fail saying so (a skip would pass them unrun)."""


@pytest.fixture(scope="module")
def browser() -> Iterator[Browser]:
    assert Path(CHROMIUM).exists(), (
        f"no browser at {CHROMIUM}: apt-get install chromium (.ci/run does), or set "
        "APPMODE_CHROMIUM to a Chromium or Chrome"
    )
    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=CHROMIUM)
        try:
            yield browser
        finally:
            browser.close()
