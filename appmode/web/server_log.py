"""The web server's own complaints (a handler that failed, a malformed request, an
accept error while open files run out), one line each on stderr, and one of a kind
every LOG_EVERY seconds: a flood of bad requests logs one line, not a traceback each."""

from __future__ import annotations

import asyncio
import logging
import sys
from typing import Any

from appmode.throttle import Throttle

_throttle = Throttle()


def _say_throttled(kind: str, text: str) -> None:
    left_out = _throttle.allow(kind)
    if left_out is not None:
        more = f" ({left_out:,} more like it left out)" if left_out else ""
        print(f"appmode web: {text}{more}", file=sys.stderr)


def one_line(loop: asyncio.AbstractEventLoop, context: dict[str, Any]) -> None:
    """What the event loop would print with a traceback, in a line (a flood, once per
    LOG_EVERY seconds: accept errors while open files run out)."""
    error = context.get("exception")
    message = str(context.get("message"))
    _say_throttled(message, f"{message}{f': {error!r}' if error else ''}")


class OneLine(logging.Handler):
    """The server's own complaints (a handler that failed, a malformed request), one line
    each, and one of a kind every LOG_EVERY seconds."""

    def emit(self, record: logging.LogRecord) -> None:
        text = record.getMessage()
        if record.exc_info and record.exc_info[1] is not None:
            text += f": {record.exc_info[1]!r}"
        _say_throttled(f"{record.name} {record.msg}", text)
