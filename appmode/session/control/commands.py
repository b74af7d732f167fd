"""The control port's session commands: each one's name, arguments, help, what runs it
and what completes after it."""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from appmode.errors import AppmodeError
from appmode.protocol import control, params, settings
from appmode.protocol.directions import MOTIONS
from appmode.session.command_line import SPEED_COMPLETES, SPEED_KEYS, SPEED_STEP, CommandSpec

if TYPE_CHECKING:
    from appmode.session.control.session import ControlSession

SETTING_NAMES = tuple(s.name for s in settings.SETTINGS)


def _read(session: ControlSession, args: list[str]) -> None:
    if not args:
        raise AppmodeError("usage: read NAME..., e.g. read max_speed pending_angle")
    session.query(args)


def _set(session: ControlSession, args: list[str]) -> None:
    value = params.whole(args[1]) if len(args) == 2 else None
    if value is None:
        raise AppmodeError("usage: set NAME VALUE, e.g. set max_speed 800")
    session.set_setting(args[0], value)


def _angle(session: ControlSession, args: list[str]) -> None:
    session.angle = _degrees(args, "usage: angle DEGREES, e.g. angle 45")
    session.say(f"r and R turn {session.angle:g}°")


def _rotate(session: ControlSession, args: list[str]) -> None:
    if args == ["-"]:
        session.rotate(-session.angle)
    else:
        session.rotate(_degrees(args, "usage: rotate [DEGREES]") if args else session.angle)


def _drive(session: ControlSession, args: list[str]) -> None:
    if len(args) != 1 or args[0] not in MOTIONS:
        raise AppmodeError(f"usage: drive MOTION, one of {', '.join(MOTIONS)}")
    session.press(args[0])


def _velocity(session: ControlSession, args: list[str]) -> None:
    if not args:
        raise AppmodeError("usage: velocity X Y Z (diff-gyro: velocity LEFT RIGHT)")
    session.send_tokens(["velocity:" + ",".join(args)])


def _store(name: str) -> Callable[[ControlSession, list[str]], None]:
    return lambda session, args: session.store(name)


COMMANDS: tuple[CommandSpec[ControlSession], ...] = (
    CommandSpec("settings", "", "read the ten settings", lambda s, a: s.query(SETTING_NAMES)),
    CommandSpec(
        "read",
        "NAME...",
        "read values: settings, pending_angle, speed_a, position_a…",
        _read,
        dict.fromkeys(settings.READ_BY_NAME),
    ),
    CommandSpec(
        "set",
        "NAME VALUE",
        "set a setting, verified by reading back",
        _set,
        dict.fromkeys(SETTING_NAMES),
    ),
    CommandSpec("save", "", "save the settings to the board's flash", _store("save")),
    CommandSpec("load", "", "load the saved settings into the running copy", _store("load")),
    CommandSpec(
        "defaults", "", "load the factory defaults into the running copy", _store("defaults")
    ),
    CommandSpec(
        "speed",
        "+N|-N|N",
        f"the speed keys drive at (keys + and - step {SPEED_STEP})",
        lambda s, a: s.speed_command(a),
        SPEED_COMPLETES,
    ),
    CommandSpec("angle", "DEGREES", "the turn r and R make", _angle),
    CommandSpec("rotate", "[DEGREES]", "turn in angle mode (default: the set angle)", _rotate),
    CommandSpec(
        "drive",
        "MOTION",
        "drive: forward, right, rotate-cw… (latched: until stop)",
        _drive,
        dict.fromkeys(MOTIONS),
    ),
    CommandSpec("velocity", "X Y Z|L R", "send a velocity frame (stays until stop)", _velocity),
    CommandSpec("stop", "", "stop the car (the zero velocity frame)", lambda s, a: s.stop()),
    CommandSpec(
        "send",
        "TOKEN...",
        "send frames as `send --uart2` takes them, or raw hex",
        lambda s, a: s.send_tokens(a),
    ),
)


def _degrees(args: list[str], usage: str) -> float:
    try:
        degrees = float(args[0]) if len(args) == 1 else float("nan")
    except ValueError:
        degrees = float("nan")
    if not abs(degrees) <= control.U16 / 10:
        raise AppmodeError(usage)
    return degrees


KEYS_HELP = (
    "arrows, q w e / a s d / z x c drive · , . turn · space stop · l latch\n"
    "r R rotate · + - speed · p settings · : command · ? help · Ctrl-Q quit"
)
"""The console's keys, as its panel and help show them."""
KEYS = {
    "r": "rotate",
    "R": "rotate -",
    "p": "settings",
    **SPEED_KEYS,
}
"""Keys that run a command line."""
