"""What the sessions that drive a motion by its name share — the control port's and a
chassis port's: the direction page's 3×3 grid of motions (row 0 is the front), and a
held key that drives one."""

from __future__ import annotations

from abc import abstractmethod

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
