"""The console's picture for the README and the docs (docs/console.svg): `appmode drive`
on the simulated board in tmux, ↑ held for a second, the screen as SVG.

Needs tmux and rich (`pip install rich`): python -m bench.console_shot docs/console.svg
"""

from __future__ import annotations

import argparse
import io
import subprocess
import sys
import time

from rich.console import Console
from rich.text import Text

SESSION = "appmode-shot"


def tmux(*args: str) -> str:
    return subprocess.run(["tmux", *args], capture_output=True, text=True, check=True).stdout


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("svg", help="where to write the picture")
    args = parser.parse_args()
    tmux(
        "new-session",
        "-d",
        "-s",
        SESSION,
        "-x",
        "80",
        "-y",
        "24",
        f"exec {sys.executable} -m appmode drive",
    )
    try:
        time.sleep(2.0)  # the parameters read
        end = time.monotonic() + 1.0
        while time.monotonic() < end:  # ↑ held: the terminal repeats it
            tmux("send-keys", "-t", SESSION, "Up")
            time.sleep(0.03)
        screen = tmux("capture-pane", "-p", "-e", "-t", SESSION)
    finally:
        subprocess.run(["tmux", "kill-session", "-t", SESSION], check=False)
    console = Console(
        record=True, width=80, force_terminal=True, color_system="truecolor", file=io.StringIO()
    )
    console.print(Text.from_ansi(screen.rstrip("\n")), crop=True, overflow="crop")
    console.save_svg(args.svg, title="appmode drive")


if __name__ == "__main__":
    main()
