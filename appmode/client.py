"""The host side as a state machine, with no I/O: what the host knows of the board.

`HostState.feed(data, now)` decodes board bytes and keeps the last A, B and C records and
the link statistics; a view (console, monitor) reads them.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field

from . import protocol

RATE_WINDOW = 1.0


@dataclass(frozen=True, slots=True)
class LinkStatus:
    """The link went down (`up` False) or came back."""

    up: bool
    text: str


@dataclass(slots=True)
class LinkStats:
    """Counters of one host session."""

    bytes_in: int = 0
    bytes_out: int = 0
    records: int = 0
    errors: int = 0
    discarded: int = 0
    last_record: float | None = None
    _recent: deque[float] = field(default_factory=deque)

    def rate(self, now: float) -> float:
        """Records a second over the last RATE_WINDOW seconds."""
        self._expire(now)
        return len(self._recent) / RATE_WINDOW

    def since_last(self, now: float) -> float | None:
        return None if self.last_record is None else now - self.last_record

    def count_record(self, now: float) -> None:
        self.records += 1
        self.last_record = now
        self._recent.append(now)
        self._expire(now)

    def _expire(self, now: float) -> None:
        while self._recent and self._recent[0] <= now - RATE_WINDOW:
            self._recent.popleft()


class HostState:
    """Last records seen and link counters, fed with the board's bytes."""

    def __init__(self) -> None:
        self.decoder = protocol.BoardDecoder()
        self.stats = LinkStats()
        self.velocity: protocol.Velocity | None = None
        self.attitude: protocol.Attitude | None = None
        self.params: protocol.ParamsRecord | None = None
        self.params_seen = 0  # C records received so far

    def feed(self, data: bytes, now: float) -> list[protocol.BoardEvent]:
        self.stats.bytes_in += len(data)
        events = self.decoder.feed(data)
        for event in events:
            self._apply(event, now)
        return events

    def sent(self, data: bytes) -> None:
        self.stats.bytes_out += len(data)

    def reset_decoder(self) -> None:
        """Forget a partial record (after the link was lost)."""
        self.decoder = protocol.BoardDecoder()

    def _apply(self, event: protocol.BoardEvent, now: float) -> None:
        if isinstance(event, protocol.ERRORS):
            self.stats.errors += 1
            self.stats.discarded += len(event.raw)
            return
        self.stats.count_record(now)
        if isinstance(event, protocol.Velocity):
            self.velocity = event
        elif isinstance(event, protocol.Attitude):
            self.attitude = event
        elif isinstance(event, protocol.ParamsRecord):
            self.params = event
            self.params_seen += 1
