"""The APP port's session commands: each one's name, arguments, help, what runs it and
what completes after it."""

from __future__ import annotations

from typing import TYPE_CHECKING

from appmode.errors import AppmodeError
from appmode.protocol import param_values, params
from appmode.session.command_line import SPEED_COMPLETES, SPEED_KEYS, SPEED_STEP, CommandSpec

if TYPE_CHECKING:
    from appmode.session.app.session import AppSession

PAGE_WORDS = {"direction": "J", "joystick": "J", "gravity": "I", "button": "K"}


def _set(session: AppSession, args: list[str]) -> None:
    """`set NAME VALUE`, in the user's units of the profile (`set balance_kp 0.42`)."""
    specs = session.specs
    if len(args) != 2:
        first = specs[0]
        example = f"{first.name} {param_values.to_user(first, first.default)}"
        raise AppmodeError(f"usage: set NAME VALUE, e.g. set {example}")
    session.set_parameter(args[0], args[1])


def _drive(session: AppSession, args: list[str]) -> None:
    if len(args) != 1 or args[0].upper() not in "ABCDEFGH" or len(args[0]) != 1:
        raise AppmodeError("usage: drive LETTER, one of A-H")
    session.press(args[0].upper())


def _page(session: AppSession, args: list[str]) -> None:
    if len(args) != 1 or args[0].lower() not in PAGE_WORDS:
        raise AppmodeError("usage: page direction|button|gravity|joystick")
    session.switch_page(PAGE_WORDS[args[0].lower()])


COMMANDS: tuple[CommandSpec[AppSession], ...] = (
    CommandSpec("params", "", "read the nine parameters", lambda s, a: s.read_params()),
    CommandSpec(
        "set",
        "NAME VALUE",
        "set a parameter, verified by reading back",
        _set,
        {p.name: None for p in params.PARAMS},
    ),
    CommandSpec(
        "save", "", "save the parameters to the board's flash ({Q:W})", lambda s, a: s.save()
    ),
    CommandSpec(
        "speed",
        "+N|-N|N",
        f"change max_speed (keys + and - step {SPEED_STEP})",
        lambda s, a: s.speed_command(a),
        SPEED_COMPLETES,
    ),
    CommandSpec("drive", "A-H", "drive in a direction (latched: until stop)", _drive),
    CommandSpec("stop", "", "stop the car (Z)", lambda s, a: s.stop()),
    CommandSpec(
        "page",
        "NAME",
        "switch page: direction (J), button (K), gravity (I)",
        _page,
        dict.fromkeys(PAGE_WORDS),
    ),
    CommandSpec(
        "send",
        "TOKEN...",
        "send raw tokens: letters, {frames}, \\xNN",
        lambda s, a: s.send_tokens(a),
    ),
)


KEYS_HELP = (
    "arrows, q w e / a s d / z x c drive · space stop · i j k page · l latch\n"
    "+ - speed · p params · v waveforms · : command · ? help · Ctrl-Q quit"
)
"""The console's keys, as its panel and help show them."""
KEYS = {
    "i": "page gravity",
    "j": "page joystick",
    "k": "page button",
    "p": "params",
    **SPEED_KEYS,
}
"""Keys that run a command line."""
