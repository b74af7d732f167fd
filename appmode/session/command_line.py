"""The command line every session shares: what a command is (`CommandSpec`), the
commands common to both ports (help, latch, record, wait, status, quit), and what a
command asks of the view (`Quit`, `SHOW_STATUS`, `SHOW_HELP`, a `Wait`)."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Generic, TypeVar

from appmode.errors import AppmodeError
from appmode.files import new_recording, recordings_folder
from appmode.host.app.tokens import parse_token
from appmode.host.waits import Wait
from appmode.protocol.formats import TEXT
from appmode.protocol.twist import BadTwist, Twist
from appmode.session.hold import TYPED_TWIST
from appmode.text import wrapped

if TYPE_CHECKING:
    from appmode.session.base import BaseSession

SPEED_STEP = 100
SPEED_KEYS = {"+": f"speed +{SPEED_STEP}", "=": f"speed +{SPEED_STEP}", "-": f"speed -{SPEED_STEP}"}
"""The keys that change the speed, as command lines."""
SPEED_COMPLETES = {f"+{SPEED_STEP}": None, f"-{SPEED_STEP}": None}
LOG = 500
"""Messages kept for scrolling back."""
QUIT_WORDS = ("quit", "exit", "q")
MAX_COMMAND = 1000
"""Characters a command line may have (splitting one into words takes time that grows
as the square of its length: a megabyte pasted or piped in would hang the session)."""
ON_OFF = {"on": None, "off": None}


class Quit(Exception):
    """The user asked to leave."""


class ShowStatus:
    """`status` was asked for: the view prints the panel (script mode)."""


SHOW_STATUS = ShowStatus()


class ShowHelp:
    """`help` was asked for: the view shows `help_lines`."""


SHOW_HELP = ShowHelp()

Step = Wait | ShowStatus | ShowHelp | None
S = TypeVar("S", bound="BaseSession")


@dataclass(frozen=True, slots=True)
class CommandSpec(Generic[S]):
    """A command of the command line: its name, its arguments and help as `help` lists
    them, what runs it, and what completes after its name."""

    name: str
    args: str
    help: str
    run: Callable[[S, list[str]], Step]
    """Runs it on a session with its arguments; AppmodeError or ValueError for a mistake."""
    completes: Mapping[str, object] | None = None


def _latch(session: BaseSession, args: list[str]) -> None:
    if args not in (["on"], ["off"]):
        raise AppmodeError("usage: latch on|off")
    session.driving.latched = args[0] == "on"
    session.say(f"latched driving {args[0]}")


def _record(session: BaseSession, args: list[str]) -> None:
    if args == ["stop"]:
        session.stop_recording()
    elif session.names_files:
        if len(args) != 1:
            raise AppmodeError("usage: record FILE, or record stop")
        session.start_recording(args[0])
    elif args in ([], ["start"]):
        session.start_recording(str(new_recording(TEXT.suffix)))
    else:
        raise AppmodeError(
            f"the page names no file: 'record' starts a recording in {recordings_folder()} "
            "under a new name, 'record stop' ends it"
        )


def _twist(session: BaseSession, args: list[str]) -> None:
    """`twist F [L [T]]`: m/s forward, m/s to the left, rad/s counter-clockwise."""
    numbers = [_number(arg) for arg in args]
    if not 1 <= len(args) <= 3 or None in numbers:
        raise AppmodeError(
            "usage: twist F [L [T]]: m/s forward, m/s to the left, rad/s "
            "counter-clockwise, e.g. twist 0.3 or twist 0 0 0.5"
        )
    try:
        forward, left, turn = [n or 0.0 for n in numbers] + [0.0] * (3 - len(numbers))
        twist = Twist.checked(forward, left, turn)
    except BadTwist as exc:
        raise AppmodeError(str(exc)) from None
    session.move(twist, TYPED_TWIST)
    session.say(f"twist {twist}")


def _number(text: str) -> float | None:
    """`text` as a number written in ASCII (`0.3`, `-1e-1`), or None."""
    try:
        return float(text) if text.isascii() and len(text) <= 40 else None
    except ValueError:
        return None


def _wait(session: BaseSession, args: list[str]) -> Wait:
    step = parse_token(f"wait:{args[0]}" if len(args) == 1 else "wait:")
    assert isinstance(step, Wait)
    return step


def _quit(session: BaseSession, args: list[str]) -> None:
    raise Quit


COMMON: tuple[CommandSpec[BaseSession], ...] = (
    CommandSpec("latch", "on|off", "latched driving: a direction stays until stop", _latch, ON_OFF),
    CommandSpec(
        "record", "FILE|stop", "start or stop recording a transcript", _record, {"stop": None}
    ),
    CommandSpec("wait", "SECONDS", "script mode: let time pass", _wait),
    CommandSpec("status", "", "print the status panel (script mode)", lambda s, a: SHOW_STATUS),
    CommandSpec("help", "", "list the commands and keys", lambda s, a: SHOW_HELP),
    CommandSpec("quit", "", "stop the car and leave (Ctrl-Q; Ctrl-C at once)", _quit),
    CommandSpec(
        "twist", "F [L [T]]", "drive in SI: F, L m/s forward, left; T rad/s to the left", _twist
    ),
)
"""The commands every session takes, listed after its own."""
COMMON_ALIASES = {"?": "help", **{word: "quit" for word in QUIT_WORDS}}


def help_lines(specs: tuple[CommandSpec[Any], ...], keys_help: str) -> list[str]:
    """The commands, a line each, then the keys."""
    usages = [f"{spec.name} {spec.args}".strip() for spec in specs]
    width = max(map(len, usages)) + 2
    lines = [
        wrapped(usage.ljust(width) + spec.help, indent=" " * width)
        for usage, spec in zip(usages, specs, strict=True)
    ]
    return [*lines, "", *keys_help.splitlines(), "PgUp/PgDn scroll the messages · End: the newest"]
