"""What the car's last records say: whether it moves (its A record: what a share judges
its stops on, by the local host's rule, `STILL`), its battery (its B record)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from appmode.host.app.state import STILL
from appmode.protocol import app

if TYPE_CHECKING:
    from appmode.protocol.layouts import Layout

FRESH = 1.0
"""Seconds an A record tells whether the car moves."""


class LastRecords:
    """The car's last A record its host saw, and when (the car's time); its battery."""

    def __init__(self) -> None:
        self.velocity: app.Velocity | None = None
        self.at = 0.0
        self.battery: int | None = None

    def saw(self, event: object, now: float, layout: Layout) -> bool | None:
        """Keep `event` if it is a record of these: whether it shows the car moving
        (None: it is no A record)."""
        if isinstance(event, app.Attitude):
            self.battery = event.battery
        if not isinstance(event, app.Velocity):
            return None
        self.velocity, self.at = event, now
        return self.moving(layout)

    def moving(self, layout: Layout, now: float | None = None) -> bool | None:
        """Whether the last A record (of the last FRESH s, when `now` is given) shows the
        car moving; None: none came."""
        velocity = self.velocity
        if velocity is None or (now is not None and now - self.at > FRESH):
            return None
        return layout.speed(velocity.values) > STILL
