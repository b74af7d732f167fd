"""`wait:SECONDS`, a token of `send` on either port and a step of a script."""

from __future__ import annotations

from dataclasses import dataclass

from appmode.errors import AppmodeError


@dataclass(frozen=True, slots=True)
class Wait:
    seconds: float


def parse_wait(token: str) -> Wait:
    """`wait:SECONDS` (0 to an hour), in ASCII digits (float() also takes others)."""
    try:
        seconds = float(token[5:]) if token.isascii() else -1.0
    except ValueError:
        seconds = -1.0
    if not 0 <= seconds <= 3600:
        raise AppmodeError(f"token {token!r}: wait takes seconds, e.g. wait:0.5")
    return Wait(seconds)
