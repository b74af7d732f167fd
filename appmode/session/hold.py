"""Hold-to-drive with no key-release events, as a state machine with no I/O.

Terminals report key presses (and the OS repeats them while a key is held) but never a
release. A press of a new direction sends its letter; presses of the same one keep it
alive; when they stop coming the car is stopped with `Z`. The first timeout is longer
than the OS delay before auto-repeat starts, the second short, for once repeats arrive.
In latched mode a direction stays until stop or another direction; a twist (`TWIST`, a
velocity a program keeps sending) never latches: it lasts while it is repeated.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from appmode.protocol.directions import STOP_LETTER
from appmode.session.timeouts import FIRST_TIMEOUT, REPEAT_TIMEOUT

TWIST = "twist"
"""What is held while a program's twists keep coming (`BaseSession.move`)."""
TYPED_TWIST = "typed twist"
"""A twist typed on the command line: held as a typed `drive` is (latched in a script)."""


@dataclass(slots=True)
class HoldToDrive:
    first_timeout: float = FIRST_TIMEOUT
    repeat_timeout: float = REPEAT_TIMEOUT
    latched: bool = False
    current: str | None = None
    deadline: float = field(default=0.0)
    timed: bool = False
    """The direction in force has a timeout of its own (`press`'s): it never latches."""

    def press(self, letter: str, now: float, timeout: float | None = None) -> str | None:
        """A key for `letter` was pressed (or repeated): the letter to send, if any.
        `timeout`: how long this press lasts, first or repeated (a source with a
        deadline of its own, such as a viewer's twists), instead of the two timeouts."""
        if letter == STOP_LETTER:
            self.current = None
            return STOP_LETTER
        self.timed = timeout is not None
        if letter == self.current:
            self.deadline = now + (self.repeat_timeout if timeout is None else timeout)
            return None
        first = self.first_timeout if timeout is None else timeout
        self.deadline = now + first  # first: the stop guard reads both
        self.current = letter
        return letter

    def late(self, now: float) -> float | None:
        """Seconds a held direction is past its deadline (below 0: not yet); None when
        none is held, or it is latched (a twist never is, nor a press with a timeout)."""
        if self.current is None or (self.latched and self.current != TWIST and not self.timed):
            return None
        return now - self.deadline

    def release_due(self, now: float) -> bool:
        """True once, when a held direction has timed out and `Z` must be sent."""
        late = self.late(now)
        if late is None or late < 0:
            return False
        self.current = None
        return True

    def stop(self) -> None:
        """Forget the direction in force (a stop was sent another way)."""
        self.current = None
