"""The chassis-port host as a state machine, with no I/O: what it knows of the board.

`ChassisState.feed(data, now)` decodes the board's status frames and keeps them (a
bounded history: the car's twist as its wheels count it, for odometry), with the link's
counters; `sent(data, now)` follows what the host sent, decoded as the board does: the
velocity in force (the board acknowledges nothing: what was last sent is what it has).
"""

from __future__ import annotations

from collections import deque

from appmode.host.stats import LinkStats
from appmode.protocol import chassis

HISTORY = 400
"""Status frames kept: 20 s of the board's 20 Hz."""


class ChassisState:
    """The last status frames, the velocity in force and the link's counters."""

    def __init__(self) -> None:
        self.decoder = chassis.StatusDecoder()
        self.sent_decoder = chassis.CommandDecoder()
        self.stats = LinkStats()
        self.statuses: deque[tuple[float, chassis.Status]] = deque(maxlen=HISTORY)
        """(session time, frame) of the last status frames, oldest first."""
        self.in_force: chassis.Command | None = None
        """The last velocity frame sent that asks for motion; None: the last was a stop."""
        self.sent_at: float | None = None
        """When the last velocity frame went out (session time)."""
        self.query: None = None
        """No read or set runs: a chassis port has none (a session is never busy)."""

    @property
    def status(self) -> chassis.Status | None:
        return self.statuses[-1][1] if self.statuses else None

    @property
    def status_at(self) -> float | None:
        return self.statuses[-1][0] if self.statuses else None

    def reset_decoder(self) -> None:
        """A new link: what was held of the old one is no frame."""
        self.decoder = chassis.StatusDecoder()

    def feed(self, data: bytes, now: float) -> list[chassis.Status | chassis.Junk]:
        """The board's bytes: status frames, and runs that are none (counted as errors
        once a frame has come: before it, the end of a frame caught half way)."""
        self.stats.bytes_in += len(data)
        events: list[chassis.Status | chassis.Junk] = []
        for event in self.decoder.feed(data):
            if isinstance(event, chassis.Status):
                self.stats.count_record(now)
                self.statuses.append((now, event))
            elif self.stats.records:
                self.stats.count_error(now, len(event.raw))
            else:
                self.stats.skipped += len(event.raw)
            events.append(event)
        return events

    def sent(self, data: bytes, now: float) -> list[chassis.Command | chassis.Junk]:
        """What the host sent, read as the board reads it."""
        self.stats.bytes_out += len(data)
        events: list[chassis.Command | chassis.Junk] = []
        for event in self.sent_decoder.feed(data):
            if isinstance(event, chassis.Command):
                self.sent_at = now
                self.in_force = None if event.twist.still else event
            events.append(event)
        return events
