"""What a radio link delivered and nobody has read yet, between the event loop that
receives it and the thread that reads it (a pyserial port's `read`)."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable

RECEIVE_BUFFER = 65536
"""Bytes kept unread at most: past it the oldest go, as an OS's serial buffer drops them."""


class Inbox:
    """Bytes received, guarded by `ready` (which the port may wait on for other things)."""

    def __init__(self, ready: threading.Condition) -> None:
        self.ready = ready
        self._data = bytearray()

    def __len__(self) -> int:
        return len(self._data)

    def add(self, data: bytes | bytearray) -> None:
        with self.ready:
            self._data += data
            if len(self._data) > RECEIVE_BUFFER:  # nobody reads: the oldest go
                del self._data[: len(self._data) - RECEIVE_BUFFER]
            self.ready.notify_all()

    def read(self, size: int, timeout: float | None, check: Callable[[], None]) -> bytes:
        """At most `size` bytes, waiting at most `timeout` seconds (None: until some
        come) for the first; `check` raises when the link can bring no more."""
        deadline = None if timeout is None else time.monotonic() + timeout
        with self.ready:
            while not self._data:
                check()
                left = None if deadline is None else deadline - time.monotonic()
                if left is not None and left <= 0:
                    return b""
                self.ready.wait(left)
            data = bytes(self._data[:size])
            del self._data[:size]
        return data

    def clear(self) -> None:
        with self.ready:
            self._data.clear()
