"""A Bluetooth UART module between the radio and the board's APP port (HC-08, HM-10,
HC-05 …), as a model with no I/O: what it takes from the radio, what it notifies.

- The radio side works in connection events, one every CONNECTION_INTERVAL: writes a
  central made since the last event arrive together, and at most NOTIFICATIONS_PER_EVENT
  notifications of at most PAYLOAD bytes go out (the ATT MTU of 23 less 3 bytes).
- The UART side runs at 9600 bps 8N1 (960 bytes/s) both ways. What the radio brings
  faster than that waits in the module's INPUT_BUFFER; what arrives when it is full is
  lost, without a word (real modules drop it too, or reset): a host must pace its writes.
  The other way, notifications carry more than the UART brings; a board that sent faster
  than 9600 bps would find OUTPUT_BUFFER full, and lose the rest.
"""

from __future__ import annotations

from dataclasses import dataclass, field

MTU = 23
PAYLOAD = MTU - 3
CONNECTION_INTERVAL = 0.015
NOTIFICATIONS_PER_EVENT = 4
INPUT_BUFFER = 128
OUTPUT_BUFFER = 512
UART_BYTES_PER_S = 960.0


@dataclass
class ModuleModel:
    """The module's buffers; `now` is seconds on any clock that only goes forward."""

    held: float = 0.0
    """Bytes waiting in the input buffer for the UART (drains at UART_BYTES_PER_S)."""
    at: float = 0.0
    lost: int = 0
    """Bytes lost to a full buffer, either way."""
    outgoing: bytearray = field(default_factory=bytearray)
    """What the board sent that is not notified yet."""

    def from_radio(self, data: bytes, now: float) -> bytes:
        """What the module keeps of a central's write: the rest is lost (counted)."""
        self.held = max(0.0, self.held - (now - self.at) * UART_BYTES_PER_S)
        self.at = now
        room = max(0, INPUT_BUFFER - int(self.held + 0.999))
        kept = data[:room]
        self.held += len(kept)
        self.lost += len(data) - len(kept)
        return kept

    def from_uart(self, data: bytes) -> None:
        """Bytes the board sent; notified at the coming connection events. What the
        radio cannot keep up with past OUTPUT_BUFFER is lost (counted)."""
        self.outgoing += data
        over = len(self.outgoing) - OUTPUT_BUFFER
        if over > 0:
            del self.outgoing[-over:]
            self.lost += over

    def notifications(self) -> list[bytes]:
        """What one connection event notifies, in order."""
        out: list[bytes] = []
        pending = self.outgoing
        while pending and len(out) < NOTIFICATIONS_PER_EVENT:
            out.append(bytes(pending[:PAYLOAD]))
            del pending[:PAYLOAD]
        return out


def next_event(now: float, origin: float) -> float:
    """The first connection event after `now` on the grid that starts at `origin`."""
    done = int((now - origin) / CONNECTION_INTERVAL) + 1
    return origin + done * CONNECTION_INTERVAL
