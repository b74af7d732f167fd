"""`socket://HOST:PORT`: pyserial's TCP port, telling how many bytes are waiting
(pyserial's own says 1 whenever any are: ports.waiting)."""

from __future__ import annotations

from serial import PortNotOpenError
from serial.urlhandler import protocol_socket

from appmode.ports.target import Target
from appmode.ports.waiting import bytes_waiting


class Serial(protocol_socket.Serial):  # type: ignore[misc]  # pyserial has no types
    target: Target | None = None

    @property
    def in_waiting(self) -> int:
        """Bytes ready to read now (1 at the connection's end, for `read` to find it)."""
        if not self.is_open:
            raise PortNotOpenError()
        return bytes_waiting(self._socket)
