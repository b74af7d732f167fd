"""The page over a WHEELTEC car's chassis port: the status in SI and the battery in
volts (no percentage made up), driving held by the pad, and the zero frame on release —
judged on the board's recording."""

from __future__ import annotations

import re
import time
from pathlib import Path

from playwright.sync_api import Browser, expect

from appmode.protocol import chassis
from tests.support.web import web_process

STOP = chassis.STOP.hex(" ").upper()


def test_the_page_shows_the_chassis_in_si_and_stops_it(tmp_path: Path, browser: Browser) -> None:
    profile = tmp_path / "quick.toml"
    profile.write_text(
        'name = "quick"\nlike = "wheeltec-mec"\n[chassis]\nkind = "mec"\nboot_ms = 300\n'
    )
    with web_process(tmp_path, profile=str(profile), chassis=True) as web:
        page = browser.new_page()
        try:
            page.goto(web.address)
            expect(page.locator("#battery-text")).to_have_text(re.compile(r"^1\d\.\d\d V$"))
            assert page.locator("#battery").is_hidden(), "a voltage gets no percentage gauge"
            page.keyboard.down("ArrowUp")
            expect(page.locator("#motion")).to_contain_text("forward +0.30 m/s", timeout=10_000)
            assert page.locator("#speed-name").text_content() == "speed mm/s"
            page.keyboard.up("ArrowUp")
            end = time.monotonic() + 5
            frames: list[str] = []
            while time.monotonic() < end:
                lines = web.record.read_text().splitlines() if web.record.exists() else []
                frames = [line.split(" c> ", 1)[1] for line in lines if " c> " in line]
                if frames and frames[-1] == STOP and len(frames) > 3:
                    break
                time.sleep(0.05)
        finally:
            page.close()
    assert chassis.command(chassis.Command(300, 0, 0).twist).hex(" ").upper() in frames
    assert frames[-1] == STOP, "letting go sends the zero frame"
