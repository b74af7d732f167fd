"""What Zenoh says of a client it refused, as one line of appmode's: Zenoh logs to the
process's standard output (Rust's tracing), in its own format; while the car is shared,
that descriptor is a pipe read here: a refused key becomes `refused a client: wrong
key`, an error or warning one line without source paths, Zenoh's other lines nothing,
and what else comes (appmode's own output) goes on where it went."""

from __future__ import annotations

import contextlib
import os
import re
import threading
from collections.abc import Callable, Iterator

from appmode.net.config import trimmed

FILTER = "zenoh_transport::unicast::establishment::accept=debug"
"""Where Zenoh says it refused a client's key (at debug); every other part of Zenoh logs
its errors only."""
ANSI = re.compile(r"\x1b\[[0-9;]*m")
REFUSED = re.compile(r"Invalid (password|user)")
LOGGED = re.compile(r"\d{4}-\d\d-\d\dT[\d:.]+Z\s+(TRACE|DEBUG|INFO|WARN|ERROR)\b")
"""A line Zenoh logged: its time, then its level."""
LEVEL = re.compile(r"\b(ERROR|WARN)\b\s+\S*\s*(\S+?):\s*(.*)")


def said(line: str) -> str | None:
    """What a line Zenoh logged means for a person, or None (nothing worth a line)."""
    if REFUSED.search(line):
        return (
            "refused a client: wrong key (Zenoh's user-password authentication; from "
            "another share or router: a host key not this one's)"
        )
    found = LEVEL.search(line)
    if found is None:
        return None
    return f"zenoh: {trimmed(found.group(3))[:200]}"


@contextlib.contextmanager
def zenoh_refusals(say: Callable[[str], None]) -> Iterator[None]:
    """While inside, what Zenoh logs is read and said in appmode's lines (`say`)."""
    import zenoh

    reading, writing = os.pipe()
    saved = os.dup(1)
    os.dup2(writing, 1)
    os.close(writing)
    reader = threading.Thread(
        target=_read, args=(reading, saved, say), name="zenoh log", daemon=True
    )
    reader.start()
    with contextlib.suppress(Exception):  # once a process: a second share keeps the first's
        zenoh.init_log_from_env_or(FILTER)
    try:
        yield
    finally:
        os.dup2(saved, 1)  # the pipe's last writer goes: the reader ends
        reader.join(1.0)
        os.close(saved)


def _read(fd: int, out: int, say: Callable[[str], None]) -> None:
    """Zenoh's lines said as appmode's; the rest written on to `out` as it came."""
    with open(fd, "rb") as lines:
        for raw in lines:
            line = ANSI.sub("", raw.decode("utf-8", "replace"))
            with contextlib.suppress(OSError, ValueError):
                if LOGGED.match(line) is None:
                    os.write(out, raw)
                elif (text := said(line)) is not None:
                    say(text)
