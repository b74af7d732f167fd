"""A driving session and the pages that show it: one page drives, the others watch.

What a page sends is checked here and goes through the session's own code — a touch on
the pad is the session's `press`, as a key in the terminal is. A held direction stays
only while the page's heartbeats come: the session's hold-to-drive runs with HEARTBEAT
as both its timeouts, so a page that goes quiet (a dropped network, a frozen or crashed
browser) stops the car within that time.
"""

from __future__ import annotations

import json
import time
from typing import Any

from appmode.session.base import BaseSession, Quit, ShowHelp, ShowStatus
from appmode.session.hold import HoldToDrive

HEARTBEAT = 0.25
"""Seconds a held direction lasts without a heartbeat from its page."""
CELLS = {
    "front-left": (0, 0),
    "forward": (0, 1),
    "front-right": (0, 2),
    "left": (1, 0),
    "stop": (1, 1),
    "right": (1, 2),
    "rear-left": (2, 0),
    "backward": (2, 1),
    "rear-right": (2, 2),
}
"""The pad's cells by their accessible names: row 0 is the front."""
MAX_MESSAGE = 1024
"""Longest message a page may send, in bytes."""
RATE = 60.0
"""Messages a second a page may send on average (bursts of up to BURST)."""
BURST = 120.0
MESSAGES = 50
"""Messages of the session sent to a page."""
MAX_LINE = 200
"""Longest command line a page may send."""


def driving() -> HoldToDrive:
    """Hold-to-drive for a page: a direction lasts HEARTBEAT after its last heartbeat."""
    return HoldToDrive(first_timeout=HEARTBEAT, repeat_timeout=HEARTBEAT)


class Bucket:
    """A page's allowance of messages: RATE a second, BURST at once."""

    def __init__(self) -> None:
        self.level = BURST
        self.at = time.monotonic()

    def take(self) -> bool:
        now = time.monotonic()
        self.level = min(BURST, self.level + (now - self.at) * RATE)
        self.at = now
        if self.level < 1:
            return False
        self.level -= 1
        return True


class Bridge:
    """The session, its pages (any hashable object stands for one), and which drives."""

    def __init__(self, session: BaseSession) -> None:
        self.session = session
        self.driver: object | None = None
        self.pages: dict[object, Bucket] = {}

    def join(self, page: object) -> None:
        """A page opened: it drives if none does, else it watches."""
        self.pages[page] = Bucket()
        if self.driver is None:
            self.driver = page

    def leave(self, page: object) -> None:
        """A page closed (or lost its connection): if it drove, the car stops."""
        self.pages.pop(page, None)
        if page is self.driver:
            self.driver = None
            self.session.stop()

    def role(self, page: object) -> str:
        return "driver" if page is self.driver else "watcher"

    def handle(self, page: object, text: str | bytes) -> dict[str, Any] | None:
        """One message from a page; what to answer it (an error), or None."""
        bucket = self.pages.get(page)
        if bucket is None:
            return {"t": "error", "text": "this page is not connected"}
        if not bucket.take():
            return {"t": "error", "text": "too many messages: slow down"}
        if len(text) > MAX_MESSAGE:
            return {"t": "error", "text": f"message over {MAX_MESSAGE} bytes: ignored"}
        try:
            message = json.loads(text)
        except (ValueError, UnicodeDecodeError):
            return {"t": "error", "text": "not JSON: ignored"}
        kind = message.get("t") if isinstance(message, dict) else None
        if kind == "take":
            return self._take(page)
        if kind not in ("press", "hold", "release", "stop", "command"):
            return {"t": "error", "text": f"unknown message {kind!r}: ignored"}
        if page is not self.driver:
            return {"t": "error", "text": "this page watches: take over to drive"}
        if kind in ("press", "hold"):
            cell = CELLS.get(message.get("key")) if isinstance(message.get("key"), str) else None
            if cell is None:
                return {"t": "error", "text": f"no pad cell {message.get('key')!r}"}
            self.session.press(self.session.grid_key(*cell))
        elif kind in ("release", "stop"):
            self.session.stop()
        else:
            return self._command(message.get("line"))
        return None

    def _take(self, page: object) -> dict[str, Any] | None:
        """A watcher takes over: the car stops first, and the page that drove sees it
        now watches (in its next status)."""
        if page is not self.driver:
            self.session.stop()
            self.driver = page
            self.session.say("another page took over driving")
        return None

    def _command(self, line: object) -> dict[str, Any] | None:
        if not isinstance(line, str) or len(line) > MAX_LINE:
            return {"t": "error", "text": f"a command is text of at most {MAX_LINE} characters"}
        try:
            step = self.session.run(line)
        except Quit:
            return {"t": "error", "text": "close the page to leave; the car stops"}
        if isinstance(step, ShowHelp):
            for text in self.session.help_lines():
                self.session.say(text)
        elif isinstance(step, ShowStatus) or step is not None:
            return {"t": "error", "text": "that command is for the terminal"}
        return None

    def status(self, page: object) -> dict[str, Any]:
        """What a page shows now."""
        session = self.session
        rows = [
            {"label": row.label, "spans": [list(span) for span in row.spans], "pairs": row.pairs}
            for row in session.status_rows()
        ]
        return {
            "t": "status",
            "title": session.title,
            "simulated": session.simulated,
            "url": session.url,
            "role": self.role(page),
            "pages": len(self.pages),
            "rows": rows,
            "grid": session.grid_cells(),
            "lit": session.lit_cell(),
            "messages": list(session.messages)[-MESSAGES:],
        }
