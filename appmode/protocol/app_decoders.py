"""The APP protocol's decoders, with no I/O (docs/protocol.md §2, §3).

`HostDecoder` turns the host→board stream into commands, `BoardDecoder` the board→host
stream into records. They never raise on bytes, hold a bounded buffer, resynchronise at
the next `{`, and give every byte they consume to exactly one event (its `raw`), so that
the events of a stream re-encode to exactly that stream. Their output does not depend on
how the stream is split into `feed` calls.
"""

from __future__ import annotations

import functools
from collections.abc import Callable

from appmode.patterns import deferred
from appmode.protocol import params
from appmode.protocol.app import (
    COLON,
    DOLLAR,
    LBRACE,
    MAX_FRAME,
    MAX_RECORD,
    MAX_RUN,
    Attitude,
    BadFrame,
    BoardEvent,
    ByteEvent,
    Garbage,
    HostEvent,
    Malformed,
    Move,
    Noise,
    OtherRecord,
    ParamsRecord,
    ReadParams,
    SaveParams,
    SetParam,
    Stop,
    SwitchPage,
    Velocity,
)
from appmode.protocol.bulk import linear
from appmode.protocol.directions import LETTERS, PAGE_LETTERS

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing: start-up stays short

# ---------------------------------------------------------------- host stream


@functools.cache
def single_byte_events() -> tuple[ByteEvent, ...]:
    """What each byte means outside a frame (§2.1), by value: built when a host stream is
    first decoded (start-up)."""
    table: list[ByteEvent] = []
    for value in range(256):
        raw = bytes([value])
        char = chr(value)
        event: ByteEvent
        if char in LETTERS:
            event = Move(LETTERS.index(char) + 1, raw=raw)
        elif 1 <= value <= 8:
            event = Move(value, numeric=True, raw=raw)
        elif char in PAGE_LETTERS:
            event = SwitchPage(char, raw=raw)
        elif char == "Z":
            event = Stop(raw=raw)
        else:
            event = Noise(raw)
        table.append(event)
    return tuple(table)


if TYPE_CHECKING:
    from typing import TypeVar

    E = TypeVar("E")
_BRACES = deferred(rb"\{{2,%d}" % (MAX_RUN + 1))


def _brace_run(
    buf: bytes, pos: int, hold: bool, out: list[E], event: Callable[[bytes, str], E], what: str
) -> int | None:
    """At a `{` followed by `{`: the run's braces, each an open frame or record the next
    `{` interrupted, reported as one `event(raw, reason)` up to MAX_RUN at a time (the
    run's last brace opens the next one). Where it stopped, or None to hold a run that
    more bytes may lengthen."""
    run = _BRACES.match(buf, pos)
    assert run is not None
    count = run.end() - pos - 1
    if count < MAX_RUN and run.end() == len(buf) and hold:
        return None
    out.append(event(buf[pos : pos + count], _interrupted(what, count)))
    return pos + count


def _opening(
    buf: bytes,
    pos: int,
    n: int,
    most: int,
    hold: bool,
    out: list[E],
    event: Callable[[bytes, str], E],
    what: str,
) -> tuple[int | None, int]:
    """At a `{`: a run of `{` (`_brace_run`), or a `{` that another interrupts within
    `most` bytes, reported as `event`s. Returns (where that left off: None to hold, -1
    when it was neither; where the `{`'s `}` is before `n` and within `most` bytes, or
    -1)."""
    if pos + 1 < n and buf[pos + 1] == LBRACE:
        return _brace_run(buf, pos, hold, out, event, what), -1
    limit = pos + most if pos + most < n else n  # min(), without the call
    close = buf.find(b"}", pos + 1, limit)
    reopen = buf.find(b"{", pos + 1, close if close >= 0 else limit)
    if reopen < 0:
        return -1, close
    out.append(event(buf[pos:reopen], _interrupted(what, 1)))
    return reopen, close


def _interrupted(what: str, count: int) -> str:
    return f"{what} interrupted by '{{'" if count == 1 else f"{count} {what}s interrupted by '{{'"


_FRAMES = deferred(rb"(\{[^{}]{0,%d}\})" % (MAX_FRAME - 2))
"""A whole frame of up to MAX_FRAME bytes: what the general way would read as one."""


@functools.lru_cache(maxsize=4096)
def _parse_frame(raw: bytes) -> HostEvent:
    """What one frame means; frames repeat (a host reads and sets the same few), and
    their events are immutable, so one is built once for each."""
    body = raw[1:-1]
    if len(body) == 3 and body[0] == 0x51 and body[2] in b"PW":  # Q?P / Q?W
        if body[2] == 0x50:
            return ReadParams(body[1], raw=raw)
        return SaveParams(body[1], raw=raw)
    if len(body) >= 2 and 0x30 <= body[0] <= 0x39 and body[1] == COLON:
        index, text = body[0] - 0x30, body[2:]
        if not text:
            return BadFrame(raw, f"set frame for parameter {index} has no value")
        if not text.isdigit():
            return BadFrame(raw, f"set frame value {text.decode('latin-1')!r} is not digits")
        error = params.value_error(index, int(text))
        if error is not None:
            return BadFrame(raw, error)
        return SetParam(index, int(text), raw=raw)
    return BadFrame(raw, "unknown frame")


class HostDecoder:
    """host→board bytes → commands (§2). A frame over 50 bytes is discarded whole."""

    LIMIT = max(MAX_FRAME, MAX_RUN)
    """Most bytes ever held between calls."""

    def __init__(self) -> None:
        self._buf = b""
        self._skip_len = 0  # bytes of an over-long frame already reported

    @property
    def buffered(self) -> int:
        return len(self._buf)

    @linear
    def feed(self, data: bytes) -> list[HostEvent]:
        buf = self._buf + data if self._buf else bytes(data)
        out: list[HostEvent] = []
        general, parse, single = self._general, _parse_frame, single_byte_events()
        pos = 0
        # split scans in C: [gap, frame, gap, frame, …, gap]; a gap of single bytes is
        # read here, others go the general way, the last one held where it may continue
        parts = iter(_FRAMES.split(buf))
        for gap, frame in zip(parts, parts, strict=False):  # pairs; the last gap left out
            if gap:
                if self._skip_len or LBRACE in gap:
                    pos = general(buf, pos, pos + len(gap), out)
                else:
                    out += [single[b] for b in gap]
                    pos += len(gap)
            self._skip_len = 0  # the frame's `{` ends an over-long frame's rest, if open
            out.append(parse(frame))
            pos += len(frame)
        pos = general(buf, pos, len(buf), out)
        self._buf = buf[pos:]
        return out

    def _general(self, buf: bytes, pos: int, end: int, out: list[HostEvent]) -> int:
        """Decode buf[pos:end], which holds no whole frame of up to MAX_FRAME bytes;
        at the end of `buf`, stop where more bytes could change the outcome. Returns
        where it stopped."""
        n, single = len(buf), single_byte_events()
        while pos < end:
            if self._skip_len:
                skipped = self._skip(buf, pos, n, out)
                if skipped is None:
                    break
                pos = skipped
                continue
            if buf[pos] != LBRACE:
                brace = buf.find(b"{", pos, end)
                stop = end if brace < 0 else brace
                out += [single[b] for b in buf[pos:stop]]  # each byte means one thing
                pos = stop
                continue
            after, close = _opening(buf, pos, n, MAX_FRAME, True, out, BadFrame, "frame")
            if after is None:
                break
            if after >= 0:
                pos = after
            elif close >= 0:
                out.append(_parse_frame(buf[pos : close + 1]))
                pos = close + 1
            elif n - pos >= MAX_FRAME:
                self._skip_len = MAX_FRAME
                out.append(BadFrame(buf[pos : pos + MAX_FRAME], _overlong(MAX_FRAME)))
                pos += MAX_FRAME
            else:
                break
        return pos

    def _skip(self, buf: bytes, pos: int, n: int, out: list[HostEvent]) -> int | None:
        """Discard the rest of an over-long frame, up to its `}` or the next `{`.

        Returns the new position, or None to wait for more bytes.
        """
        end = min(n, pos + MAX_RUN)
        opening = buf.find(b"{", pos, end)
        closing = buf.find(b"}", pos, opening if opening >= 0 else end)
        if closing >= 0:
            stop, done = closing + 1, True
        elif opening >= 0:
            stop, done = opening, True
        elif end - pos == MAX_RUN:
            stop, done = end, False
        else:
            return None
        self._skip_len += stop - pos
        if stop > pos:
            out.append(BadFrame(buf[pos:stop], _overlong(self._skip_len, done)))
        if done:
            self._skip_len = 0
        return stop

    @property
    def in_frame(self) -> bool:
        """Whether the bytes so far leave a frame open (a `Z` now would be part of it)."""
        return bool(self._buf) or self._skip_len > 0

    def flush(self) -> list[HostEvent]:
        """Report what is held at the end of the stream (an unterminated frame)."""
        if not self._buf:
            return []
        reason = (
            _overlong(self._skip_len + len(self._buf))
            if self._skip_len
            else ("unterminated frame at end of stream")
        )
        self._skip_len = 0
        raw = self._buf
        self._buf = b""
        return [BadFrame(raw, reason)]


def _overlong(length: int, done: bool = False) -> str:
    if done:
        return f"over-long frame discarded ({length} bytes, limit {MAX_FRAME})"
    return f"over-long frame ({length}+ bytes, limit {MAX_FRAME}): discarding to '}}'"


# ---------------------------------------------------------------- board stream

_FIELDS = deferred(rb"-?[0-9]+(?::-?[0-9]+)*")
_RECORD_SIZES = {ord("A"): 4, ord("B"): 4, ord("C"): params.PARAM_COUNT}


def _parse_record(
    raw: bytes, body: bytes, terminated: bool, b_fields: int | None = 4, c_fields: int = 9
) -> BoardEvent:
    """One record's event; `b_fields` None: any record whose field count is not the
    sheet's is an OtherRecord (a probe that does not know the firmware yet)."""
    if not body:
        return Malformed(raw, "empty record")
    letter = body[0]
    if not (0x41 <= letter <= 0x5A or 0x61 <= letter <= 0x7A):
        return Malformed(raw, "record does not start with a letter")
    fields = body[1:]
    if not _FIELDS.fullmatch(fields):
        return Malformed(raw, "fields are not ':'-separated integers")
    values = tuple(int(f) for f in fields.split(b":"))
    size = b_fields if letter == 0x42 else c_fields if letter == 0x43 else _RECORD_SIZES.get(letter)
    if b_fields is None and len(values) != _RECORD_SIZES.get(letter):
        size = None
    if size is None or (letter == 0x42 and size != 4 and len(values) == size):
        return OtherRecord(chr(letter), values, terminated, raw)  # a profile names the Bs
    if len(values) != size:
        return Malformed(raw, f"{chr(letter)} record has {len(values)} fields, expected {size}")
    if letter == 0x43:
        return ParamsRecord(values, terminated, raw)  # out-of-range values too: boards hold them
    a, b, c, d = values
    if letter == 0x41:
        return Velocity(a, b, c, d, terminated, raw)
    return Attitude(a, b, c, d, terminated, raw)


_FAST = deferred(rb"(\{[AB](-?[0-9]{1,11}):(-?[0-9]{1,11}):(-?[0-9]{1,11}):(-?[0-9]{1,11})\}\$)")
"""A complete A or B record: the common case, decoded without the general path. It opens
with a literal `{`, so the search skips to each `{` and fails within a few bytes there:
linear in the input, whatever it holds."""
_FAST_A = deferred(rb"(\{A(-?[0-9]{1,11}):(-?[0-9]{1,11}):(-?[0-9]{1,11}):(-?[0-9]{1,11})\}\$)")
"""`_FAST` for A records alone (a profile whose B record has other than four fields)."""
_FAST_KIND = {0x41: Velocity, 0x42: Attitude}


class BoardDecoder:
    """board→host bytes → records (§3). A missing `$` is tolerated."""

    LIMIT = max(MAX_RECORD, MAX_RUN)
    """Most bytes ever held between calls."""

    def __init__(self, b_fields: int | None = 4, c_fields: int = params.PARAM_COUNT) -> None:
        """`b_fields`, `c_fields`: how many fields the profile's B and C records have
        (the sheet's four B fields are an `Attitude`; other counts an `OtherRecord` that
        the profile's layout names); `b_fields` None: any count, as an OtherRecord."""
        self._buf = b""
        self._sizes = b_fields, c_fields
        self._fast = _FAST if b_fields in (4, None) else _FAST_A

    @property
    def buffered(self) -> int:
        return len(self._buf)

    @linear
    def feed(self, data: bytes) -> list[BoardEvent]:
        buf = self._buf + data if self._buf else bytes(data)
        out: list[BoardEvent] = []
        append, general, kind = out.append, self._general, _FAST_KIND
        pos = 0
        # split scans in C: [gap, record, x, y, z, w, gap, record, …, gap]; each gap
        # goes the general way, the last one held if it may continue
        parts = iter(self._fast.split(buf))
        for gap, raw, x, y, z, w in zip(*[parts] * 6, strict=False):  # the last gap left out
            if gap:
                general(buf, pos, pos + len(gap), out, False)
                pos += len(gap)
            append(kind[raw[1]](int(x), int(y), int(z), int(w), True, raw))
            pos += len(raw)
        pos = general(buf, pos, len(buf), out, True)
        self._buf = buf[pos:]
        return out

    def _general(self, buf: bytes, pos: int, n: int, out: list[BoardEvent], hold: bool) -> int:
        """Decode buf[pos:n]. With `hold`, stop where more bytes could change the outcome
        (a partial record or garbage run at the end); without, n is the start of a record.
        Returns where it stopped."""
        while pos < n:
            if buf[pos] != LBRACE:
                start = buf.find(b"{", pos, pos + MAX_RUN if pos + MAX_RUN < n else n)
                if start < 0:
                    if n - pos < MAX_RUN:
                        if hold:
                            break  # the run may go on: hold it
                        start = n
                    else:
                        start = pos + MAX_RUN
                out.append(Garbage(buf[pos:start]))
                pos = start
                continue
            after, close = _opening(buf, pos, n, MAX_RECORD, hold, out, Malformed, "record")
            if after is None:
                break
            if after >= 0:
                pos = after
            elif close >= 0:
                if close + 1 == n and hold:
                    break  # a '$' may follow
                end = close + 2 if close + 1 < n and buf[close + 1] == DOLLAR else close + 1
                raw = buf[pos:end]
                out.append(_parse_record(raw, raw[1 : close - pos], end == close + 2, *self._sizes))
                pos = end
            elif n - pos >= MAX_RECORD:
                out.append(
                    Malformed(buf[pos : pos + MAX_RECORD], f"over {MAX_RECORD} bytes without '}}'")
                )
                pos += MAX_RECORD
            elif hold:
                break
            else:
                out.append(Malformed(buf[pos:n], _interrupted("record", 1)))
                pos = n
        return pos

    def flush(self) -> list[BoardEvent]:
        """Report what is held at the end of the stream."""
        raw = self._buf
        self._buf = b""
        if not raw:
            return []
        if raw[0] != LBRACE:
            return [Garbage(raw)]
        if raw.endswith(b"}"):
            return [_parse_record(raw, raw[1:-1], False, *self._sizes)]
        return [Malformed(raw, "unterminated record at end of stream")]
