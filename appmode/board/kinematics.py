"""Wheels and body (docs/protocol.md §9.2, §11): the simulated car's kinematics.

Documented model (decisions): a wheel's speed is in the A record's velocity unit, so a
car going straight ahead at y = 300 turns every wheel at 300; a wheel's position is its
speed integrated over time (a wheel at 500 for 2 s has moved 1000). Positive is the
wheel's forward.

- mecanum, wheels 1 front-left, 2 front-right, 3 rear-right, 4 rear-left:
  1 = y + x + z, 2 = y − x − z, 3 = y + x − z, 4 = y − x + z;
- omni, three wheels: 1 front-left and 2 front-right at ±60°, 3 at the rear rolling
  sideways: 1 = y·√3/2 − x/2 + z, 2 = −y·√3/2 − x/2 + z, 3 = x + z;
- differential: motors 1 and 4 on the left = y + z, 2 and 3 on the right = y − z.

`body` inverts `wheels` (by least squares where the wheels over-determine the body), so
a per-motor frame moves the body consistently with what the encoders then read.
"""

from __future__ import annotations

import math

from appmode.protocol.params import DriveType

HALF_ROOT3 = math.sqrt(3) / 2


def wheels(drive: DriveType, x: float, y: float, z: float) -> tuple[float, ...]:
    """Each wheel's speed (or position) for a body velocity (or displacement)."""
    if drive is DriveType.OMNI:
        return (HALF_ROOT3 * y - x / 2 + z, -HALF_ROOT3 * y - x / 2 + z, x + z)
    if drive is DriveType.MECANUM:
        return (y + x + z, y - x - z, y + x - z, y - x + z)
    return (y + z, y - z, y - z, y + z)


def body(drive: DriveType, speeds: tuple[float, ...]) -> tuple[float, float, float]:
    """The body velocity that the wheel speeds give (x, y, z)."""
    if drive is DriveType.OMNI:
        a, b, c = speeds[:3]
        return ((2 * c - a - b) / 3, (a - b) / (2 * HALF_ROOT3), (a + b + c) / 3)
    one, two, three, four = speeds[:4]
    if drive is DriveType.MECANUM:
        return (
            (one - two + three - four) / 4,
            (one + two + three + four) / 4,
            (one - two - three + four) / 4,
        )
    left, right = (one + four) / 2, (two + three) / 2
    return (0.0, (left + right) / 2, (left - right) / 2)
