"""The phone page held to Lighthouse and axe-core: serve `appmode web` on the simulated
board, run Lighthouse (mobile) on it and axe-core on each tab, light and dark, on the
APP port and over UART2, at a phone's size; exit 1 below the targets or on any axe
violation. `.ci/run` runs it with both from npm:

    npm install --prefix DIR lighthouse@12.2.3 axe-core@4
    python -m bench.page_audit --lighthouse DIR/node_modules/.bin/lighthouse \\
        --axe DIR/node_modules/axe-core/axe.min.js
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

TARGETS = {"performance": 95, "accessibility": 100, "best-practices": 100, "seo": 100}
CHROMIUM = "/usr/bin/chromium"
TABS = ("drive", "tilt", "params", "waves")


RUNS = 3
"""Lighthouse runs; each category's median counts, as Lighthouse's docs advise for a
score that varies from run to run with the machine's load."""


def lighthouse(tool: str, url: str) -> list[str]:
    """Lighthouse's scores (the median of RUNS runs), printed; what misses its target."""
    results = sorted(
        (_lighthouse_once(tool, url) for _ in range(RUNS)),
        key=lambda result: result["categories"]["performance"]["score"],
    )
    audits = results[RUNS // 2]["audits"]  # the run of the median performance
    metrics = ("first-contentful-paint", "largest-contentful-paint", "total-blocking-time")
    shown = [
        f"{audits[m]['title']} {audits[m]['displayValue']}"
        for m in (*metrics, "cumulative-layout-shift", "speed-index")
    ]
    print("lighthouse metrics (the median run): " + ", ".join(shown))
    missed = []
    for name, target in TARGETS.items():
        scores = sorted(round(r["categories"][name]["score"] * 100) for r in results)
        score = scores[RUNS // 2]
        print(f"lighthouse {name}: {score} (target {target}; runs {scores})")
        if score < target:
            missed.append(f"lighthouse {name} {score} < {target}")
    return missed


def _lighthouse_once(tool: str, url: str) -> dict[str, Any]:
    with tempfile.TemporaryDirectory() as folder:
        report = Path(folder) / "report.json"
        subprocess.run(
            [
                tool,
                url,
                "--quiet",
                "--chrome-flags=--headless=new --no-sandbox",
                "--output=json",
                f"--output-path={report}",
                f"--only-categories={','.join(TARGETS)}",
            ],
            env={**os.environ, "CHROME_PATH": CHROMIUM},
            check=True,
            timeout=300,
        )
        result: dict[str, Any] = json.loads(report.read_text())
    return result


def axe(script: str, url: str, port: str) -> list[str]:
    """axe-core's violations on every tab, light and dark, at 360 x 640, on the page of
    `port` (app or uart2)."""
    from playwright.sync_api import sync_playwright

    source = Path(script).read_text(encoding="utf-8")
    found = []
    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=CHROMIUM)
        for scheme in ("light", "dark"):
            context = browser.new_context(
                viewport={"width": 360, "height": 640},
                is_mobile=True,
                has_touch=True,
                color_scheme=scheme,
                bypass_csp=True,  # axe is evaluated in the page; the page's CSP is 'self'
            )
            page = context.new_page()
            page.goto(url)
            ready = "settings read" if port == "uart2" else "parameters read"
            page.get_by_text(ready).wait_for(timeout=10_000)
            page.evaluate(source)
            for tab in TABS:
                page.locator(f'nav button[data-tab="{tab}"]').click()
                result = page.evaluate("axe.run(document).then(r => r.violations)")
                for violation in result:
                    nodes = len(violation["nodes"])
                    found.append(f"axe {port} {scheme} {tab}: {violation['id']} ({nodes} nodes)")
                print(f"axe {port} {scheme} {tab}: {len(result)} violations")
            context.close()
        browser.close()
    return found


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--lighthouse", required=True, help="the lighthouse command")
    parser.add_argument("--axe", required=True, help="axe.min.js")
    args = parser.parse_args()
    missed = []
    for port in ("app", "uart2"):
        web = subprocess.Popen(
            [sys.executable, "-m", "appmode", "web", "sim://", "--listen", "127.0.0.1:0"]
            + (["--uart2"] if port == "uart2" else []),
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            text=True,
        )
        try:
            assert web.stdout is not None
            url = web.stdout.readline().removeprefix("web: ").strip()
            if port == "app":
                missed += lighthouse(args.lighthouse, url)
            missed += axe(args.axe, url, port)
        finally:
            web.send_signal(signal.SIGINT)
            web.wait(10)
    for line in missed:
        print(f"missed: {line}", file=sys.stderr)
    return 1 if missed else 0


if __name__ == "__main__":
    sys.exit(main())
