"""Whether a stop took, judged on the board's own A records, with no I/O.

After the session's stop, an A record must show the car at rest (every motion field at
most STILL) within SETTLE seconds. If none does, something kept the stop from taking: a
frame left open by another program, or a `}` lost on a noisy link, swallowed the `Z`
(on the sheet board a frame takes letters); a button-page rotation left by `I`/`J` goes
on after `Z` (§13). Then the check asks for `again` (`session_end.stop_again`) and waits once
more; after TRIES stops in all it gives up, and the host says the car may still move.
"""

from __future__ import annotations

from dataclasses import dataclass

from appmode.host.app.state import STILL
from appmode.protocol import app
from appmode.protocol.layouts import Layout

SETTLE = 1.5
"""Seconds after a stop by which the car must be at rest (the reference firmware's
coasting, ÷1.05 a tick, takes about 0.9 s from full speed)."""
TRIES = 3
"""Stops sent in all, the first included."""


@dataclass
class StopCheck:
    layout: Layout
    again: bytes
    """What a new try sends."""
    since: float
    """When the last stop was sent."""
    tries: int = 1
    moving: app.Velocity | None = None
    """The last A record that showed the car moving."""

    def at_rest(self, record: app.Velocity) -> bool:
        """An A record after the stop: True when it shows the car at rest."""
        if self.layout.speed(record.values) <= STILL:
            return True
        self.moving = record
        return False

    def on_time(self, now: float) -> bytes | None:
        """The bytes of a new try when SETTLE has passed since the last (b"" to wait on);
        None when TRIES stops have not taken: give up."""
        if now - self.since < SETTLE:
            return b""
        if self.tries >= TRIES:
            return None
        self.tries += 1
        self.since = now
        return self.again
