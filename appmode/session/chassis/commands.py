"""The chassis port's session commands: each one's name, arguments, help, what runs it
and what completes after it."""

from __future__ import annotations

from typing import TYPE_CHECKING

from appmode.errors import AppmodeError
from appmode.protocol.directions import MOTIONS
from appmode.session.command_line import SPEED_COMPLETES, SPEED_KEYS, SPEED_STEP, CommandSpec

if TYPE_CHECKING:
    from appmode.session.chassis.session import ChassisSession


def _drive(session: ChassisSession, args: list[str]) -> None:
    if len(args) != 1 or args[0] not in MOTIONS:
        raise AppmodeError(f"usage: drive MOTION, one of {', '.join(MOTIONS)}")
    session.press(args[0])


COMMANDS: tuple[CommandSpec[ChassisSession], ...] = (
    CommandSpec(
        "speed",
        "+N|-N|N",
        f"the keys' speed in mm/s (keys + and - step {SPEED_STEP}); they turn at speed / 0.5 m",
        lambda s, a: s.speed_command(a),
        SPEED_COMPLETES,
    ),
    CommandSpec(
        "drive",
        "MOTION",
        "drive: forward, right, rotate-cw… (latched: until stop)",
        _drive,
        dict.fromkeys(MOTIONS),
    ),
    CommandSpec("stop", "", "stop the car (a zero velocity frame)", lambda s, a: s.stop()),
    CommandSpec(
        "send",
        "TOKEN...",
        "send frames as `send --chassis` takes them (velocity:F,L,T, stop, raw hex)",
        lambda s, a: s.send_tokens(a),
    ),
)

KEYS_HELP = (
    "arrows, q w e / a s d / z x c drive · , . turn · space stop · l latch\n"
    "+ - speed · : command · ? help · Ctrl-Q quit"
)
"""The console's keys, as its panel and help show them."""
KEYS = dict(SPEED_KEYS)
"""Keys that run a command line."""
