"""appmode web in a real browser (Chromium under Playwright): how long from a finger on
the ↑ cell to the `A` on the board's wire, what the server costs while pages watch, and
what the page weighs.

The latency bench is its own board: it opens a pty pair, gives `appmode web` the slave
and reads the master, so each byte is timed where the board would read it.
`--screenshots DIR` saves the page at 360×640, 640×360 and 1280×800 (docs/ keeps them).
"""

from __future__ import annotations

import argparse
import os
import pty
import select
import subprocess
import time
import tty
from contextlib import AbstractContextManager
from pathlib import Path

from playwright.sync_api import Browser, Page, sync_playwright

from bench.common import Row, board, cpu_seconds, percentile, started

CHROMIUM = "/usr/bin/chromium"
ROOT = Path(__file__).resolve().parent.parent
ASSETS = ROOT / "appmode" / "web" / "static"
PAUSE = 0.05
"""Seconds between a release and the next press: a page may send 60 messages a second
(bridge.RATE); pressing faster than a person can meets that limit, not the latency."""


def web(url: str, *args: str) -> AbstractContextManager[tuple[subprocess.Popen[str], str]]:
    """`appmode web URL` on a free port: the process and the page's address."""
    return started("web", url, "--listen", "127.0.0.1:0", *args)


def open_page(browser: Browser, address: str, width: int = 360, height: int = 640) -> Page:
    page = browser.new_page(viewport={"width": width, "height": height})
    page.goto(address)
    page.locator("#badge.simulated, #badge.real").wait_for(timeout=10_000)  # a status came
    return page


def forward(page: Page) -> tuple[float, float]:
    """Where a finger pushes the joystick forward (the page's first control)."""
    box = page.locator("#stick").bounding_box()
    assert box is not None
    return box["x"] + box["width"] / 2, box["y"] + box["height"] * 0.15


def read_until(fd: int, wanted: bytes, timeout: float = 2.0) -> float:
    """Read the board's side until `wanted` comes; when it came."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        ready, _, _ = select.select([fd], [], [], 0.05)
        if ready:
            data = os.read(fd, 4096)
            if wanted in data:
                return time.monotonic()
    raise SystemExit(f"the board never read {wanted!r}")


def latency(browser: Browser, presses: int) -> list[float]:
    """Seconds from the pointer going down on the joystick's ↑ to the `A` reaching the
    board."""
    master, slave = pty.openpty()
    tty.setraw(slave)
    tty.setraw(master)
    took = []
    with web(os.ttyname(slave)) as (_, address):
        page = open_page(browser, address)
        page.mouse.move(*forward(page))
        time.sleep(0.5)
        os.read(master, 4096)  # the session's start
        for _ in range(presses):
            down = time.monotonic()
            page.mouse.down()
            took.append(read_until(master, b"A") - down)
            page.mouse.up()
            read_until(master, b"Z")
            time.sleep(PAUSE)
        page.close()
    os.close(master)
    os.close(slave)
    return took


def server_cpu(browser: Browser, pages: int, seconds: float) -> float:
    """The web process's share of a core while `pages` pages show a streaming board."""
    with board("--pty") as url, web(url) as (proc, address):
        opened = [open_page(browser, address) for _ in range(pages)]
        time.sleep(1.0)
        start, begun = cpu_seconds(proc.pid), time.monotonic()
        time.sleep(seconds)
        share = (cpu_seconds(proc.pid) - start) / (time.monotonic() - begun)
        for page in opened:
            page.close()
    return share


def weight_and_paint(browser: Browser) -> tuple[int, float]:
    """The page's bytes (its three assets) and its first contentful paint (ms)."""
    size = sum(path.stat().st_size for path in ASSETS.iterdir())
    with web("sim://") as (_, address):
        page = open_page(browser, address)
        paint = page.evaluate(  # the entry may come after the load: wait for it
            """() => new Promise((done) => new PerformanceObserver((list) => {
                const fcp = list.getEntriesByName('first-contentful-paint')[0];
                if (fcp) done(fcp.startTime);
            }).observe({type: 'paint', buffered: true}))"""
        )
        page.close()
    return size, float(paint)


SHOTS = (
    (360, 640, "web-phone.png"),
    (640, 360, "web-landscape.png"),
    (1280, 800, "web-desktop.png"),
)
"""The screenshots docs/ keeps: a phone upright and on its side, a desktop."""


def screenshots(browser: Browser, folder: Path) -> None:
    folder.mkdir(parents=True, exist_ok=True)
    with web("sim://") as (_, address):
        for width, height, name in SHOTS:
            page = open_page(browser, address, width, height)
            page.get_by_text("parameters read").wait_for(timeout=10_000)
            page.mouse.move(*forward(page))
            page.mouse.down()
            time.sleep(1.0)  # the car under way, its velocity shown
            page.screenshot(path=str(folder / name))
            page.mouse.up()
            page.close()
            time.sleep(0.3)


def rows(quick: bool) -> list[Row]:
    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=CHROMIUM)
        try:
            took = [t * 1000 for t in latency(browser, 50 if quick else 200)]
            one = server_cpu(browser, 1, 5 if quick else 15)
            ten = server_cpu(browser, 10, 5 if quick else 15)
            size, paint = weight_and_paint(browser)
        finally:
            browser.close()
    return [
        Row(
            "web: pointer-down on the joystick's ↑ to A on the board",
            f"p50 {percentile(took, 50):.1f} ms, p99 {percentile(took, 99):.1f} ms "
            f"(n={len(took)}, Chromium)",
            "p99 < 30 ms",
            percentile(took, 99) < 30,
        ),
        Row(
            "web: server CPU, one page streaming",
            f"{one * 100:.2f} % of a core",
            "< 3 %",
            one < 0.03,
        ),
        Row("web: server CPU, ten pages watching", f"{ten * 100:.2f} % of a core", "", None),
        Row(
            "web: page weight, first paint",
            f"{size / 1000:.1f} KB, first contentful paint {paint:.0f} ms",
            "< 150 KB, < 300 ms",
            size < 150_000 and paint < 300,
        ),
    ]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true", help="fewer presses, shorter runs")
    parser.add_argument("--screenshots", metavar="DIR", help="save the page's screenshots there")
    args = parser.parse_args()
    if args.screenshots:
        with sync_playwright() as playwright:
            browser = playwright.chromium.launch(executable_path=CHROMIUM)
            screenshots(browser, Path(args.screenshots))
            browser.close()
        return
    for row in rows(args.quick):
        print(f"{row.benchmark}: {row.result} (target {row.target or '—'}; met: {row.met})")


if __name__ == "__main__":
    main()
