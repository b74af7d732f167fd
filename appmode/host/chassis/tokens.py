"""Command-line tokens for `appmode send --chassis`: a velocity in SI, the stop, waits and
raw hex."""

from __future__ import annotations

import math

from appmode.errors import AppmodeError
from appmode.host.token_help import CHASSIS_TOKENS as HELP
from appmode.host.waits import Wait, parse_wait
from appmode.protocol.twist import BadTwist, Twist

Token = Twist | Wait | bytes


def parse_token(token: str) -> Token:
    """A Twist (`stop`: the still one), a Wait or raw bytes; AppmodeError names the token
    and the fix."""
    if token.startswith("wait:"):
        return parse_wait(token)
    word, sep, rest = token.partition(":")
    if word.lower() == "stop" and not sep:
        return Twist()
    if word.lower() == "velocity" and sep:
        return _twist(token, rest)
    text = token.replace(" ", "").replace(",", "")
    try:
        data = bytes.fromhex(text) if not sep else b""
    except ValueError:
        data = b""
    if not data:
        raise AppmodeError(f"token {token!r} is not understood: {HELP}")
    return data


def _twist(token: str, text: str) -> Twist:
    parts = text.split(",")
    try:
        numbers = [float(part) for part in parts] if text.isascii() else []
    except ValueError:
        numbers = []
    if not 1 <= len(numbers) <= 3 or not all(math.isfinite(n) for n in numbers):
        raise AppmodeError(
            f"token {token!r}: velocity takes FORWARD[,LEFT[,TURN]] in m/s and rad/s, e.g. "
            "velocity:0.3,0,0.5"
        )
    try:
        return Twist.checked(*numbers, *[0.0] * (3 - len(numbers)))
    except BadTwist as exc:
        raise AppmodeError(f"token {token!r}: {exc}") from None
