"""Command-line tokens for `appmode send --uart2`: frames by name, raw hex and waits."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from appmode.errors import AppmodeError
from appmode.host.token_help import CONTROL_TOKENS as HELP
from appmode.host.waits import Wait, parse_wait
from appmode.protocol import control, params, settings

if TYPE_CHECKING:
    from appmode.host.control.client import ControlHost

WORDS = ("velocity", "rotate", "motors", "position", "read", "set")


@dataclass(frozen=True, slots=True)
class Step:
    """A named step; `values` are checked for their drive type when sent."""

    kind: str
    values: tuple[int, ...] = ()
    name: str = ""


Token = Step | Wait | bytes


def parse_token(token: str) -> Token:
    """A Step, a Wait or raw bytes; AppmodeError names the token and the fix."""
    if token.startswith("wait:"):
        return parse_wait(token)
    word, sep, rest = token.partition(":")
    word = word.lower()
    if not sep:
        if word in settings.STORE_BY_NAME or word == "stop":
            return Step(word)
        return _hex(token)
    if word not in WORDS:
        raise AppmodeError(f"token {token!r} is not understood: {HELP}")
    if word == "read":
        try:
            return Step(word, name=settings.read_named(rest).name)
        except ValueError as exc:
            raise AppmodeError(f"token {token!r}: {exc}") from None
    if word == "set":
        setting, value = parse_setting(rest, f"token {token!r}")
        return Step(word, (value,), setting.name)
    if word == "rotate":
        try:
            degrees = float(rest)
        except ValueError:
            degrees = float("nan")
        if not abs(degrees) <= control.U16 / 10:
            raise AppmodeError(f"token {token!r}: rotate takes degrees, e.g. rotate:90")
        return Step(word, (round(degrees * 10),))
    values = _numbers(token, rest)
    counts = {"velocity": (2, 3), "motors": (3, 4), "position": (3,)}[word]
    if len(values) not in counts:
        raise AppmodeError(
            f"token {token!r}: {word} takes {' or '.join(map(str, counts))} numbers; {HELP}"
        )
    for each in values:
        if abs(each) > control.U16:
            raise AppmodeError(f"token {token!r}: {each} is beyond ±{control.U16}")
    return Step(word, values)


def parse_setting(text: str, where: str) -> tuple[settings.Setting, int]:
    """`NAME=VALUE` (or `ID=VALUE`), checked against the settings table; AppmodeError
    starts with `where` (the option or token it came from)."""
    name, sep, value = text.partition("=")
    if not sep:
        raise AppmodeError(f"{where}: expected NAME=VALUE, e.g. max_speed=800")
    try:
        setting = settings.lookup(name)
    except ValueError as exc:
        raise AppmodeError(f"{where}: {exc}") from None
    number = params.whole(value)
    if number is None:
        raise AppmodeError(f"{where}: {setting.name} takes a whole number in {setting.range_text}")
    error = settings.value_error(setting, number)
    if error is not None:
        raise AppmodeError(f"{where}: {error}")
    return setting, number


def _numbers(token: str, text: str) -> tuple[int, ...]:
    try:
        return tuple(int(part) for part in text.split(","))
    except ValueError:
        raise AppmodeError(f"token {token!r}: expected whole numbers; {HELP}") from None


def _hex(token: str) -> bytes:
    text = token.replace(" ", "").replace(",", "")
    try:
        data = bytes.fromhex(text)
    except ValueError:
        data = b""
    if not data:
        raise AppmodeError(f"token {token!r} is not understood: {HELP}")
    return data


def perform(host: ControlHost, step: Step | bytes) -> None:
    """Send one step (a rotation is only started; a read only sent)."""
    if isinstance(step, bytes):
        host.send(step)
        return
    kind, values = step.kind, step.values
    if kind == "velocity":
        if host.drive is params.DriveType.DIFF_GYRO:
            if len(values) != 2:
                raise AppmodeError("velocity: a diff-gyro car takes LEFT,RIGHT duties")
            host.velocity(left=values[0], right=values[1])
        elif len(values) != 3:
            raise AppmodeError(f"velocity: a {host.drive.cli_name} car takes X,Y,Z")
        else:
            host.velocity(*values)
    elif kind == "motors":
        host.motors(values)
    elif kind == "position":
        host.position(*values)
    elif kind == "read":
        host.send_frame(control.read(step.name))
    elif kind == "set":
        host.send_frame(control.setting(step.name, values[0]))
    elif kind == "rotate":
        host.start_rotation(values[0] / 10)
    elif kind == "stop":
        host.stop()
    else:
        host.store(kind)
