"""The documentation site read as people read it (issue 79.4): every page of the built
site in Chromium (under Playwright) at a laptop's width (1280 px) and a phone's (390
px); every code block must show each line whole (it wraps, it never clips) with the end
of its first line clear of the copy button, and no page may be wider than the window.
`.ci/run` runs it on the site it builds; each page's screenshot goes to --shots if
given (to look at). Exit status 1, a line a failure.

    python -m bench.site_audit --site DIR [--shots DIR]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

CHROMIUM = "/usr/bin/chromium"
WIDTHS = {"laptop": (1280, 800), "phone": (390, 844)}
CHECK = """() => {
  const found = [];
  const blocks = [...document.querySelectorAll('pre > code')];
  for (const code of blocks) {
    const first = code.textContent.split('\\n')[0].slice(0, 50);
    if (code.scrollWidth > code.clientWidth + 1) found.push('clipped: ' + first);
    const button = code.parentElement.querySelector('.md-clipboard');
    if (button) {
      const box = code.getBoundingClientRect(), at = button.getBoundingClientRect();
      const room = parseFloat(getComputedStyle(code).paddingRight);
      if (at.left < box.right - room - 1) found.push('under the copy button: ' + first);
    }
  }
  if (document.documentElement.scrollWidth > innerWidth) found.push('the page is too wide');
  return [blocks.length, found];
}"""


def audit(site: Path, shots: Path | None) -> tuple[int, list[str]]:
    """Code blocks looked at, and what is wrong, page by page and width by width."""
    from playwright.sync_api import sync_playwright

    pages = sorted(site.rglob("*.html"))
    failures: list[str] = []
    looked = 0
    with sync_playwright() as play:
        browser = play.chromium.launch(executable_path=CHROMIUM)
        try:
            for name, (width, height) in WIDTHS.items():
                tab = browser.new_page(viewport={"width": width, "height": height})
                for path in pages:
                    tab.goto(path.as_uri())
                    count, found = tab.evaluate(CHECK)
                    looked += count
                    where = path.relative_to(site)
                    failures += [f"{where} at {width} px: {what}" for what in found]
                    if shots is not None:
                        shot = shots / f"{name}-{str(where).replace('/', '-')}.png"
                        tab.screenshot(path=str(shot), full_page=True)
                tab.close()
        finally:
            browser.close()
    return looked, failures


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--site", type=Path, required=True, help="the built site")
    parser.add_argument("--shots", type=Path, help="a folder for each page's screenshots")
    args = parser.parse_args()
    if args.shots is not None:
        args.shots.mkdir(parents=True, exist_ok=True)
    looked, failures = audit(args.site, args.shots)
    pages = len(list(args.site.rglob("*.html")))
    print(f"site_audit: {pages} pages at {len(WIDTHS)} widths, {looked} code blocks looked at")
    for failure in failures:
        print(f"site_audit: FAILED: {failure}", file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
