"""The page as a phone shows it, measured in a real Chromium: the Drive view on one
screen (portrait, landscape, desktop; APP port and UART2), every touch target a finger's
size, the joystick, the instruments, the sliders and the waveforms' controls."""

from __future__ import annotations

import math
import time
from pathlib import Path

import pytest
from playwright.sync_api import Browser, Page

from tests.support.web import WebProcess, wait_sent, web_process

SCREENS = ((360, 640), (640, 360), (1280, 800))
FINGER = 48
"""CSS pixels a touch target needs each way."""


def open_page(browser: Browser, web: WebProcess, width: int, height: int, ready: str) -> Page:
    mobile = width < 1000
    context = browser.new_context(
        viewport={"width": width, "height": height}, has_touch=mobile, is_mobile=mobile
    )
    page = context.new_page()
    page.goto(web.address)
    page.get_by_text(ready).wait_for(timeout=10_000)
    page.wait_for_timeout(300)  # a few statuses: the instruments filled in
    return page


def until(page: Page, script: str, timeout: float = 5.0) -> None:
    """Wait until `script` (a function, evaluated as Playwright does under the page's
    CSP, which forbids a string's eval) returns true."""
    deadline = time.monotonic() + timeout
    while not page.evaluate(script):
        assert time.monotonic() < deadline, f"never true: {script}"
        page.wait_for_timeout(50)


def text_is(page: Page, selector: str, text: str) -> None:
    until(page, f"() => document.querySelector({selector!r}).textContent === {text!r}")


def on_screen(page: Page, selector: str, width: int, height: int) -> None:
    box = page.locator(selector).bounding_box()
    assert box is not None, f"{selector} is not shown"
    assert box["x"] >= 0 and box["y"] >= 0, (selector, box)
    assert box["x"] + box["width"] <= width + 0.5, (selector, box, width)
    assert box["y"] + box["height"] <= height + 0.5, (selector, box, height)


def small_targets(page: Page) -> list[str]:
    """The Drive view's visible buttons and inputs under FINGER px either way."""
    found: list[str] = page.evaluate(
        """(finger) => [...document.querySelectorAll(
            'header button, nav button, #drive button, #drive input, #command *')]
          .filter((e) => /^(BUTTON|INPUT)$/.test(e.tagName) && e.getClientRects().length)
          .map((e) => [e, e.getBoundingClientRect()])
          .filter(([, r]) => r.width < finger - 0.5 || r.height < finger - 0.5)
          .map(([e, r]) => `${e.id || e.getAttribute('aria-label') || e.textContent}`
            + ` ${r.width.toFixed(0)}x${r.height.toFixed(0)}`)""",
        FINGER,
    )
    return found


@pytest.mark.parametrize("uart2", [False, True], ids=["app", "uart2"])
def test_the_drive_view_fits_one_screen_with_finger_sized_targets(
    browser: Browser, tmp_path: Path, uart2: bool
) -> None:
    with web_process(tmp_path, uart2=uart2) as web:
        for width, height in SCREENS:
            page = open_page(
                browser, web, width, height, "settings read" if uart2 else "parameters read"
            )
            for selector in ("#stick", "#in-force", "#speed", "#slower", "#faster"):
                on_screen(page, selector, width, height)
            for selector in ("#battery-tile", "#link"):
                on_screen(page, selector, width, height)
            if not uart2:
                on_screen(page, "#pages", width, height)
                page.get_by_role("button", name="Spin").click()
                page.get_by_role("button", name="rotate-cw", exact=True).wait_for()
                for selector in ("#pad", "#extra", "#in-force", "#speed", "#battery-tile"):
                    on_screen(page, selector, width, height)
                assert small_targets(page) == [], (width, height)
                page.get_by_role("button", name="Move").click()
                page.locator("#stick").wait_for()
            assert page.locator("#link").inner_text().startswith("link up")
            assert small_targets(page) == [], (width, height)
            page.get_by_role("button", name="Pad").click()  # the pad, one tap away
            on_screen(page, "#pad", width, height)
            assert small_targets(page) == [], (width, height)
            if width > height:  # landscape: the control beside the status, on the right
                stick = page.locator("#pad").bounding_box()
                force = page.locator("#in-force").bounding_box()
                assert stick is not None and force is not None
                assert stick["x"] > force["x"] + force["width"], (stick, force)
            page.context.close()


def test_the_joystick_drives_by_sector_stops_in_its_dead_zone_and_on_release(
    browser: Browser, tmp_path: Path
) -> None:
    with web_process(tmp_path) as web:
        page = open_page(browser, web, 360, 640, "parameters read")
        box = page.locator("#stick").bounding_box()
        assert box is not None
        cx, cy, r = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2, box["width"] / 2
        page.mouse.move(cx, cy)
        page.mouse.down()  # in the dead zone: nothing moves
        page.wait_for_timeout(300)
        assert not set(web.sent()) & set("ABCDEFGH"), web.sent()
        page.mouse.move(cx, cy - r * 0.8, steps=4)  # up: forward
        wait_sent(web, "A")
        text_is(page, "#in-force", "forward")
        page.mouse.move(cx + r * 0.8, cy, steps=4)  # round to the right
        wait_sent(web, "C")
        page.mouse.move(cx + r * 0.1, cy, steps=4)  # back into the dead zone: stop
        wait_sent(web, "Z")
        page.mouse.move(cx - r * 0.6, cy + r * 0.6, steps=4)  # rear-left
        wait_sent(web, "F")
        page.mouse.up()  # let go: stop, the knob back in the centre
        wait_sent(web, "Z")
        assert page.locator("#knob").evaluate("(k) => k.style.transform") == ""
        page.keyboard.down("w")  # driven by a key: the stick's sector lights all the same
        until(page, "() => document.querySelector('#sectors .lit')?.dataset.name === 'forward'")
        page.keyboard.up("w")
        until(page, "() => document.querySelector('#sectors .lit') === null")
        page.get_by_role("button", name="Spin").click()  # the button page: the pad
        page.get_by_role("button", name="rotate-cw", exact=True).wait_for()
        assert not page.locator("#stick").is_visible()


def test_the_instruments_show_the_car_the_speed_keys_their_value_and_a_lost_link(
    browser: Browser, tmp_path: Path
) -> None:
    with web_process(tmp_path) as web:
        page = open_page(browser, web, 360, 640, "parameters read")
        assert page.locator("#battery-text").inner_text() == "100 %"
        assert page.locator("#battery").evaluate("(m) => m.value") == 100
        assert page.locator("#heading").get_attribute("aria-label") == "heading 0°"
        assert page.locator("#attitude").get_attribute("aria-label") == "pitch 0°, roll 0°"
        assert page.locator("#speed").inner_text() == "500"
        assert page.locator("#page-name").inner_text() == "joystick page"
        page.get_by_role("button", name="speed up").click()
        page.get_by_text("max_speed = 600 (verified)").wait_for(timeout=10_000)
        text_is(page, "#speed", "600")
        assert "{0:600}" in web.sent()
        box = page.locator("#stick").bounding_box()
        assert box is not None
        page.mouse.move(box["x"] + box["width"] / 2, box["y"] + box["height"] * 0.1)
        page.mouse.down()
        text_is(page, "#measured", "now 600")  # the car's own records: its speed
        assert "moving" in (page.locator("#force-tile").get_attribute("class") or "")
        page.mouse.up()
        wait_sent(web, "Z")
        text_is(page, "#in-force", "stopped")
        web.board.proc.kill()  # the board gone: the chip says so, the readings dim
        text_is(page, "#link", "LINK LOST")
        assert page.locator("#link").get_attribute("class") == "chip lost"
        for reading in ("dials", "battery-tile", "motion"):  # the B and the A records' own
            until(page, f"() => document.getElementById('{reading}').classList.contains('stale')")


def test_over_uart2_the_wheels_show_as_bars_and_who_drives(
    browser: Browser, tmp_path: Path
) -> None:
    with web_process(tmp_path, uart2=True) as web:
        page = open_page(browser, web, 360, 640, "settings read")
        assert page.locator("#driver").inner_text() == "UART2"
        assert page.locator("#speed-name").inner_text() == "speed"
        assert page.locator("#speed").inner_text() == "300"
        box = page.locator("#stick").bounding_box()
        assert box is not None
        page.mouse.move(box["x"] + box["width"] / 2, box["y"] + box["height"] * 0.05)
        page.mouse.down()
        wheel = page.get_by_role("img", name="wheel a: target")
        until(
            page,
            "() => [...document.querySelectorAll('#wheels .bars')].some((b) =>"
            " /target [1-9]/.test(b.getAttribute('aria-label')))",
        )
        assert wheel.count() == 1
        page.mouse.up()
        until(
            page,
            "() => [...document.querySelectorAll('#wheels .bars')].every((b) =>"
            " /target 0,/.test(b.getAttribute('aria-label')))",
        )
        assert web.frames()[-1] == "FF FE 01 00 00 00 00 00 00 00"
        page.get_by_role("button", name="Waves").click()  # no APP port: nothing to draw
        page.get_by_text("No records to draw").wait_for()
        assert not page.locator("#chart").is_visible()


def test_params_are_sliders_with_exact_entry_and_unsaved_values_are_marked(
    browser: Browser, tmp_path: Path
) -> None:
    with web_process(tmp_path) as web:
        page = open_page(browser, web, 360, 640, "parameters read")
        page.get_by_role("button", name="Params").click()
        slider = page.get_by_label("max_speed slider")
        assert slider.get_attribute("max") == "1000"  # 0–65535: a logarithmic slider
        slider.evaluate("(s) => { s.value = '1000'; s.dispatchEvent(new Event('input')); }")
        assert page.get_by_label("new max_speed").input_value() == "65535"
        slider.evaluate("(s) => { s.value = '600'; s.dispatchEvent(new Event('input')); }")
        chosen = int(page.get_by_label("new max_speed").input_value())
        assert 700 < chosen < 1000, chosen  # fine steps low down
        page.get_by_label("new max_speed").fill("650")  # exact entry wins
        page.get_by_role("button", name="set max_speed").click()
        page.get_by_text("max_speed = 650 (verified)").wait_for(timeout=10_000)
        page.get_by_text("Not saved to flash: max_speed").wait_for()
        row = page.locator(".param", has_text="max_speed (0–65535)")
        assert "unsaved" in (row.get_attribute("class") or "")
        assert slider.input_value() == str(round(1000 * math.log1p(650) / math.log1p(65535)))
        page.get_by_role("button", name="Save to flash").click()
        page.get_by_text("Not saved to flash").wait_for(state="hidden")
        assert "unsaved" not in (row.get_attribute("class") or "")
        assert web.sent()[-1] == "{Q:W}"


def chart_pixels(page: Page) -> str:
    return str(page.evaluate("document.getElementById('chart').toDataURL()"))


def test_the_waves_pause_resume_and_hide_channels(browser: Browser, tmp_path: Path) -> None:
    with web_process(tmp_path) as web:
        page = open_page(browser, web, 360, 640, "parameters read")
        page.get_by_role("button", name="Waves").click()
        channels = page.locator("#channels button")
        channels.first.wait_for()
        assert channels.all_inner_texts() == ["x", "y", "z", "pitch", "roll", "yaw", "battery"]
        page.keyboard.down("w")  # the car moves: the traces change
        wait_sent(web, "A")
        page.get_by_role("button", name="Pause").click()
        frozen = chart_pixels(page)
        page.wait_for_timeout(600)
        assert chart_pixels(page) == frozen, "a paused chart does not move"
        page.get_by_role("button", name="Resume").click()
        page.wait_for_timeout(600)
        assert chart_pixels(page) != frozen
        page.keyboard.up("w")
        wait_sent(web, "Z")
        page.get_by_role("button", name="Pause").click()
        all_shown = chart_pixels(page)
        page.get_by_role("button", name="battery", exact=True).click()  # hidden: redrawn
        assert (
            page.get_by_role("button", name="battery", exact=True).get_attribute("aria-pressed")
            == "false"
        )
        assert chart_pixels(page) != all_shown
        size = page.evaluate(
            "(() => { const c = document.getElementById('chart');"
            " return [c.width / c.clientWidth, c.height / c.clientHeight]; })()"
        )
        assert size == [1, 1], "drawn at the size it is shown: labels at their size"
