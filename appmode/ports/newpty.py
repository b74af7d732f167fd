"""A new pseudo-terminal for another program to open as its serial port: `tap pty` and
`replay --to pty` play the other end."""

from __future__ import annotations

import fcntl
import os
import pty
import select
import struct
import termios
import time
import tty

READ_TIMEOUT = 0.05
SETTLE = 0.05
"""Seconds for bytes written to the master to be counted as waiting on the slave (the
kernel hands them over from a work queue)."""


class PtyPort:
    """The master side of a new pseudo-terminal; the app opens `path`."""

    def __init__(self) -> None:
        self._master, self._slave = pty.openpty()
        tty.setraw(self._slave)
        self.path = os.ttyname(self._slave)

    def read(self, size: int = 1, timeout: float = READ_TIMEOUT) -> bytes:
        """What the program wrote, waiting at most `timeout` seconds for it."""
        if not select.select([self._master], [], [], timeout)[0]:
            return b""
        return os.read(self._master, max(size, 4096))

    def write(self, data: bytes) -> int:
        return os.write(self._master, data)

    def close(self, drain: float = 1.0) -> None:
        """Close, once the program has read what was written (for at most `drain` s):
        closing the master would discard it."""
        end = time.monotonic() + drain
        time.sleep(min(drain, SETTLE))  # the last bytes reach the count only after a while
        while time.monotonic() < end and _waiting(self._slave):
            time.sleep(0.01)
        os.close(self._master)
        os.close(self._slave)


def _waiting(fd: int) -> int:
    """Bytes written to the program and not read by it yet."""
    (count,) = struct.unpack("i", fcntl.ioctl(fd, termios.FIONREAD, b"\0\0\0\0"))
    return int(count)
