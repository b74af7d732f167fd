"""A one-way serial line, with no I/O: bytes go in at a time and come out paced.

At `baud` with 10 bits a byte (8N1), a byte pushed at time t is delivered when its
stop bit is done. Deadlines are computed from each burst's start (`start + (i+1) * byte
time`), never by adding a sleep per byte, so rounding errors do not accumulate. With
no baud the line is instantaneous.
"""

from __future__ import annotations

from collections import deque

BITS_PER_BYTE = 10


def byte_time(baud: int | None) -> float:
    """Seconds one byte takes on the wire; 0 for an unpaced line."""
    return BITS_PER_BYTE / baud if baud else 0.0


class Ahead:
    """A writer's side of a line of `baud`: how long to wait before handing the OS more,
    so that it never holds more than `limit` bytes the wire has not carried. What an OS
    holds reaches the other end before anything written after it — a stop, say."""

    def __init__(self, baud: int | None, limit: int) -> None:
        self.byte_time = byte_time(baud)
        self.limit = limit
        self._free_at = float("-inf")  # when the wire will have carried what was written

    def delay(self, now: float) -> float:
        """Seconds to wait, from `now`, before writing more."""
        return max(0.0, self._free_at - now - self.limit * self.byte_time)

    def wrote(self, size: int, now: float) -> None:
        self._free_at = max(self._free_at, now) + size * self.byte_time


class Line:
    """Bytes pushed at a time, delivered at the line's rate, in order."""

    def __init__(self, baud: int | None) -> None:
        self.baud = baud
        self.byte_time = byte_time(baud)
        self.bursts: deque[tuple[float, bytes]] = deque()
        """(first byte's start, data) of each burst not wholly delivered: to be read only.
        Truthy while the line carries bytes, as `len` is, and cheaper to test (a served
        board tests its lines on every pass)."""
        self._taken = 0  # bytes of the first burst already delivered
        self._queued = 0  # bytes of every burst, the first's delivered ones included
        self._free_at = float("-inf")

    def __len__(self) -> int:
        return self._queued - self._taken

    def push(self, data: bytes, now: float) -> None:
        """Queue `data`, sent from `now` or when the line is free, whichever is later."""
        if not data:
            return
        start = max(now, self._free_at)
        self.bursts.append((start, bytes(data)))
        self._queued += len(data)
        self._free_at = start + len(data) * self.byte_time

    def next_due(self) -> float | None:
        """When the next byte is delivered, or None when the line is idle."""
        if not self.bursts:
            return None
        start, _ = self.bursts[0]
        return start + (self._taken + 1) * self.byte_time

    def last_due(self) -> float | None:
        """When the last byte queued is delivered, or None when the line is idle."""
        return self._free_at if self.bursts else None

    def take(self, now: float) -> bytes:
        """Every byte delivered by `now`."""
        bursts, step = self.bursts, self.byte_time
        if len(bursts) == 1 and step:  # the usual case on a paced line: one burst
            start, data = bursts[0]
            size, taken = len(data), self._taken
            due = int((now - start) / step + 1e-9)
            if due < size:
                if due <= taken:
                    return b""
                self._taken = due
                return data[taken:due]
            bursts.popleft()
            self._queued -= size
            self._taken = 0
            return data[taken:]
        spans = self._delivered(now)
        if len(spans) == 1:  # the usual case: part of one burst
            _, data, first, end = spans[0]
            return data[first:end]
        return b"".join(data[first:end] for _, data, first, end in spans)

    def take_timed(self, now: float) -> list[tuple[float, bytes]]:
        """Bytes delivered by `now`, each run with its delivery time.

        On a paced line a run is one byte; on an instantaneous line, one burst.
        """
        step = self.byte_time
        spans = self._delivered(now)
        if step == 0.0:
            return [(start, data[first:end]) for start, data, first, end in spans]
        return [
            (start + (i + 1) * step, data[i : i + 1])
            for start, data, first, end in spans
            for i in range(first, end)
        ]

    def _delivered(self, now: float) -> list[tuple[float, bytes, int, int]]:
        """The bytes delivered by `now`, as (burst start, burst, first, end) spans; the
        line lets go of them."""
        out: list[tuple[float, bytes, int, int]] = []
        step = self.byte_time
        while self.bursts:
            start, data = self.bursts[0]
            if step == 0.0:
                if start > now:
                    break
                due = len(data)
            else:
                due = min(len(data), int((now - start) / step + 1e-9))
            if due > self._taken:
                out.append((start, data, self._taken, due))
            if due < len(data):
                self._taken = max(self._taken, due)
                break
            self.bursts.popleft()
            self._queued -= len(data)
            self._taken = 0
        return out
