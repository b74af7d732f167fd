"""The web page in a real Chromium (Debian's, under Playwright), as a person uses it on
a phone (360×640, touch) and on a desktop: the pad drives while a finger holds it and
stops when it lifts, a second finger leaves no direction behind, keys drive, and a
closed or hidden page stops the car."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
from playwright.sync_api import Browser, CDPSession, Page, sync_playwright

from tests.support.web import WebProcess, wait_sent, web_process

CHROMIUM = "/usr/bin/chromium"


@pytest.fixture(scope="module")
def browser() -> Iterator[Browser]:
    assert Path(CHROMIUM).exists(), "install Chromium: apt-get install chromium (.ci/run does)"
    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=CHROMIUM)
        try:
            yield browser
        finally:
            browser.close()


def phone(browser: Browser, web: WebProcess) -> Page:
    context = browser.new_context(
        viewport={"width": 360, "height": 640}, has_touch=True, is_mobile=True
    )
    page = context.new_page()
    page.goto(web.address)
    page.get_by_text("parameters read").wait_for(timeout=10_000)
    return page


def centre(page: Page, name: str) -> tuple[float, float]:
    box = page.get_by_role("button", name=name, exact=True).bounding_box()
    assert box is not None
    return box["x"] + box["width"] / 2, box["y"] + box["height"] / 2


def touch(cdp: CDPSession, kind: str, fingers: dict[int, tuple[float, float]]) -> None:
    points = [{"x": x, "y": y, "id": finger} for finger, (x, y) in fingers.items()]
    cdp.send("Input.dispatchTouchEvent", {"type": kind, "touchPoints": points})


def test_holding_a_cell_drives_and_lifting_the_finger_stops(
    browser: Browser, tmp_path: Path
) -> None:
    with web_process(tmp_path) as web:
        page = phone(browser, web)
        for name in ("forward", "backward", "left", "right", "stop"):
            assert page.get_by_role("button", name=name, exact=True).is_visible()
        page.screenshot(path=str(tmp_path / "phone.png"))
        x, y = centre(page, "forward")
        page.mouse.move(x, y)
        page.mouse.down()
        wait_sent(web, "A")
        page.wait_for_timeout(800)  # held: the heartbeats keep it going
        assert web.sent()[-1] == "A"
        page.mouse.up()
        wait_sent(web, "Z")
        assert page.locator("#badge").inner_text() == "REAL BOARD"


def test_a_second_finger_leaves_no_direction_behind(browser: Browser, tmp_path: Path) -> None:
    with web_process(tmp_path) as web:
        page = phone(browser, web)
        cdp = page.context.new_cdp_session(page)
        forward, left = centre(page, "forward"), centre(page, "left")
        touch(cdp, "touchStart", {0: forward})
        wait_sent(web, "A")
        touch(cdp, "touchStart", {0: forward, 1: left})
        wait_sent(web, "G")
        touch(cdp, "touchEnd", {1: left})  # the first finger alone: forward again
        wait_sent(web, "A")
        touch(cdp, "touchEnd", {0: forward})
        wait_sent(web, "Z")
        page.wait_for_timeout(500)
        assert web.sent()[-1] == "Z"


def test_keys_drive_while_held_and_space_stops(browser: Browser, tmp_path: Path) -> None:
    with web_process(tmp_path) as web:
        page = browser.new_page()
        page.goto(web.address)
        page.get_by_text("parameters read").wait_for(timeout=10_000)
        page.keyboard.down("w")
        wait_sent(web, "A")
        page.keyboard.up("w")
        wait_sent(web, "Z")
        page.keyboard.down("ArrowRight")
        wait_sent(web, "C")
        page.keyboard.press(" ")
        wait_sent(web, "Z")
        page.keyboard.up("ArrowRight")
        page.close()


def test_closing_or_hiding_the_page_stops_the_car(browser: Browser, tmp_path: Path) -> None:
    with web_process(tmp_path) as web:
        page = phone(browser, web)
        x, y = centre(page, "backward")
        page.mouse.move(x, y)
        page.mouse.down()
        wait_sent(web, "E")
        page.evaluate(
            "Object.defineProperty(document, 'hidden', {value: true, configurable: true});"
            "document.dispatchEvent(new Event('visibilitychange'))"
        )
        wait_sent(web, "Z")
        page.close()
        page = phone(browser, web)
        x, y = centre(page, "right")
        page.mouse.move(x, y)
        page.mouse.down()
        wait_sent(web, "C")
        page.context.close()  # the tab goes away with the finger still down
        wait_sent(web, "Z")
