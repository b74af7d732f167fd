"""Boards unlike ours, on a pty, for the host to cope with: one as lenient as the reference
firmware, one that keeps driving whatever it is told."""

from __future__ import annotations

import os
import pty
import re
import select
import threading
import tty
from collections.abc import Callable, Iterator
from contextlib import contextmanager

FRAME = re.compile(rb"\{(Q:P|\d:-?\d+)\}")


@contextmanager
def _pty_board(step: Callable[[int], None], every: float) -> Iterator[str]:
    """A pty whose master `step(master)` serves every `every` seconds in a thread, until
    the block ends; yields the path a host opens."""
    master, slave = pty.openpty()
    tty.setraw(slave)
    stop = threading.Event()

    def serve() -> None:
        while not stop.wait(every):
            step(master)

    thread = threading.Thread(target=serve, daemon=True)
    thread.start()
    try:
        yield os.ttyname(slave)
    finally:
        stop.set()
        thread.join(2)
        os.close(master)
        os.close(slave)


@contextmanager
def lenient_board(
    values: list[int], store: Callable[[int, int], int | None] = lambda index, value: value
) -> Iterator[str]:
    """Answers `{Q:P}` with a C record of `values`, and keeps what `store(index, value)`
    makes of each set frame (None: the set is ignored), like the reference firmware,
    which stores any value. `values` is updated in place."""
    pending = bytearray()

    def step(master: int) -> None:
        if not select.select([master], [], [], 0)[0]:
            return
        pending.extend(os.read(master, 1024))
        for match in FRAME.finditer(pending):
            body = match.group(1)
            if body == b"Q:P":
                os.write(master, b"{C" + b":".join(b"%d" % v for v in values) + b"}$")
                continue
            index, value = (int(x) for x in body.split(b":"))
            stored = store(index, value)
            if stored is not None:
                values[index] = stored
        del pending[: pending.rfind(b"}") + 1]

    with _pty_board(step, 0.01) as path:
        yield path


@contextmanager
def runaway_board(y: int = 300) -> Iterator[str]:
    """Streams `{A0:<y>:0:0}$` every 50 ms whatever it is told (another port in control,
    say)."""

    def step(master: int) -> None:
        os.write(master, b"{A0:%d:0:0}$" % y)
        if select.select([master], [], [], 0)[0]:
            os.read(master, 1024)  # what the host says changes nothing

    with _pty_board(step, 0.05) as path:
        yield path


@contextmanager
def chatty_board(text: bytes) -> Iterator[str]:
    """Sends `text` and a resting A record every 50 ms (a board's start-up text, or a
    hostile one's)."""

    def step(master: int) -> None:
        os.write(master, text + b"{A0:0:0:0}$")
        if select.select([master], [], [], 0)[0]:
            os.read(master, 1024)

    with _pty_board(step, 0.05) as path:
        yield path
