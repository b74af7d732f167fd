"""A driving session and the pages that show it: one page drives, the others watch.

What a page sends is checked here and goes through the session's own code — a touch on
the pad is the session's `press`, as a key in the terminal is. Any motion lasts only
while the driving page proves it is alive: it sends a heartbeat (`alive`) every 100 ms,
and the session's lease (`BaseSession.lease`) is HEARTBEAT, whatever started the motion
(the pad, a latch, the command line, the stick, a turn); a held direction also needs
its repeats (hold-to-drive with HEARTBEAT as both timeouts). A page that goes quiet (a
dropped network, a frozen renderer or browser) stops the car within that time.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from typing import Any

from appmode.errors import AppmodeError
from appmode.host.app.state import TRACE_SECONDS, HostState
from appmode.session.base import BaseSession
from appmode.session.command_line import Quit, ShowHelp, ShowStatus
from appmode.session.hold import HoldToDrive

HEARTBEAT = 0.25
"""Seconds a held direction lasts without a heartbeat from its page."""
MAX_MESSAGE = 1024
"""Longest message a page may send, in bytes."""
RATE = 60.0
"""Messages a second a page may send on average (bursts of up to BURST)."""
BURST = 120.0
MESSAGES = 50
"""Messages of the session sent to a page."""
MAX_LINE = 200
"""Longest command line a page may send."""
WATCHERS_MAY = ("alive", "take", "waves")
"""What a watching page may send: the rest drives."""
Handler = Callable[[object, dict[str, Any]], "dict[str, Any] | None"]


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
        session.lease = HEARTBEAT
        session.names_files = False  # a page names no file on this machine
        self.driver: object | None = None
        self.pages: dict[object, Bucket] = {}
        self.waves: set[object] = set()
        """Pages that draw waveforms: their status carries the traces."""
        self._handlers: dict[str, Handler] = {
            "alive": self._alive,
            "take": self._take,
            "waves": self._waves,
            "press": self._press,
            "hold": self._press,
            "stick": self._stick,
            "release": self._stop,
            "stop": self._stop,
            "command": self._command,
        }
        """What each kind of message (`messages.PAGE`) does."""

    def join(self, page: object) -> None:
        """A page opened: it drives if none does, else it watches."""
        self.pages[page] = Bucket()
        if self.driver is None:
            self.driver = page
            self.session.keepalive()

    def leave(self, page: object) -> None:
        """A page closed (or lost its connection): if it drove, the car stops."""
        self.pages.pop(page, None)
        self.waves.discard(page)
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
            if page is self.driver and self.session.driving.current is not None:
                self.session.stop()  # a page that floods loses the car: stopped, once
            return {"t": "error", "text": "too many messages: slow down (the car is stopped)"}
        if page is self.driver:
            self.session.keepalive()  # any message proves the driving page alive
        if len(text) > MAX_MESSAGE:
            return {"t": "error", "text": f"message over {MAX_MESSAGE} bytes: ignored"}
        try:
            message = json.loads(text)
        except (ValueError, UnicodeDecodeError):
            return {"t": "error", "text": "not JSON: ignored"}
        kind = message.get("t") if isinstance(message, dict) else None
        handler = self._handlers.get(kind) if isinstance(kind, str) else None
        if handler is None:
            return {"t": "error", "text": f"unknown message {kind!r}: ignored"}
        if kind not in WATCHERS_MAY and page is not self.driver:
            return {"t": "error", "text": "this page watches: take over to drive"}
        return handler(page, message)

    def _alive(self, page: object, message: dict[str, Any]) -> None:
        return None  # any message proves the driving page alive (above)

    def _waves(self, page: object, message: dict[str, Any]) -> None:
        (self.waves.add if message.get("on") is True else self.waves.discard)(page)

    def _press(self, page: object, message: dict[str, Any]) -> dict[str, Any] | None:
        key = self._key(message.get("key"))
        if key is None:
            return {"t": "error", "text": f"no key {message.get('key')!r} here"}
        self.session.press(key)
        return None

    def _stop(self, page: object, message: dict[str, Any]) -> None:
        self.session.stop()

    def _key(self, name: object) -> str | None:
        """What the session's `press` takes for a key the page names: a cell of the grid
        by what it does (`forward`, `rotate-cw` on the button page), or a driving key
        besides the grid."""
        session = self.session
        for r, row in enumerate(session.cell_names()):
            for c, cell in enumerate(row):
                if cell == name:
                    return session.grid_key(r, c)
        return name if isinstance(name, str) and name in session.hold_keys.values() else None

    def _stick(self, page: object, message: dict[str, Any]) -> dict[str, Any] | None:
        """An analog stick's position, each axis −1…1 (repeated while it is held)."""
        x, y = message.get("x"), message.get("y")
        if not (_unit(x) and _unit(y)):
            return {"t": "error", "text": "a stick's x and y are numbers in −1…1"}
        assert isinstance(x, (int, float)) and isinstance(y, (int, float))
        try:
            self.session.steer(round(float(x), 2), round(float(y), 2))
        except AppmodeError as exc:
            return {"t": "error", "text": str(exc)}
        return None

    def _take(self, page: object, message: dict[str, Any]) -> None:
        """A watcher takes over: the car stops first, and the page that drove sees it
        now watches (in its next status)."""
        if page is not self.driver:
            self.session.stop()
            self.driver = page
            self.session.keepalive()
            self.session.say("another page took over driving")

    def _command(self, page: object, message: dict[str, Any]) -> dict[str, Any] | None:
        line = message.get("line")
        if not isinstance(line, str) or len(line) > MAX_LINE:
            return {"t": "error", "text": f"a command is text of at most {MAX_LINE} characters"}
        try:
            step = self.session.run(line)
        except Quit:
            return {"t": "error", "text": "close the page to leave; the car stops"}
        if isinstance(step, ShowHelp):
            for text in self.session.help_lines:
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
            "instruments": _plain(session.instruments()),
            "cells": session.cell_names(),
            "extra": list(session.hold_keys.values()),
            "lit": session.lit_cell(),
            "commands": [spec.name for spec in session.commands],
            "traces": _traces(session.telemetry_state(), session.now())
            if page in self.waves
            else None,
            "messages": list(session.messages)[-MESSAGES:],
        }


def _traces(state: HostState | None, now: float) -> dict[str, Any] | None:
    """The last TRACE_SECONDS of A and B records, for waveforms: each series's label and
    its points (seconds before now, value)."""
    if state is None:
        return None
    velocity = [(now - t, v.values) for t, v in state.velocities.points]
    attitude = [(now - t, a.values) for t, a in state.attitudes.points]
    labels, units = state.layout.labels, [f.unit for f in state.layout.a_fields]
    series = [
        {
            "label": labels[i],
            "unit": units[i],
            "points": [[round(ago, 3), values[i]] for ago, values in velocity],
        }
        for i in state.layout.motion
    ]
    series += [
        {
            "label": field.label,
            "unit": field.unit,
            "points": [[round(ago, 3), values[i]] for ago, values in attitude if i < len(values)],
        }
        for i, field in enumerate(state.layout.b_fields)
    ]
    return {"seconds": TRACE_SECONDS, "series": series}


def _plain(value: Any) -> Any:
    """A dataclass of the session's view as JSON's values, floats to 2 places (ages and
    rates need no more on a page); a dataclass's fields are its `__match_args__` (five
    times as fast as `dataclasses.asdict`, and this runs ten times a second a page)."""
    kind = type(value)
    if kind is float:
        return round(value, 2)
    if kind in (int, str, bool) or value is None:
        return value
    if kind in (list, tuple):
        return [_plain(item) for item in value]
    return {name: _plain(getattr(value, name)) for name in kind.__match_args__}


def _unit(value: object) -> bool:
    """A number in −1…1 (not a bool, not NaN)."""
    return isinstance(value, (int, float)) and not isinstance(value, bool) and -1 <= value <= 1
