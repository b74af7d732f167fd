"""The web page in a real Chromium (Debian's, under Playwright), as a person uses it on
a phone (360×640, touch) and on a desktop: the pad drives while a finger holds it and
stops when it lifts, a second finger leaves no direction behind, keys drive, and a
closed or hidden page stops the car."""

from __future__ import annotations

import time
from pathlib import Path

import pytest
from playwright.sync_api import Browser, CDPSession, Page

from tests.support.processes import timed_sent
from tests.support.web import WebProcess, wait_frame, wait_frames, wait_sent, web_process


def phone(browser: Browser, web: WebProcess, control: str = "pad") -> Page:
    """A phone's page, its driving control chosen as a user's choice is remembered: the
    3×3 pad (what these tests hold) or the joystick (the page's first choice)."""
    context = browser.new_context(
        viewport={"width": 360, "height": 640}, has_touch=True, is_mobile=True
    )
    page = context.new_page()
    page.add_init_script(f"localStorage.setItem('appmode-control', '{control}')")
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


@pytest.mark.timing
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
        rising = [y for _, y in a_records(web)][-6:]
        assert rising[-1] > rising[0] > 0 or rising[-1] == rising[0] > 0, rising
        released = time.monotonic()
        page.mouse.up()
        wait_sent(web, "Z")
        stop_at = web.board.clock_after + timed_sent(web.record)[-1][0]  # on its recording
        assert stop_at - released < 0.3, f"the stop reached the board {stop_at - released} s after"
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


@pytest.mark.parametrize("control", ["stick", "pad"])
def test_the_first_screen_says_how_to_drive_and_always_shows_a_stop(
    browser: Browser, tmp_path: Path, control: str
) -> None:
    """Issue 69.6: the first screen hid how to drive and had no stop with the joystick;
    the joystick's sectors had no labels; the pages had the firmware's names."""
    with web_process(tmp_path) as web:
        page = phone(browser, web, control)
        hint = page.get_by_text("Hold a direction to drive; let go to stop.")
        stop = page.get_by_role("button", name="Stop", exact=True)
        for shown in (hint, stop, page.get_by_role("button", name="Move", exact=True),
                      page.get_by_role("button", name="Spin", exact=True)):  # fmt: skip
            assert shown.is_visible()
            box = shown.bounding_box()
            assert box is not None and box["y"] + box["height"] <= 640, "on the first screen"
        if control == "stick":
            labels = page.locator("#sectors text").evaluate_all(
                "els => els.map(e => e.textContent)"
            )
            assert labels == ["→", "↗", "↑", "↖", "←", "↙", "↓", "↘"]
        page.keyboard.down("w")  # something else drives: a key held
        wait_sent(web, "A")
        stop.click()
        wait_sent(web, "Z")
        page.wait_for_timeout(400)  # the key is still down: no heartbeat starts it again
        assert web.sent()[-1] == "Z", web.sent()[-5:]
        page.keyboard.up("w")
        page.context.close()


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


def test_tilting_drives_past_the_dead_zone_and_level_stops(
    browser: Browser, tmp_path: Path
) -> None:
    with web_process(tmp_path) as web:
        page = phone(browser, web)
        page.get_by_role("button", name="Tilt").click()

        def tilt(beta: float, gamma: float) -> None:
            page.evaluate(
                "([beta, gamma]) => window.dispatchEvent("
                "new DeviceOrientationEvent('deviceorientation', {beta, gamma, alpha: 0}))",
                [beta, gamma],
            )

        level = page.get_by_role("button", name="Calibrate level")
        level.click()  # before the sensor said anything: there is no level to set
        assert "No tilt sensor has answered" in page.locator("#tilt-note").inner_text()
        tilt(40, 0)  # held at 40°: then calibrated as level
        level.click()
        assert "Level set" in page.locator("#tilt-note").inner_text()
        page.get_by_role("button", name="Drive by tilting").click()
        tilt(45, 3)  # inside the dead zone: nothing
        page.wait_for_timeout(300)
        assert "A" not in web.sent()
        for _ in range(5):  # the top edge down: forward, as the sensor repeats
            tilt(15, 0)
            page.wait_for_timeout(100)
        wait_sent(web, "A")
        tilt(40, 25)  # to the right
        wait_sent(web, "C")
        tilt(40, 0)  # level again: stop
        wait_sent(web, "Z")
        assert "I" in web.sent(), "tilt drives on the gravity page, as the app does"
        assert page.locator("#tilt-page").inner_text() == "gravity"
        page.screenshot(path=str(tmp_path / "tilt.png"))


def test_the_button_page_rotates_and_the_pad_says_so(browser: Browser, tmp_path: Path) -> None:
    with web_process(tmp_path) as web:
        page = phone(browser, web)
        page.get_by_role("button", name="Spin").click()
        rotate = page.get_by_role("button", name="rotate-cw", exact=True)
        rotate.wait_for(timeout=5000)
        x, y = centre(page, "rotate-cw")
        page.mouse.move(x, y)
        page.mouse.down()
        wait_sent(web, "C")
        page.mouse.up()
        wait_sent(web, "Z")
        assert "K" in web.sent()
        x, y = centre(page, "front-left")  # B: mirrored on the button page (§4)
        page.mouse.move(x, y)
        page.mouse.down()
        wait_sent(web, "B")
        page.mouse.up()
        wait_sent(web, "Z")


def test_the_params_page_sets_verified_and_save_is_only_requested(
    browser: Browser, tmp_path: Path
) -> None:
    with web_process(tmp_path) as web:
        page = phone(browser, web)
        page.get_by_role("button", name="Params").click()
        page.get_by_label("new max_speed").fill("650")
        page.get_by_role("button", name="set max_speed").click()
        page.get_by_text("max_speed = 650 (verified)").wait_for(timeout=10_000)
        page.get_by_role("button", name="Save to flash").click()
        page.get_by_text("the board saves its parameters to flash (it sends no reply)").wait_for()
        assert "{0:650}" in web.sent() and "{Q:W}" in web.sent()
        page.screenshot(path=str(tmp_path / "params.png"))


def test_a_balance_car_s_page_shows_its_fields_and_sets_its_gains_scaled(
    browser: Browser, tmp_path: Path
) -> None:
    """Issue 53.3: the instruments, the sliders and the speed follow the profile."""
    with web_process(tmp_path, profile="balance") as web:
        page = phone(browser, web)
        motion = page.locator("#motion")
        for field in ("left encoder", "|1.1 right|"):  # a B record and an A record came
            motion.get_by_text(field).wait_for(timeout=5_000)
        assert "balance angle" in motion.inner_text()
        assert page.locator("#dials").is_hidden(), "no pitch, roll, yaw on this car"
        assert page.locator("#speed").inner_text() == "fixed"
        assert page.get_by_role("button", name="speed up").is_disabled()
        assert page.locator("#battery-text").inner_text() == "100 %"
        page.get_by_role("button", name="Params").click()
        names = page.locator("#values .name").all_inner_texts()
        assert names[0] == "balance_kp (0–21474836.47)" and names[4] == "reserved_4 (0–0)"
        assert page.get_by_label("new reserved_4").is_disabled()
        page.get_by_label("new balance_kp").fill("0.42")
        page.get_by_role("button", name="set balance_kp").click()
        page.get_by_text("balance_kp = 0.42 (verified)").wait_for(timeout=10_000)
        assert "{0:42}" in web.sent()
        first = page.locator("#values .value").first
        assert first.inner_text().startswith("0.42")
        page.get_by_label("new balance_kp").fill("0.425")
        page.get_by_role("button", name="set balance_kp").click()
        page.get_by_text("balance_kp takes steps of 0.01").wait_for(timeout=5_000)
        page.screenshot(path=str(tmp_path / "balance-params.png"))


def test_the_waves_page_draws_the_telemetry(browser: Browser, tmp_path: Path) -> None:
    with web_process(tmp_path) as web:
        page = phone(browser, web)
        page.get_by_role("button", name="Waves").click()
        page.wait_for_timeout(1500)
        drawn = page.evaluate(
            "() => { const c = document.getElementById('chart');"
            " const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;"
            " let n = 0; for (let i = 3; i < d.length; i += 4) if (d[i]) n++; return n; }"
        )
        assert drawn > 1000, drawn
        page.screenshot(path=str(tmp_path / "waves.png"))


def test_a_gamepad_stick_drives_and_its_first_button_stops(
    browser: Browser, tmp_path: Path
) -> None:
    with web_process(tmp_path) as web:
        page = browser.new_page()
        page.add_init_script(
            "window.stick = [0, 0]; window.stopButton = false;"
            "navigator.getGamepads = () => [{axes: window.stick,"
            " buttons: [{pressed: window.stopButton}]}];"
        )
        page.goto(web.address)
        page.get_by_text("parameters read").wait_for(timeout=10_000)
        page.evaluate("window.stick = [0, -0.9]")  # pushed forward
        wait_sent(web, "A")
        page.evaluate("window.stick = [-0.8, -0.8]")
        wait_sent(web, "H")
        page.evaluate("window.stick = [0, 0]")
        wait_sent(web, "Z")
        page.close()


def test_a_second_page_watches_and_takes_over_only_when_asked(
    browser: Browser, tmp_path: Path
) -> None:
    with web_process(tmp_path) as web:
        first = phone(browser, web)
        second = phone(browser, web)
        second.get_by_text("another page drives").wait_for()
        first.keyboard.down("w")
        wait_sent(web, "A")
        second.get_by_role("button", name="Take over driving").click()
        wait_sent(web, "Z")
        first.get_by_text("another page drives").wait_for()
        second.get_by_text("This page drives the car.").wait_for()


STOP_FRAME = "FF FE 01 00 00 00 00 00 00 00"


def test_over_uart2_the_analog_pad_s_deflection_is_the_speed(
    browser: Browser, tmp_path: Path
) -> None:
    with web_process(tmp_path, uart2=True) as web:
        page = browser.new_page()
        page.goto(web.address)
        page.get_by_text("settings read").wait_for(timeout=10_000)
        for name in ("Move", "Spin"):  # the APP port's pages: not here
            assert not page.get_by_role("button", name=name, exact=True).is_visible()
        box = page.get_by_role("application").bounding_box()
        assert box is not None
        cx, cy, radius = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2, box["width"] / 2
        page.mouse.move(cx, cy - radius / 2)  # half way forward: y = half the speed
        page.mouse.down()
        frames = wait_frame(web, "FF FE 01 00 00 00 96")  # y 150 of the speed 300
        page.mouse.move(cx, cy - radius)  # all the way: y 300
        full = "FF FE 01 00 00 01 2C 00 00 00"
        before = wait_frame(web, full).count(full)
        page.wait_for_timeout(600)  # held still: the page keeps saying so
        assert web.frames().count(full) >= before + 2, web.frames()[-6:]
        page.mouse.up()
        frames = wait_frame(web, STOP_FRAME)
        assert len(frames) > 2
        page.get_by_label("degrees").fill("45")
        page.get_by_role("button", name="Turn", exact=True).click()
        wait_frames(  # the stop is an 01 frame too: the turn's is one after it
            web,
            lambda now: any(
                frame.startswith("FF FE 01") and int(frame.split()[-1], 16) & 0x10
                for frame in now[len(frames) :]
            ),
            "velocity frame in angle mode after the stop (§9.1)",
        )
        page.close()


def a_records(web: WebProcess) -> list[tuple[float, int]]:
    """(time, y) of the A records the board sent."""
    found = []
    for line in web.record.read_text().splitlines():
        parts = line.split(" ", 2)
        if len(parts) == 3 and parts[1] == "<" and parts[2].startswith("{A"):
            found.append((float(parts[0]), int(parts[2][2:].split(":")[1])))
    return found


def test_a_network_that_drops_while_holding_stops_the_car(browser: Browser, tmp_path: Path) -> None:
    with web_process(tmp_path) as web:
        page = phone(browser, web)
        cdp = page.context.new_cdp_session(page)
        x, y = centre(page, "forward")
        page.mouse.move(x, y)
        page.mouse.down()
        wait_sent(web, "A")
        cdp.send("Network.enable")
        cdp.send(  # nothing gets through any more, the open websocket included
            "Network.emulateNetworkConditions",
            {"offline": True, "latency": 0, "downloadThroughput": 0, "uploadThroughput": 0},
        )
        page.context.set_offline(True)
        wait_sent(web, "Z", timeout=3)
        page.context.close()


def test_a_server_killed_while_holding_is_not_said_to_have_stopped_the_car(
    browser: Browser, tmp_path: Path
) -> None:
    """Issue 64.3: the page says what it knows — the server is gone, the car may still
    be moving — and never that the car was stopped; so does the page kept for when the
    server does not answer."""
    with web_process(tmp_path) as web:
        page = phone(browser, web)
        deadline = time.monotonic() + 10  # polled from here: the page's CSP forbids eval,
        while not page.evaluate("navigator.serviceWorker.controller !== null"):  # which
            assert time.monotonic() < deadline, "the service worker never took the page"
            time.sleep(0.05)  # wait_for_function polls with once the page is slow
        x, y = centre(page, "forward")
        page.mouse.move(x, y)
        page.mouse.down()
        wait_sent(web, "A")
        web.proc.kill()  # SIGKILL: nothing on this machine stops the car now
        banner = page.locator("#connection")
        banner.filter(has_text="may still be moving").wait_for(timeout=5_000)
        said = banner.inner_text()
        assert "stops the car;" not in said and "was stopped" not in said, said
        banner.filter(has_text="NOT ANSWERING").wait_for(timeout=10_000)
        page.screenshot(path=str(tmp_path / "gone.png"))
        assert "may still be moving" in page.locator("#in-force").inner_text()
        assert page.locator("#pad button.lit").count() == 0
        page.mouse.up()
        page.reload()
        offline = page.locator("main").inner_text()
        assert "may still be moving" in offline and "was stopped" not in offline, offline
        page.context.close()
        assert web.sent()[-1] == "A", "the board's recording: nobody stopped it"
