"""`socket://HOST:PORT`: pyserial's TCP port, telling how many bytes are waiting.

pyserial's own says 1 whenever any are (a `select`), so a host that reads what is
waiting took one byte a pass: a board's stream at 9600 bps filled the pass and its
answers queued behind it (a parameter read over TCP waited seconds). This one peeks."""

from __future__ import annotations

import select
import socket

from serial import PortNotOpenError
from serial.urlhandler import protocol_socket

from appmode.ports.target import Target

PEEK = 65536


class Serial(protocol_socket.Serial):  # type: ignore[misc]  # pyserial has no types
    target: Target | None = None

    @property
    def in_waiting(self) -> int:
        """Bytes ready to read now (1 at the connection's end, for `read` to find it)."""
        if not self.is_open:
            raise PortNotOpenError()
        ready, _, _ = select.select([self._socket], [], [], 0)
        if not ready:
            return 0
        try:
            return len(self._socket.recv(PEEK, socket.MSG_PEEK)) or 1
        except BlockingIOError:
            return 0
        except OSError:
            return 1  # a reset: read says so
