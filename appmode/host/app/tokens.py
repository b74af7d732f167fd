"""Command-line tokens for `appmode send`: letters, frames, escaped bytes and waits."""

from __future__ import annotations

from appmode.errors import AppmodeError
from appmode.host.token_help import APP_TOKENS as HELP
from appmode.host.waits import Wait, parse_wait
from appmode.protocol import app, app_decoders
from appmode.protocol.directions import LETTERS, PAGE_LETTERS, STOP_LETTER
from appmode.protocol.escaping import unescape

SINGLE = LETTERS + "".join(PAGE_LETTERS) + STOP_LETTER


def parse_token(token: str, raw: bool = False) -> bytes | Wait:
    """The bytes a token sends, or a Wait; AppmodeError names the token and the fix.

    Frames are checked as the board would decode them, unless `raw` is set.
    """
    if token.startswith("wait:"):
        return parse_wait(token)
    try:
        data = unescape(token)
    except ValueError as exc:
        raise AppmodeError(f"token {token!r}: {exc}") from None
    if raw:
        return data
    if token.startswith("{"):
        events = app_decoders.HostDecoder().feed(data)
        if len(events) != 1 or len(events[0].raw) != len(data):
            raise AppmodeError(f"token {token!r} is not one frame; {HELP}")
        event = events[0]
        if isinstance(event, app.BadFrame):
            raise AppmodeError(f"token {token!r}: {event.reason} (--raw sends it anyway)")
        return data
    if "\\" in token or (token and all(c in SINGLE for c in token)):
        return data
    raise AppmodeError(f"token {token!r} is not understood: {HELP}")
