"""`--foxglove [HOST:]PORT`: the option, and the live view it opens (`viewers.live`)."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Iterator
from contextlib import contextmanager

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing: start-up stays short
if TYPE_CHECKING:
    from appmode.protocol.layouts import Layout
    from appmode.viewers.live import LiveView

HELP = (
    "serve it live to Foxglove or Lichtblick (Open connection → Foxglove WebSocket) on "
    "[HOST:]PORT: 127.0.0.1 unless a host is given; 8765 is the viewers' usual port, 0 "
    "picks a free one (needs the foxglove extra)"
)


def add_foxglove(parser: argparse.ArgumentParser, what: str = "the session") -> None:
    parser.add_argument(
        "--foxglove", metavar="[HOST:]PORT", help=HELP.replace("it live", f"{what} live", 1)
    )


@contextmanager
def live_view(spec: str | None, layout: Layout) -> Iterator[LiveView | None]:
    """The live view `--foxglove` asks for (None if not asked), its address said on
    stderr; stopped on the way out, after what it was fed is logged."""
    if spec is None:
        yield None
        return
    from appmode.ports.endpoints import parse_listen
    from appmode.viewers.live import LiveView
    from appmode.web.access import is_loopback

    host, port = parse_listen(spec, "--foxglove")
    view = LiveView(host, port, layout)
    print(
        f"foxglove: {view.url} (in Foxglove or Lichtblick: Open connection → Foxglove WebSocket)",
        file=sys.stderr,
        flush=True,
    )
    if not is_loopback(host):
        print(
            f"appmode: WARNING: the live view is served on {host}:{view.port}: every device "
            "that reaches this machine there can watch the car (a viewer cannot drive it)",
            file=sys.stderr,
            flush=True,
        )
    try:
        yield view
    finally:
        view.close()
        if view.dropped:
            print(
                f"appmode: the live view dropped {view.dropped} units it had no room for",
                file=sys.stderr,
            )
