"""What the sessions that drive a motion by its name share — the control port's and a
chassis port's: the direction page's 3×3 grid of motions (row 0 is the front), a held
key that drives one, and sends that turn a lost link into a message."""

from __future__ import annotations

from abc import abstractmethod
from collections.abc import Callable
from functools import partial
from typing import ClassVar

from appmode.errors import AppmodeError
from appmode.host.link import LinkLost, Refused
from appmode.host.waits import Wait
from appmode.protocol import params
from appmode.protocol.directions import DIRECTION_PAGE, GRID, STOP_LETTER
from appmode.session.base import BaseSession
from appmode.session.rows import GLYPHS


class MotionGridSession(BaseSession):
    """A session whose grid keys are motions by name (`forward`, `rotate-cw`…)."""

    def grid_key(self, row: int, col: int) -> str:
        letter = GRID[row][col]
        return STOP_LETTER if letter == STOP_LETTER else DIRECTION_PAGE[letter].name

    def cell_names(self) -> list[list[str]]:
        keys = [[self.grid_key(r, c) for c in range(3)] for r in range(3)]
        return [["stop" if key == STOP_LETTER else key for key in row] for row in keys]

    def grid_cells(self) -> list[list[str]]:
        """The grid's cells as shown: an arrow and what the key drives."""
        names = self.cell_names()
        return [[f"{GLYPHS[r][c]} {names[r][c]}" for c in range(3)] for r in range(3)]

    def press(self, key: str) -> None:
        """A held key: a motion's name (`forward`, `rotate-cw`…) or STOP_LETTER."""
        if self.link_down():
            return
        what = self.driving.press(key, self.now())
        if what == STOP_LETTER:
            self.stop()
        elif what is not None:
            self._drive_named(what)

    @abstractmethod
    def _drive_named(self, name: str) -> None:
        """Drive the motion `name` (a held key's, or the `drive` command's)."""

    speed: int
    """What the keys drive at, in the port's units."""

    def _speed_asked(self, args: list[str], top: int, unit: str = "") -> int:
        """`speed +N`, `speed -N` or `speed N` from the keys' speed, within 0…`top`."""
        number = params.whole(args[0].lstrip("+-")) if len(args) == 1 else None
        if number is None:
            raise AppmodeError(f"usage: speed +N, speed -N or speed N{unit}")
        sign = args[0][0]
        wanted = self.speed + (-number if sign == "-" else number) if sign in "+-" else number
        return min(top, max(0, wanted))

    send_example: ClassVar[str] = ""
    """A `send` command line of the port's tokens, for its usage."""

    def send_tokens(self, tokens: list[str]) -> None:
        """`send`: the port's tokens, as `send` takes them on it, sent in order (what they
        do shows as the frame in force)."""
        if not tokens:
            raise AppmodeError(f"usage: send TOKEN..., e.g. {self.send_example}")
        steps = [self._parse_token(token) for token in tokens]
        if any(isinstance(step, Wait) for step in steps):
            raise AppmodeError("send takes no waits here: use the wait command")
        self._forget_motion()
        for step in steps:
            if not self._send(partial(self._perform, step)):
                return
        self.say(f"sent {' '.join(tokens)}")

    @abstractmethod
    def _parse_token(self, token: str) -> object:
        """A `send` token as the port's step (AppmodeError: not one)."""

    @abstractmethod
    def _perform(self, step: object) -> None:
        """Send one step that `_parse_token` made."""

    def _send(self, send: Callable[[], object]) -> bool:
        """Run a send; a lost link becomes a message (what was in force stays)."""
        try:
            send()
        except (LinkLost, Refused) as exc:
            self.say(str(exc))
            self.driving.stop()
            return False
        return True
