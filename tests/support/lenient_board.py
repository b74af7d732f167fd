"""A board as lenient as the reference firmware: on a pty, it stores whatever value a set
frame carries and answers `{Q:P}` with a C record of what it holds."""

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
def lenient_board(
    values: list[int], store: Callable[[int, int], int | None] = lambda index, value: value
) -> Iterator[str]:
    """Serve until the block ends; yields the pty path. `values` is updated in place with
    what `store(index, value)` makes of each set (None: the set is ignored)."""
    master, slave = pty.openpty()
    tty.setraw(slave)
    stop = threading.Event()

    def serve() -> None:
        pending = b""
        while not stop.is_set():
            if not select.select([master], [], [], 0.05)[0]:
                continue
            pending += os.read(master, 1024)
            for match in FRAME.finditer(pending):
                body = match.group(1)
                if body == b"Q:P":
                    os.write(master, b"{C" + b":".join(b"%d" % v for v in values) + b"}$")
                else:
                    index, value = (int(x) for x in body.split(b":"))
                    stored = store(index, value)
                    if stored is not None:
                        values[index] = stored
            pending = pending[pending.rfind(b"}") + 1 :] if b"}" in pending else pending[-64:]

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
def runaway_board(y: int = 300) -> Iterator[str]:
    """A board that streams `{A0:<y>:0:0}$` every 50 ms whatever it is told (another
    port in control, say); yields the pty path."""
    master, slave = pty.openpty()
    tty.setraw(slave)
    stop = threading.Event()

    def stream() -> None:
        while not stop.wait(0.05):
            os.write(master, b"{A0:%d:0:0}$" % y)
            if select.select([master], [], [], 0)[0]:
                os.read(master, 1024)  # what the host says changes nothing

    thread = threading.Thread(target=stream, daemon=True)
    thread.start()
    try:
        yield os.ttyname(slave)
    finally:
        stop.set()
        thread.join(2)
        os.close(master)
        os.close(slave)
