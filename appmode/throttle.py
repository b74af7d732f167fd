"""One line of a kind every so often: a flood of complaints (bad requests, a viewer's
bad messages) says one line, and how many were left out, not one each."""

from __future__ import annotations

import math
import time

LOG_EVERY = 10.0
"""Seconds between two log lines of one kind (a flood of bad requests logs one)."""


class Throttle:
    """One log line of a kind every LOG_EVERY seconds; how many were left out between."""

    def __init__(self, every: float = LOG_EVERY) -> None:
        self.every = every
        self._last: dict[str, float] = {}
        self._left_out: dict[str, int] = {}

    def allow(self, kind: str) -> int | None:
        """None to leave this line out; else how many of its kind were left out."""
        now = time.monotonic()
        if now - self._last.get(kind, -math.inf) < self.every:
            self._left_out[kind] = self._left_out.get(kind, 0) + 1
            return None
        self._last[kind] = now
        return self._left_out.pop(kind, 0)
