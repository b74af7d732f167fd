"""What a `cmd_vel` asks of the car, with no I/O: REP 103's velocity (m/s forward and
left, rad/s counter-clockwise) in the board's terms. On the control port, a velocity
frame in the board's units (the profile's `velocity_si`): x right, y forward, z
clockwise on omni and mecanum cars; on differential ones duties of max_speed in ‰, as
§9.1 takes them. The APP port has eight directions and a speed: the nearest direction
on the direction page (a turn on the spot on the button page, or C and G of the
direction page on a differential car) at the speed asked, in the velocity unit."""

from __future__ import annotations

import math
from dataclasses import dataclass

from appmode.protocol import control
from appmode.protocol.params import DriveType

STILL = 0.005
"""m/s, and rad/s, below which a cmd_vel asks for no motion."""
SECTORS = "AHGFEDCB"
"""The direction page's letters by the direction of motion, every 45° counter-clockwise
from forward (A forward, H front-left, G left, …, B front-right: docs/protocol.md §4)."""


def frame_fields(
    forward: float,
    left: float,
    turn: float,
    drive: DriveType,
    si: tuple[float, float],
    max_speed: int | None,
) -> dict[str, int]:
    """The velocity frame's fields (ControlHost.velocity's keywords) for a cmd_vel;
    `max_speed` is needed on a differential car (its frames take duties of it)."""
    x, y, z = -left / si[0], forward / si[0], -turn / si[1]
    if not drive.differential:
        return {k: _within(v, control.U16) for k, v in (("x", x), ("y", y), ("z", z))}
    if not max_speed:
        raise ValueError("a differential car's frames are duties of max_speed: read it first")
    duty_y, duty_z = y / max_speed * 1000, z / max_speed * 1000
    if drive is DriveType.DIFF_GYRO:
        return {
            "left": _within(duty_y + duty_z, control.MAX_DUTY),
            "right": _within(duty_y - duty_z, control.MAX_DUTY),
        }
    return {"y": _within(duty_y, control.MAX_DUTY), "z": _within(duty_z, control.MAX_DUTY)}


def _within(value: float, limit: int) -> int:
    return max(-limit, min(limit, round(value)))


@dataclass(frozen=True, slots=True)
class Letter:
    """A direction of the APP port: the page it is on, its letter, and the speed
    (max_speed, in the velocity unit) that gives the cmd_vel's magnitude."""

    page: str
    letter: str
    speed: int


def letter_for(
    forward: float, left: float, turn: float, drive: DriveType, si: tuple[float, float]
) -> Letter | None:
    """The nearest the APP port comes to a cmd_vel (None: stop). A motion with both a
    translation and a turn drives the translation: the port has no letter for both."""
    moving = math.hypot(forward, left)
    if moving >= STILL:
        sector = round(math.degrees(math.atan2(left, forward)) / 45) % 8
        return Letter("J", SECTORS[sector], max(1, round(moving / si[0])))
    if abs(turn) < STILL:
        return None
    clockwise = turn < 0
    page = "J" if drive.differential else "K"  # §4: C turns right on the spot on diff
    return Letter(page, "C" if clockwise else "G", max(1, round(abs(turn) / si[1])))
