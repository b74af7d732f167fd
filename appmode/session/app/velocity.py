"""A twist on the APP port, with no I/O: the port has eight directions and a speed, so
a twist is the nearest direction of the direction page at the speed asked (a turn on
the spot on the button page, or C and G of the direction page on a differential car),
in the profile's velocity unit."""

from __future__ import annotations

import math
from dataclasses import dataclass

from appmode.host.app.state import HostState
from appmode.protocol import params
from appmode.protocol.params import DriveType
from appmode.protocol.twist import STILL, Twist

SECTORS = "AHGFEDCB"
"""The direction page's letters by the direction of motion, every 45° counter-clockwise
from forward (A forward, H front-left, G left, …, B front-right: docs/protocol.md §4)."""


@dataclass(frozen=True, slots=True)
class Letter:
    """A direction of the APP port: the page it is on, its letter, and the speed
    (max_speed, in the velocity unit) that gives the twist's magnitude (a diagonal
    drives both axes at max_speed)."""

    page: str
    letter: str
    speed: int


def letter_for(twist: Twist, drive: DriveType, si: tuple[float, float]) -> Letter | None:
    """The nearest the APP port comes to `twist` (None: stop). A motion with both a
    translation and a turn drives the translation: the port has no letter for both."""
    if twist.still:
        return None
    if twist.speed >= STILL:
        sector = round(math.degrees(math.atan2(twist.left, twist.forward)) / 45) % 8
        per_axis = twist.speed / (math.sqrt(2) if sector % 2 and not drive.differential else 1)
        return Letter("J", SECTORS[sector], max(1, round(per_axis / si[0])))
    clockwise = twist.turn < 0
    page = "J" if drive.differential else "K"  # §4: C turns right on the spot on diff
    return Letter(page, "C" if clockwise else "G", max(1, round(abs(twist.turn) / si[1])))


def speed_and_drive(state: HostState) -> tuple[int | None, DriveType]:
    """The APP port's speed parameter and drive type, as its last C record gave them
    (no record yet, or no system_mode: an omni car, whose letters every drive takes)."""
    layout = state.layout
    if state.params is None:
        return None, DriveType.OMNI
    values = state.params.values
    speed = None if layout.speed_index is None else int(values[layout.speed_index])
    names = [param.name for param in layout.params]
    if "system_mode" not in names:
        return speed, DriveType.OMNI
    drive = params.drive_type(int(values[names.index("system_mode")]))
    return speed, drive or DriveType.OMNI
