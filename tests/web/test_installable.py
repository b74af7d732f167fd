"""The page as an installable web app (issue 51, part 7), in a real Chromium: no error in
the console, pinch zoom allowed, a description, a theme colour, an icon, a manifest, the
system's dark mode followed, and a service worker that keeps only the page's own files
and says "the server is not reachable" when it is not."""

from __future__ import annotations

import json
from pathlib import Path

from playwright.sync_api import Browser

from tests.support.web import web_process


def test_the_page_is_tidy_installable_and_says_when_the_server_is_gone(
    browser: Browser,
    tmp_path: Path,
) -> None:
    context = browser.new_context(color_scheme="dark")
    page = context.new_page()
    errors: list[str] = []
    page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda e: errors.append(str(e)))
    failed: list[str] = []
    page.on(  # what the reloads below cancel (the browser's own icon fetches) is no failure
        "requestfailed",
        lambda r: failed.append(f"{r.failure} {r.url}") if r.failure != "net::ERR_ABORTED" else 0,
    )
    page.on("response", lambda r: failed.append(f"{r.status} {r.url}") if r.status >= 400 else None)
    with web_process(tmp_path) as web:
        page.goto(web.address)
        page.get_by_text("parameters read").wait_for(timeout=10_000)
        head = page.evaluate(
            """() => ({
                viewport: document.querySelector('meta[name=viewport]').content,
                description: document.querySelector('meta[name=description]').content,
                theme: document.querySelector('meta[name=theme-color]').content,
                icon: document.querySelector('link[rel=icon]').href,
                manifest: document.querySelector('link[rel=manifest]').href,
                dark: matchMedia('(prefers-color-scheme: dark)').matches,
                pad: getComputedStyle(document.querySelector("#stick")).backgroundColor,
            })"""
        )
        assert "user-scalable" not in head["viewport"] and "maximum-scale" not in head["viewport"]
        assert len(head["description"]) > 50 and head["theme"].startswith("#")
        assert head["dark"] and head["pad"] == "rgb(38, 38, 38)", "dark mode follows the system"
        manifest = page.evaluate(f"fetch({json.dumps(head['manifest'])}).then(r => r.json())")
        assert manifest["start_url"] == "/" and manifest["display"] == "standalone"
        for icon in manifest["icons"]:
            status = page.evaluate(f"fetch({json.dumps(icon['src'])}).then(r => r.status)")
            assert status == 200, icon
        page.evaluate("navigator.serviceWorker.ready")
        page.reload()  # now under the worker
        page.get_by_text("parameters read").wait_for(timeout=10_000)
        kept = page.evaluate(  # the worker's one cache, whatever its version
            "caches.keys().then(n => caches.open(n[0])).then(c => c.keys())"
            ".then(k => k.map(r => r.url))"
        )
        assert kept and all("/static/" in url for url in kept), "only the page's own files"
        assert not any("token" in url or url.endswith("/") for url in kept)
        assert not errors and not failed, (errors, failed)
    page.reload()  # the server has gone
    assert "The server is not reachable" in page.locator("h1").inner_text()
    context.close()


def test_every_control_is_a_finger_s_target_on_every_tab(
    browser: Browser,
    tmp_path: Path,
) -> None:
    """Issue 51: the tabs, page and speed buttons, Run and each parameter's Set and input
    were 21–40 px high; every control a finger may touch is at least 48 × 48 CSS px."""
    context = browser.new_context(
        viewport={"width": 360, "height": 640}, has_touch=True, is_mobile=True
    )
    page = context.new_page()
    small: list[str] = []
    with web_process(tmp_path) as web:
        page.goto(web.address)
        page.get_by_text("parameters read").wait_for(timeout=10_000)
        for tab in ("drive", "tilt", "params", "waves"):
            page.locator(f'nav button[data-tab="{tab}"]').click()
            found = page.evaluate(
                """() => [...document.querySelectorAll('button, input')]
                    .filter(e => e.offsetParent !== null)
                    .map(e => [e, e.getBoundingClientRect()])
                    .filter(([, r]) => r.width < 48 || r.height < 48)
                    .map(([e, r]) => [e.id || e.getAttribute('aria-label') || e.textContent,
                                      Math.round(r.width), Math.round(r.height)])"""
            )
            small += [f"{tab}: {name.strip()} {w}x{h}" for name, w, h in found]
        assert page.locator("#values input").count() >= 9, "the parameters' inputs were there"
    context.close()
    assert not small, small
