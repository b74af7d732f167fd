"""Recording a session as a transcript (format v1, `protocol.transcript`) while it
happens: `Recorder`, a tap on both ports that writes one protocol unit a line."""

from __future__ import annotations

import itertools
import math
from collections import deque
from typing import Any, BinaryIO, Protocol, TextIO

from appmode.errors import AppmodeError
from appmode.protocol.escaping import escape
from appmode.protocol.reader import APP_EVENTS, Event, PortsReader
from appmode.protocol.transcript import (
    CHASSIS_DIRECTIONS,
    DIRECTIONS,
    HEADER,
    TIME_DIGITS,
    UART2_DIRECTIONS,
    uart2_payload,
)
from appmode.writer import CLOSE_WAIT, BoundedWriter, reason

HOLD = 0.5
"""Seconds a recorder waits for a unit to end before writing it as far as it goes (the
lines after it wait too: the file stays in time order)."""


class _Held:
    """One direction's bytes fed to its decoder and not yet in a unit, with the time each
    arrived, and how many of them a line already shows (a unit cut by other lines)."""

    def __init__(self) -> None:
        self.data = bytearray()
        self.times: deque[list[float | int]] = deque()  # [time, count] runs of `data`
        self.written = 0

    def add(self, data: bytes, time: float) -> None:
        self.data += data
        self.times.append([time, len(data)])

    def time_at(self, offset: int) -> float:
        """When the held byte at `offset` arrived."""
        for when, count in self.times:
            if offset < count:
                return float(when)
            offset -= int(count)
        return float(self.times[-1][0]) if self.times else 0.0

    def take(self, count: int) -> tuple[float, bytes]:
        """A unit of `count` bytes leaves: (the time of its first byte no line shows, those
        bytes)."""
        shown = min(self.written, count)
        rest = (self.time_at(shown), bytes(self.data[shown:count]))
        del self.data[:count]
        self.written -= shown
        while count and self.times:
            run = self.times[0]
            used = min(count, int(run[1]))
            run[1] = int(run[1]) - used
            count -= used
            if not run[1]:
                self.times.popleft()
        return rest

    def unshown(self) -> tuple[float, bytes]:
        """The bytes no line shows yet, from the time of the first; they are shown now."""
        rest = (self.time_at(self.written), bytes(self.data[self.written :]))
        self.written = len(self.data)
        return rest


class Lines(Protocol):
    """A recording's format: what its start, each unit and comment, and its end add
    (text for a transcript, bytes for MCAP: `mcap_format.McapLines`)."""

    def start(self, directives: tuple[str, ...]) -> str | bytes: ...

    def line(
        self, time: float, raw: bytes, direction: str, text: bool, event: Any = None
    ) -> str | bytes: ...

    def comment(self, time: float, text: str) -> str | bytes: ...

    def finish(self) -> str | bytes: ...


class TextLines:
    """A transcript, format v1: a line a unit."""

    def start(self, directives: tuple[str, ...]) -> str:
        return "".join([HEADER + "\n", *(f"@{d}\n" for d in directives)])

    def line(self, time: float, raw: bytes, direction: str, text: bool, event: Any = None) -> str:
        if direction in CHASSIS_DIRECTIONS:
            payload = raw.hex(" ").upper()
        else:
            payload = uart2_payload(raw, text) if direction in UART2_DIRECTIONS else escape(raw)
        return f"{time:.{TIME_DIGITS}f} {direction} {payload}\n"

    def comment(self, time: float, text: str) -> str:
        return f"# {text}\n"

    def finish(self) -> str:
        return ""


class Recorder:
    """Writes a session as it happens: each direction split into commands and records.

    Call it as a tap: `recorder(direction, time, data)` with `>` for host→board bytes and
    `<` for board→host bytes. Every line is flushed as it is written, and lines stay in
    time order: a unit still incomplete when another direction's bytes come (a frame
    whose end is still to come) is written as far as it goes, at its own time, and the
    rest when it ends. Each line carries the arrival time of its first byte.
    """

    def __init__(
        self,
        out: TextIO | BinaryIO | BoundedWriter,
        origin: float = 0.0,
        directives: tuple[str, ...] = (),
        name: str | None = None,
        closes: bool = False,
        lines: Lines | None = None,
    ) -> None:
        """`out`: a stream (written at once, and left open unless `closes`), or a bounded
        writer (written off the caller's thread, closed with the recorder); `lines`: the
        format (a transcript's text by default; a binary stream for MCAP's bytes)."""
        self._out = out
        self.name = name or str(getattr(out, "name", "the transcript"))
        self._failed = False
        self._closed = False
        self._closes = closes
        self._origin = origin
        self._reader = PortsReader()
        self._held = {direction: _Held() for direction in DIRECTIONS}
        self._lines: Lines = lines or TextLines()
        self._queue: list[tuple[float, int, bytes, str, bool, Event | None]] = []
        """Lines not yet written: time, order, bytes, direction, whether a UART2 line is
        APP text (§12) — as decoded, whatever the mode when it is written — and the
        event it decoded to (None: a unit written before it ended)."""
        self._order = itertools.count()  # keeps lines of one time in the order they came
        self._write(self._lines.start(directives))

    def __call__(self, direction: str, time: float, data: bytes) -> None:
        self._held[direction].add(data, time)
        self._units(self._reader.feed(direction, data))
        self._release(time)

    def note(self, text: str, time: float) -> None:
        """A comment line at `time`: what happened that no byte shows (the first comment
        of a transcript is its title)."""
        said = " ".join(text.split()).encode()
        self._queue.append((time, next(self._order), said, "#", False, None))
        self._release(time)

    def follow(self, system_mode: int, time: float) -> None:
        """Read UART2 as a board with this system_mode does (`PortsReader.follow`)."""
        self._units(self._reader.follow(system_mode))
        self._release(time)

    def _units(self, events: list[tuple[str, Event]]) -> None:
        for shown, event in events:
            when, raw = self._held[shown].take(len(event.raw))
            if raw:
                text = isinstance(event, APP_EVENTS)
                whole = event if raw == event.raw else None
                self._queue.append((when, next(self._order), raw, shown, text, whole))

    def _release(self, now: float) -> None:
        """Write, in time order, the lines that no incomplete unit came before; a unit
        incomplete for HOLD seconds is written as far as it goes."""
        first = math.inf
        for direction, held in self._held.items():
            if len(held.data) > held.written:
                start = held.time_at(held.written)
                if start <= now - HOLD:
                    when, raw = held.unshown()
                    text = self._reader.app_mode
                    self._queue.append((when, next(self._order), raw, direction, text, None))
                else:
                    first = min(first, start)
        self._queue.sort()
        ready = [line for line in self._queue if line[0] < first]
        del self._queue[: len(ready)]
        for when, _, raw, direction, text, event in ready:
            at = max(0.0, when - self._origin)
            if direction == "#":
                self._write(self._lines.comment(at, raw.decode()))
            else:
                self._write(self._lines.line(at, raw, direction, text, event))

    def _write(self, text: str | bytes) -> None:
        if not text:
            return
        if isinstance(self._out, BoundedWriter):
            data = text.encode("utf-8") if isinstance(text, str) else text
            if self._failed or not self._out.write(data):
                self._failed = True
                raise AppmodeError(f"cannot write transcript {self.name}: {self._out.failure}")
            return
        try:
            self._out.write(text)  # type: ignore[arg-type]  # the stream the format wants
            self._out.flush()
        except OSError as exc:
            self._failed = True
            raise AppmodeError(f"cannot write transcript {self.name}: {reason(exc)}") from None

    def close(self, wait: float = CLOSE_WAIT) -> None:
        """Write what the decoders still hold, and close the file (if it opened it),
        waiting at most `wait` seconds for its writer; AppmodeError if the recording is
        not whole. After a failed write it only closes the file: that failure was
        reported."""
        if self._closed:
            return
        self._closed = True
        failed_before, error = self._failed, None
        if not self._failed:
            try:
                self._units(self._reader.flush())
                self._release(math.inf)
                self._write(self._lines.finish())
            except AppmodeError as exc:
                error = exc
        if isinstance(self._out, BoundedWriter):
            if not self._out.close(wait) and not failed_before:
                raise AppmodeError(f"cannot write transcript {self.name}: {self._out.failure}")
            return
        if self._closes:
            try:
                self._out.close()
            except OSError as exc:
                said = f"cannot write transcript {self.name}: {reason(exc)}"
                error = error or AppmodeError(said)
        if error is not None:
            raise error
