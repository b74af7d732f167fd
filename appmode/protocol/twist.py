"""The car's one motion language, with no I/O: a twist, the body velocity in SI units as
REP 103 has it (m/s forward, m/s left, rad/s counter-clockwise), and the same in a board's
velocity units (x right, y forward, z clockwise, as the APP record and the control
port's frames count them; a profile's `velocity_si` says what one unit is)."""

from __future__ import annotations

import math
from dataclasses import dataclass

STILL = 0.005
"""m/s, and rad/s, below which a velocity asks for no motion."""
LIMIT = 100.0
"""m/s, and rad/s, past which a velocity is no car's: a request beyond it is refused."""


class BadTwist(ValueError):
    """A twist that is no number (NaN, infinite), or no car's (past LIMIT)."""


@dataclass(frozen=True, slots=True)
class Twist:
    """A body velocity in SI: `forward` and `left` in m/s, `turn` in rad/s
    counter-clockwise (REP 103)."""

    forward: float = 0.0
    left: float = 0.0
    turn: float = 0.0

    @classmethod
    def checked(cls, forward: float, left: float, turn: float) -> Twist:
        """A velocity from outside (a cmd_vel, a script): every part a finite number
        within ±LIMIT; raises BadTwist otherwise (what a port cannot drive of it, each
        port clamps as it translates it)."""
        parts = (forward, left, turn)
        if not all(math.isfinite(part) for part in parts):
            raise BadTwist(f"a twist of {forward}, {left}, {turn}: each part must be a number")
        if max(map(abs, parts)) > LIMIT:
            raise BadTwist(
                f"a twist of {forward:g}, {left:g}, {turn:g}: over {LIMIT:g} m/s or rad/s, no car's"
            )
        return cls(*parts)

    @classmethod
    def from_units(cls, x: float, y: float, z: float, si: tuple[float, float]) -> Twist:
        """A board's velocity (x right, y forward, z clockwise, in its units) in SI."""
        return cls(y * si[0], -x * si[0], -z * si[1])

    def units(self, si: tuple[float, float]) -> tuple[float, float, float]:
        """The board's x (right), y (forward), z (clockwise), in its velocity units."""
        return -self.left / si[0], self.forward / si[0], -self.turn / si[1]

    @property
    def still(self) -> bool:
        """It asks for no motion."""
        return max(abs(self.forward), abs(self.left), abs(self.turn)) < STILL

    @property
    def speed(self) -> float:
        """m/s over the ground, whatever the direction."""
        return math.hypot(self.forward, self.left)

    def __str__(self) -> str:
        return f"{self.forward:+.2f} m/s, {self.left:+.2f} m/s, {self.turn:+.2f} rad/s"


STOPPED = Twist()
