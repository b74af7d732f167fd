"""A viewer's desk: what a viewer asks of the session from a thread of its own (Foxglove's
Teleop and Parameters panels, `viewers.live`), taken by the session at each tick.

A viewer's twist goes through the stop authority as any source's does: it lasts LAPSE
seconds unless the viewer sends it again, and the viewer that left stops what it drove.
One viewer drives at a time: another's twists are refused while the driver's last one is
alive. A parameter set goes through the session's own verified set (one at a time, in
the order asked); when none waits, the values read back go to the viewers (`on_values`).
"""

from __future__ import annotations

import threading
from collections import deque
from collections.abc import Callable
from typing import TYPE_CHECKING

from appmode.errors import AppmodeError
from appmode.protocol.twist import Twist

if TYPE_CHECKING:
    from appmode.session.base import BaseSession

VIEWER = "viewer twist"
"""What is held while a viewer's twists keep coming."""
LAPSE = 0.5
"""Seconds a viewer's twist lasts unless it is sent again."""
SETS = 64
"""Parameter sets waiting at most (the oldest are dropped)."""
LOOK = 0.5
"""Seconds between two looks at the parameters when no set is under way."""
CLIENTS = 64
"""Viewers whose newest twist waits at most (a twist from one more is dropped)."""

Values = dict[str, int | float]
"""The car's parameters by name, in the user's units."""


class Desk:
    """The requests of a session's viewers, thread-safe on the viewer's side."""

    def __init__(self, on_values: Callable[[Values], None]) -> None:
        self._lock = threading.Lock()
        self._twists: dict[int, Twist] = {}
        self._left: set[int] = set()
        self._sets: deque[tuple[str, str]] = deque(maxlen=SETS)
        self._values: Values = {}
        self._on_values = on_values
        self._setting = False
        self._looked = -LOOK
        self.driver: int | None = None
        """The viewer that drives (its client id), None when none does."""
        self._driven_at = 0.0
        self._refused: set[int] = set()
        self._told: deque[str] = deque(maxlen=SETS)

    # ------------------------------------------------------------ the viewer's side

    def twist(self, client: int, twist: Twist) -> None:
        with self._lock:
            if client in self._twists or len(self._twists) < CLIENTS:
                self._twists[client] = twist

    def left(self, client: int) -> None:
        """The viewer stopped publishing, or went away."""
        with self._lock:
            self._left.add(client)

    def set(self, values: list[tuple[str, str]]) -> None:
        """Set parameters (name, value in the user's units), in order."""
        with self._lock:
            self._sets.extend(values)

    def tell(self, text: str) -> None:
        """Something for the session to say (what the viewers' server complains of)."""
        with self._lock:
            self._told.append(text)

    def values(self) -> Values:
        """The parameters as last read (none before they are)."""
        with self._lock:
            return dict(self._values)

    # ------------------------------------------------------------ the session's side

    def serve(self, session: BaseSession) -> None:
        """Act on what the viewers asked since the last tick."""
        with self._lock:
            twists, self._twists = self._twists, {}
            left, self._left = self._left, set()
            told = list(self._told)
            self._told.clear()
        for text in told:
            session.say(text)
        for client, twist in twists.items():
            self._drive(session, client, twist)
        for client in left:
            self._leave(session, client)
        if self.driver is not None and session.now() - self._driven_at > LAPSE:
            session.say(f"viewer {self.driver} no longer drives (no twist for {LAPSE:g} s)")
            self.driver = None
        self._tune(session)

    def _drive(self, session: BaseSession, client: int, twist: Twist) -> None:
        now = session.now()
        if self.driver not in (None, client) and now - self._driven_at <= LAPSE:
            if client not in self._refused:
                self._refused.add(client)
                session.say(f"viewer {client}'s twists are refused: viewer {self.driver} drives")
            return
        if self.driver != client:
            self.driver = client
            session.say(f"viewer {client} drives")
        self._driven_at = now
        session.keepalive()
        session.move(twist, VIEWER, LAPSE)

    def _leave(self, session: BaseSession, client: int) -> None:
        self._refused.discard(client)
        if self.driver != client:
            return
        self.driver = None
        if session.driving.current == VIEWER and session.moving:
            session.stop()
            session.say(f"stopped: viewer {client}, which drove, left")

    def _tune(self, session: BaseSession) -> None:
        if session.busy:
            return
        with self._lock:
            name, value = self._sets.popleft() if self._sets else ("", "")
        if name:
            self._setting = True
            try:
                session.set_parameter(name, value)
            except AppmodeError as exc:
                session.say(f"error: {name} = {value} refused: {exc}")
            if session.busy:
                return
        elif not self._setting and session.now() - self._looked < LOOK:
            return  # the values change with a set, or a C record: looked at now and then
        self._looked = session.now()
        values = session.parameters()
        with self._lock:
            changed, self._values = values != self._values, values
            waiting = bool(self._sets)
        if (changed or self._setting) and not waiting:
            self._setting = False
            self._on_values(values)
