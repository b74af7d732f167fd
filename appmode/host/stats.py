"""A link's counters, on either port: bytes, records, errors, and how fresh they are."""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field

RATE_WINDOW = 2.0
DEGRADED_WINDOW = 5.0


@dataclass(slots=True)
class LinkStats:
    """Counters of one host session."""

    bytes_in: int = 0
    bytes_out: int = 0
    records: int = 0
    errors: int = 0
    discarded: int = 0
    skipped: int = 0
    """Bytes before the first record of a link that start no record (the end of one
    caught half way, a board's start-up text): not errors."""
    last_record: float | None = None
    _recent: deque[float] = field(default_factory=deque)
    _error_times: deque[float] = field(default_factory=deque)

    def rate(self, now: float) -> float:
        """Records a second over the last RATE_WINDOW seconds."""
        self._expire(now)
        return len(self._recent) / RATE_WINDOW

    def recent_errors(self, now: float) -> int:
        """Errors in the last DEGRADED_WINDOW seconds: the link is degraded while > 0."""
        while self._error_times and self._error_times[0] <= now - DEGRADED_WINDOW:
            self._error_times.popleft()
        return len(self._error_times)

    def count_error(self, now: float, size: int) -> None:
        self.errors += 1
        self.discarded += size
        self._error_times.append(now)
        self.recent_errors(now)

    def since_last(self, now: float) -> float | None:
        return None if self.last_record is None else now - self.last_record

    def count_record(self, now: float) -> None:
        self.records += 1
        self.last_record = now
        self._recent.append(now)
        self._expire(now)

    def _expire(self, now: float) -> None:
        while self._recent and self._recent[0] <= now - RATE_WINDOW:
            self._recent.popleft()
