"""`--foxglove [HOST:]PORT`: the option, and the live view it opens (`viewers.live`)."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Iterator
from contextlib import contextmanager

from appmode.cli.options import listen

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing: start-up stays short
if TYPE_CHECKING:
    from appmode.cli.options import Address
    from appmode.protocol.layouts import Layout
    from appmode.protocol.params import DriveType
    from appmode.viewers.live import LiveView

HELP = (
    "serve it live to Foxglove or Lichtblick (Open connection → Foxglove WebSocket) on "
    "[HOST:]PORT: 127.0.0.1 unless a host is given; 8765 is the viewers' usual port, 0 "
    "picks a free one (needs the foxglove extra)"
)


DRIVE_HELP = (
    "let the viewer drive (a Teleop panel publishing geometry_msgs/msg/Twist on /cmd_vel "
    "at 5 Hz or more: each twist lasts 0.5 s) and tune the car (the Parameters panel); "
    "this machine's viewers only"
)


def add_foxglove(
    parser: argparse.ArgumentParser, what: str = "the session", drives: bool = False
) -> None:
    """`--foxglove`, and with `drives` (a command that drives a car) `--foxglove-drive`."""
    parser.add_argument(
        "--foxglove",
        type=listen("--foxglove"),
        metavar="[HOST:]PORT",
        help=HELP.replace("it live", f"{what} live", 1),
    )
    if drives:
        parser.add_argument("--foxglove-drive", action="store_true", help=DRIVE_HELP)


class LiveViews:
    """The live view `--foxglove` asks for, made once the board is known (`make`: the
    session opener calls it with the session's layout) and stopped on the way out,
    after what it was fed is logged. With `drive`, its viewers may drive and tune the
    car (`session.opener.open_session` gives them the session)."""

    def __init__(self, where: Address | None, drive: bool = False) -> None:
        from appmode.errors import AppmodeError

        if where is None and drive:
            raise AppmodeError("--foxglove-drive needs --foxglove PORT (the viewers' server)")
        self._where = where
        self._drive = drive
        self._view: LiveView | None = None

    def __enter__(self) -> LiveViews:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def make(self, layout: Layout, drive_type: DriveType | None = None) -> LiveView | None:
        """The view (None if none was asked for), its address said on stderr, for
        records of `layout`; `drive_type` signs the A records' magnitudes by the control
        port's frames (the pose)."""
        from appmode.errors import AppmodeError

        if self._where is None:
            return None
        from appmode.viewers.live import LiveView
        from appmode.web.access import is_loopback

        host, port = self._where
        if self._drive and not is_loopback(host):
            raise AppmodeError(
                f"--foxglove-drive serves this machine only (a Foxglove viewer shows no "
                f"owner's token): serve on a loopback address (--foxglove {port}), and from "
                f"another machine reach it through SSH (ssh -L {port}:localhost:{port} "
                "THIS-MACHINE)"
            )
        view = self._view = LiveView(host, port, layout, drive=self._drive, drive_type=drive_type)
        print(
            f"foxglove: {view.url} (in Foxglove or Lichtblick: Open connection → Foxglove "
            "WebSocket)",
            file=sys.stderr,
            flush=True,
        )
        if self._drive:
            print(
                "foxglove: viewers on this machine may drive (Teleop on /cmd_vel, 0.5 s a "
                "twist) and tune (Parameters)",
                file=sys.stderr,
                flush=True,
            )
        if not is_loopback(host):
            print(
                f"appmode: WARNING: the live view is served on {host}:{view.port}: every "
                "device that reaches this machine there can watch the car (a viewer cannot "
                "drive it)",
                file=sys.stderr,
                flush=True,
            )
        return view

    def close(self) -> None:
        """Stop the view, if one was made, and say what it dropped."""
        view, self._view = self._view, None
        if view is None:
            return
        view.close()
        if view.dropped:
            print(
                f"appmode: the live view dropped {view.dropped} units it had no room for",
                file=sys.stderr,
            )


@contextmanager
def live_view(
    where: Address | None, layout: Layout, drive_type: DriveType | None = None
) -> Iterator[LiveView | None]:
    """The live view of a command without a session (a board, a monitor, a replay):
    made at once (`LiveViews.make`), stopped on the way out."""
    with LiveViews(where) as views:
        yield views.make(layout, drive_type)
