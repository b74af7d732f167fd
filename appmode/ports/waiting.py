"""How many bytes a connected socket holds for reading now: a port's `in_waiting` for the
links that are sockets (`socket://`, `bt://`). Saying 1 whenever any are, as a `select`
does, had a host read one byte a pass: a board's stream filled the pass, and its answers
and records queued behind it (a drive over `bt://` showed 2 records a second)."""

from __future__ import annotations

import select
import socket

PEEK = 65536
"""The most a peek asks for: more than a pass reads."""


def bytes_waiting(link: socket.socket) -> int:
    """Bytes ready to read from `link` without waiting; 1 at its end or on an error, for
    the read that follows to find it."""
    ready, _, _ = select.select([link], [], [], 0)
    if not ready:
        return 0
    try:
        return len(link.recv(PEEK, socket.MSG_PEEK)) or 1
    except BlockingIOError:
        return 0
    except OSError:
        return 1  # a reset: read says so
