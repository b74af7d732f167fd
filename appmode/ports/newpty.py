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
    """The master side of a new pseudo-terminal; the app opens `path`. It reads and
    writes as a pyserial port does, so the code that uses it takes either."""

    def __init__(self) -> None:
        self._master, self._slave = pty.openpty()
        tty.setraw(self._slave)
        self.path = os.ttyname(self._slave)

    @property
    def in_waiting(self) -> int:
        """Bytes the program wrote that were not read yet (as pyserial's ports say)."""
        return _waiting(self._master)

    def read(self, size: int = 1) -> bytes:
        """At most `size` bytes the program wrote, waiting at most READ_TIMEOUT for the
        first (as a pyserial port with that timeout; `read(0)` does not wait)."""
        if size <= 0 or not select.select([self._master], [], [], READ_TIMEOUT)[0]:
            return b""
        return os.read(self._master, size)

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
    """Bytes that can be read from `fd` (on the slave: written to the program and not
    read by it yet)."""
    (count,) = struct.unpack("i", fcntl.ioctl(fd, termios.FIONREAD, b"\0\0\0\0"))
    return int(count)


SPEEDS = {
    getattr(termios, name): int(name[1:])
    for name in dir(termios)
    if name[0] == "B" and name[1:].isdigit() and int(name[1:]) > 0
}
"""termios speed codes by their bit rates."""


def client_baud(fd: int) -> int | None:
    """The bit rate the program at the other end of pty `fd` set to send at (tcsetattr),
    None when termios has no name for it."""
    return SPEEDS.get(termios.tcgetattr(fd)[5])
