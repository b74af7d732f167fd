"""`appmode replay`: play one side of a transcript to a port, against absolute deadlines.

Each send's deadline is computed from the start (start + t / speed), never by adding up
sleeps, so a late send does not make every later one late (python-can's MessageSync
idea). It is waited for by sleeping with exact wake-ups (`ports.wakeups`: no timer
slack, and on Linux 6.12+ a short slice, so that a busy machine runs the replay at once
when it wakes), in two sleeps: to EARLY before it, then to it. The second is short, so
the processor waits for it in a shallow idle state and wakes at once: its p99 lateness
is about half of one sleep's. A last stretch waited awake instead is ahead on an idle
machine but, with every core busy, the scheduler makes a process that spins wait and it
ends milliseconds late (bench/replay_timing.py). As the host, the replay ends with `Z`,
like every host session.
"""

from __future__ import annotations

import itertools
import os
import sys
import time
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

import serial

from appmode.errors import AppmodeError
from appmode.host.app.client import Host
from appmode.host.chassis.client import ChassisHost
from appmode.line.wire import APP, CHASSIS
from appmode.ports.urls import new_pty, open_link
from appmode.ports.wakeups import exact_wakeups
from appmode.protocol import chassis
from appmode.protocol.app_decoders import BoardDecoder, HostDecoder
from appmode.protocol.control_view import view as view_of
from appmode.protocol.reader import RECEIVED, RECEIVED_CHASSIS, SENT, SENT_CHASSIS
from appmode.protocol.render import line
from appmode.transcript.reading import read_transcript

if TYPE_CHECKING:
    from appmode.ports.newpty import PtyPort
    from appmode.protocol.channels import Viewer

Item = tuple[float, bytes]
Decoder = HostDecoder | BoardDecoder | chassis.CommandDecoder | chassis.StatusDecoder
EARLY = 0.0005
"""Seconds before a deadline that `play` wakes, to sleep the rest."""


LINES = {APP: (SENT, RECEIVED), CHASSIS: (SENT_CHASSIS, RECEIVED_CHASSIS)}
"""The lines each port's host and board send, by the port a replay plays."""
DECODERS: dict[str, tuple[Callable[[], Decoder], Callable[[], Decoder]]] = {
    APP: (HostDecoder, BoardDecoder),
    CHASSIS: (chassis.CommandDecoder, chassis.StatusDecoder),
}
"""What reads each side of each port, for `--verbose`."""
HOSTS: dict[str, Callable[[str], Host | ChassisHost]] = {APP: Host, CHASSIS: ChassisHost}
"""The host that plays the host's side of each port (and stops the car at its end)."""


def plan(entries: Sequence[tuple[float, str, bytes]], side: str, port: str = APP) -> list[Item]:
    """The (time, bytes) a side sends: `>` lines for the host, `<` lines for the board
    (`c>` and `c<` on a chassis port)."""
    direction = LINES[port][side != "host"]
    return sorted(((t, data) for t, d, data in entries if d == direction), key=lambda i: i[0])


def retime(items: Sequence[Item], gap: float = 0.0, skip: float | None = None) -> list[Item]:
    """The items with every pause between two made at least `gap` and at most `skip`
    seconds (python-can's player's --gap and --skip); the first keeps its time."""
    out: list[Item] = []
    for i, (t, data) in enumerate(items):
        if i:
            pause = max(t - items[i - 1][0], gap)
            t = out[-1][0] + (pause if skip is None else min(pause, skip))
        out.append((t, data))
    return out


def play(
    items: Sequence[Item],
    write: Callable[[bytes], object],
    *,
    speed: float = 1.0,
    loops: int = 1,
    clock: Callable[[], float] = time.monotonic,
    sleep: Callable[[float], None] = time.sleep,
    idle: Callable[[], object] | None = None,
    progress: Callable[[float, float], None] | None = None,
) -> list[float]:
    """Send each item at start + (loop offset + t) / speed; returns how late each was (s)."""
    period = max((t for t, _ in items), default=0.0)
    total = period * loops / speed
    lateness: list[float] = []
    with exact_wakeups():
        start = clock()
        shown = start
        for loop in range(loops):
            for t, data in items:
                deadline = start + (loop * period + t) / speed
                wake = deadline - EARLY  # the first sleep ends here, the second at the deadline
                while (now := clock()) < deadline:
                    if now >= wake:
                        sleep(deadline - now)
                        continue
                    if idle is not None:
                        idle()
                    if progress is not None and now - shown >= 0.2:
                        shown = now
                        progress(shown - start, total)
                    left = wake - now
                    sleep(min(left, 0.05) if idle is not None or progress is not None else left)
                write(data)
                lateness.append(clock() - deadline)
    if progress is not None:
        progress(clock() - start, total)
    return lateness


def run_replay(
    path: str,
    url: str | None,
    side: str,
    speed: float,
    loops: int,
    *,
    gap: float = 0.0,
    skip: float | None = None,
    verbose: bool = False,
    view: Viewer | None = None,
    port: str = APP,
) -> int:
    """Play one side (`host` or `board`) of the transcript at `path` to `url` (`pty`: a new
    pseudo-terminal, for an app to open), `loops` times at `speed`× its pace, of its APP
    port or a chassis `port`; with a live `view`, what is played is shown there too (both
    sides when `url` is None)."""
    transcript = read_transcript(path)
    for warning in transcript.warnings:
        print(f"appmode: WARNING: {warning}", file=sys.stderr)
    entries = [(e.time, e.direction, e.data) for e in transcript.entries]
    if url is None:
        if view is None:
            raise AppmodeError("replay: nowhere to play to: give --to URL or --foxglove PORT")
        return _to_view(path, entries, view, speed, loops, gap, skip)
    items = retime(plan(entries, side, port), gap, skip)
    mark = LINES[port][side != "host"]
    if not items:
        raise AppmodeError(f"{path} has no '{mark}' lines to play as the {side}")
    show = _progress(path) if sys.stderr.isatty() and not verbose else None
    started = time.monotonic()
    decoder = DECODERS[port][side != "host"]() if verbose else None

    def shown(write: Callable[[bytes], object]) -> Callable[[bytes], object]:
        """`write`, printing each unit as it goes (-v), and showing it in the live view."""
        if view is not None:
            view.epoch = time.time()
            write = _also_shown(write, view, mark, started)
        return write if decoder is None else _printed(write, decoder, mark, started)

    if side == "host":
        with HOSTS[port](url) as host:
            late = play(
                items,
                shown(host.send),
                speed=speed,
                loops=loops,
                idle=host.poll_nowait,
                progress=show,
            )
    else:
        link = _open_for_app(url)
        try:
            late = play(
                items,
                shown(link.write),
                speed=speed,
                loops=loops,
                idle=lambda: link.read(link.in_waiting),  # what the app says meanwhile
                progress=show,
            )
        except (serial.SerialException, OSError) as exc:
            raise AppmodeError(f"lost {url} during the replay: {exc}") from None
        finally:
            link.close()
    if show is not None:
        print(file=sys.stderr)
    worst = max(late) * 1000
    print(
        f"replayed {len(late)} {'commands' if side == 'host' else 'records'} from {path} "
        f"as the {side} to {url}; latest send {worst:.2f} ms after its time",
        file=sys.stderr,
    )
    return 0


def _printed(
    write: Callable[[bytes], object], decoder: Decoder, mark: str, started: float
) -> Callable[[bytes], object]:
    """`write`, printing each unit as it goes (`replay -v`)."""

    def write_and_print(data: bytes) -> None:
        write(data)
        views = [view_of(e) for e in decoder.feed(data)]
        text = ", ".join(v[1] for v in views)
        hexed = views[0][2] if views else None  # a chassis port's frames as hex
        print(line(time.monotonic() - started, mark, data, text, hexed), flush=True)

    return write_and_print


def _also_shown(
    write: Callable[[bytes], object], view: Viewer, direction: str, started: float
) -> Callable[[bytes], object]:
    def write_and_show(data: bytes) -> None:
        write(data)
        view(direction, time.monotonic() - started, data)

    return write_and_show


def _to_view(
    path: str,
    entries: list[tuple[float, str, bytes]],
    view: Viewer,
    speed: float,
    loops: int,
    gap: float,
    skip: float | None,
) -> int:
    """Both sides of a transcript played to a live view in real time."""
    ordered = sorted(entries, key=lambda e: e[0])
    items = retime([(t, data) for t, _, data in ordered], gap, skip)
    if not items:
        raise AppmodeError(f"{path} has no lines to play")
    directions = itertools.cycle([d for _, d, _ in ordered])
    show = _progress(path) if sys.stderr.isatty() else None
    print(
        "replay: waiting for a viewer to subscribe (Ctrl-C gives up)", file=sys.stderr, flush=True
    )
    while not view.watched.wait(0.2):  # a short wait: Ctrl-C ends it
        pass
    view.epoch = time.time()
    started = time.monotonic()
    late = play(
        items,
        lambda data: view(next(directions), time.monotonic() - started, data),
        speed=speed,
        loops=loops,
        progress=show,
    )
    if show is not None:
        print(file=sys.stderr)
    print(
        f"replayed {len(late)} lines from {path} to the live view; latest "
        f"{max(late) * 1000:.2f} ms after its time",
        file=sys.stderr,
    )
    return 0


def _open_for_app(url: str) -> serial.SerialBase | PtyPort:
    """The port an app listens on: `pty` makes a new pseudo-terminal, prints its path and
    waits until the app has opened it and sent something (an app asks first)."""
    if url != "pty":
        return open_link(url)
    port = new_pty()
    print(f"port: {port.path}", flush=True)
    print(
        f"waiting for an app to open {port.path} and send something (Ctrl-C to give up)",
        file=sys.stderr,
        flush=True,
    )
    while not port.read():
        pass
    return port


PROGRESS_WIDTH = 79
"""Columns the progress line takes at most (an 80-column terminal does not wrap it)."""


def _progress(path: str) -> Callable[[float, float], None]:
    name = os.path.basename(path) or path

    def show(done: float, total: float) -> None:
        share = 0.0 if total <= 0 else min(1.0, done / total)
        bar = "#" * round(share * 20)
        tail = f" [{bar:<20}] {done:.1f}/{total:.1f} s, ETA {max(0.0, total - done):.1f} s"
        room = PROGRESS_WIDTH - len("replay ") - len(tail)
        shown = name if len(name) <= room else name[: max(0, room - 1)] + "…"
        print(f"\r\033[Kreplay {shown}{tail}", end="", file=sys.stderr, flush=True)

    return show
