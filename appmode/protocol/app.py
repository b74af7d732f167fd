"""The APP protocol's grammar both ways, with no I/O (docs/protocol.md §2, §3).

`encode(item)` turns any command or record into bytes. `HostDecoder` turns the
host→board stream into commands, `BoardDecoder` the board→host stream into records.
Decoders never raise on bytes, hold a bounded buffer, resynchronise at the next `{`,
and give every byte they consume to exactly one event (its `raw`), so that the events
of a stream re-encode to exactly that stream. Their output does not depend on how the
stream is split into `feed` calls.
"""

from __future__ import annotations

import functools
import re
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TypeVar

from appmode.protocol import params
from appmode.protocol.bulk import linear
from appmode.protocol.directions import BUTTON_PAGE, LETTERS, PAGE_LETTERS

LBRACE, RBRACE, DOLLAR, COLON = 0x7B, 0x7D, 0x24, 0x3A
MAX_FRAME = 50
"""Longest host frame, braces included (§2.2)."""
MAX_RECORD = 128
"""Longest board record kept whole: a C record of nine 10-digit values is 100 bytes."""
MAX_RUN = 64
"""Longest run of undecodable bytes reported as one event."""
SEPARATOR = COLON


def _raw() -> bytes:
    return field(default=b"", compare=False, repr=False)


# ---------------------------------------------------------------- host → board commands


@dataclass(frozen=True, slots=True)
class Move:
    """Drive in direction 1…8: letters A–H, or the raw bytes 0x01–0x08 when `numeric`."""

    direction: int
    numeric: bool = False
    raw: bytes = _raw()

    @property
    def letter(self) -> str:
        return LETTERS[self.direction - 1]


@dataclass(frozen=True, slots=True)
class Stop:
    """`Z`: stop."""

    raw: bytes = _raw()


@dataclass(frozen=True, slots=True)
class SwitchPage:
    """`I` (gravity) or `J` (joystick): the direction page; `K`: the button page."""

    letter: str
    raw: bytes = _raw()


@dataclass(frozen=True, slots=True)
class ReadParams:
    """`{Q:P}`: ask for a C record. `separator` is the byte in position 2 (§2.2)."""

    separator: int = SEPARATOR
    raw: bytes = _raw()

    @property
    def warning(self) -> str | None:
        return _separator_warning(self.separator)


@dataclass(frozen=True, slots=True)
class SaveParams:
    """`{Q:W}`: save the running parameters to non-volatile memory."""

    separator: int = SEPARATOR
    raw: bytes = _raw()

    @property
    def warning(self) -> str | None:
        return _separator_warning(self.separator)


@dataclass(frozen=True, slots=True)
class SetParam:
    """`{n:v}`: set parameter n to v (always within range when decoded)."""

    index: int
    value: int
    raw: bytes = _raw()

    @property
    def name(self) -> str:
        return params.PARAMS[self.index].name


@dataclass(frozen=True, slots=True)
class Noise:
    """A byte outside any frame that is no command: the board stops (§2.1)."""

    raw: bytes


@dataclass(frozen=True, slots=True)
class BadFrame:
    """A `{…}` frame the board discards: over-long, unknown, or a bad set frame."""

    raw: bytes
    reason: str


Command = Move | Stop | SwitchPage | ReadParams | SaveParams | SetParam
HostEvent = Command | Noise | BadFrame
ByteEvent = Move | Stop | SwitchPage | Noise
"""What a byte outside a frame can be."""


def _separator_warning(separator: int) -> str | None:
    if separator == SEPARATOR:
        return None
    return f"Q frame separator is 0x{separator:02X}, expected 0x3A ':' (accepted)"


# ---------------------------------------------------------------- board → host records
# Records, and what a decoder reports of bytes that are none, are not frozen: a frozen
# dataclass costs three to four times as much to build, and the decoders build hundreds
# of thousands a second (bench/decoder.py). Treat them as immutable all the same.


@dataclass(slots=True)
class Velocity:
    """`{A x:y:z:0}$`: body velocity, lateral (right +), forward (+), rotation (cw +)."""

    x: int
    y: int
    z: int
    extra: int = 0
    terminated: bool = field(default=True, compare=False, repr=False)
    raw: bytes = _raw()


@dataclass(slots=True)
class Attitude:
    """`{B pitch:roll:yaw:battery}$`: degrees and battery percent."""

    pitch: int
    roll: int
    yaw: int
    battery: int
    terminated: bool = field(default=True, compare=False, repr=False)
    raw: bytes = _raw()


@dataclass(slots=True)
class ParamsRecord:
    """`{C p0:…:p8}$`: the nine parameters in index order."""

    values: tuple[int, ...]
    terminated: bool = field(default=True, compare=False, repr=False)
    raw: bytes = _raw()

    def as_dict(self) -> dict[str, int]:
        return {p.name: v for p, v in zip(params.PARAMS, self.values, strict=True)}

    @property
    def out_of_range(self) -> tuple[str, ...]:
        """The names of the values outside the sheet's ranges: a real firmware takes any
        value it is sent, so a board can hold them (they are shown, flagged)."""
        if params.values_error(self.values) is None:
            return ()
        return tuple(
            p.name
            for p, v in zip(params.PARAMS, self.values, strict=True)
            if params.value_error(p.index, v) is not None
        )


@dataclass(slots=True)
class OtherRecord:
    """A well-formed record whose letter this protocol does not define."""

    letter: str
    values: tuple[int, ...]
    terminated: bool = field(default=True, compare=False, repr=False)
    raw: bytes = _raw()


@dataclass(slots=True)
class Malformed:
    """Bytes from `{` that do not make a record: truncated, over-long or ill-formed."""

    raw: bytes
    reason: str


@dataclass(slots=True)
class Garbage:
    """A run of bytes outside any record."""

    raw: bytes


Record = Velocity | Attitude | ParamsRecord | OtherRecord
BoardEvent = Record | Malformed | Garbage
Event = HostEvent | BoardEvent
RECORDS = (Velocity, Attitude, ParamsRecord, OtherRecord)
ERRORS = (Noise, BadFrame, Malformed, Garbage)
"""Event types that carry bytes which decoded to nothing."""

# ---------------------------------------------------------------- encoding


def record_fields(record: Record) -> tuple[str, tuple[int, ...]]:
    """A record as (letter, field values)."""
    if isinstance(record, Velocity):
        return "A", (record.x, record.y, record.z, record.extra)
    if isinstance(record, Attitude):
        return "B", (record.pitch, record.roll, record.yaw, record.battery)
    if isinstance(record, ParamsRecord):
        return "C", record.values
    return record.letter, record.values


def _ints(values: tuple[int, ...] | list[int]) -> bytes:
    return b":".join(b"%d" % v for v in values)


def encode(item: Event) -> bytes:
    """The wire bytes of a command or record; ValueError when a value is out of range."""
    if isinstance(item, Move):
        if not 1 <= item.direction <= 8:
            raise ValueError(f"direction must be 1–8, not {item.direction}")
        return bytes([item.direction]) if item.numeric else item.letter.encode()
    if isinstance(item, Stop):
        return b"Z"
    if isinstance(item, SwitchPage):
        if item.letter not in PAGE_LETTERS:
            raise ValueError(f"page letter must be I, J or K, not {item.letter!r}")
        return item.letter.encode()
    if isinstance(item, ReadParams):
        return b"{Q" + bytes([item.separator]) + b"P}"
    if isinstance(item, SaveParams):
        return b"{Q" + bytes([item.separator]) + b"W}"
    if isinstance(item, SetParam):
        params.check_value(item.index, item.value)
        return b"{%d:%d}" % (item.index, item.value)
    if isinstance(item, Velocity):
        return b"{A" + _ints([item.x, item.y, item.z, item.extra]) + b"}$"
    if isinstance(item, Attitude):
        return b"{B" + _ints([item.pitch, item.roll, item.yaw, item.battery]) + b"}$"
    if isinstance(item, ParamsRecord):  # any values: a real board sends what it holds (§3.3)
        if len(item.values) != params.PARAM_COUNT:
            raise ValueError(f"a C record has {params.PARAM_COUNT} values, not {len(item.values)}")
        return b"{C" + _ints(item.values) + b"}$"
    if isinstance(item, OtherRecord):
        if len(item.letter) != 1 or not item.letter.isalpha() or not item.letter.isascii():
            raise ValueError(f"record letter must be one ASCII letter, not {item.letter!r}")
        return b"{" + item.letter.encode() + _ints(item.values) + b"}$"
    return item.raw


# ---------------------------------------------------------------- host stream decoder


def _single_byte_events() -> tuple[ByteEvent, ...]:
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


SINGLE_BYTE = _single_byte_events()
"""What each byte means outside a frame (§2.1), by value."""


E = TypeVar("E")
_BRACES = re.compile(rb"\{{2,%d}" % (MAX_RUN + 1))


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


def _interrupted(what: str, count: int) -> str:
    return f"{what} interrupted by '{{'" if count == 1 else f"{count} {what}s interrupted by '{{'"


_FRAMES = re.compile(rb"(\{[^{}]{0,%d}\})" % (MAX_FRAME - 2))
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
        general, parse, single = self._general, _parse_frame, SINGLE_BYTE
        pos = 0
        # split scans in C: [gap, frame, gap, frame, …, gap]; a gap of single bytes is
        # read here, others go the general way, the last one held where it may continue
        parts = _FRAMES.split(buf)
        for i in range(0, len(parts) - 1, 2):
            gap, frame = parts[i], parts[i + 1]
            if gap:
                if self._skip_len or LBRACE in gap:
                    pos = general(buf, pos, pos + len(gap), out)
                else:
                    out += [single[b] for b in gap]
                    pos += len(gap)
            out.append(parse(frame))
            pos += len(frame)
        pos = general(buf, pos, len(buf), out)
        self._buf = buf[pos:]
        return out

    def _general(self, buf: bytes, pos: int, end: int, out: list[HostEvent]) -> int:
        """Decode buf[pos:end], which holds no whole frame of up to MAX_FRAME bytes;
        at the end of `buf`, stop where more bytes could change the outcome. Returns
        where it stopped."""
        n, single = len(buf), SINGLE_BYTE
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
            if pos + 1 < n and buf[pos + 1] == LBRACE:
                after = _brace_run(buf, pos, True, out, BadFrame, "frame")
                if after is None:
                    break
                pos = after
                continue
            limit = min(n, pos + MAX_FRAME)
            close = buf.find(b"}", pos + 1, limit)
            reopen = buf.find(b"{", pos + 1, close if close >= 0 else limit)
            if reopen >= 0:
                out.append(BadFrame(buf[pos:reopen], _interrupted("frame", 1)))
                pos = reopen
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


ABANDON_FRAME = b"{}"
"""Ends an open frame without applying it: `{` abandons the open frame (§2.2) and `{}` is
an empty frame, which changes nothing."""


def stop_again(frames_take_letters: bool) -> bytes:
    """What to send when a stop did not take (the car still moves): where a frame takes
    letters (the sheet, §2.2) a frame another program left open may have swallowed the
    `Z`: `{` drops it unapplied and `}` closes the empty frame; `K` ends a button-page
    rotation left by `I`/`J` (§13) and `J` goes back to the direction page; then `Z`.
    Where every byte steers even inside a frame (the reference firmware, §13) no brace is
    sent: there a `}` would apply a half-sent set."""
    return (ABANDON_FRAME if frames_take_letters else b"") + b"KJ" + encode(Stop())


class SessionEnd:
    """Follows what a host sends, so that its last bytes stop the car (§2.1).

    A `Z` sent while a frame is open is swallowed by the frame: then `{}` goes first. A
    rotation begun on the button page and left by `I`/`J` goes on after `Z` on the
    reference firmware (§13): then `K` ends it, and the page letter goes back, first.
    """

    def __init__(self) -> None:
        self._decoder = HostDecoder()
        self._page = "J"  # the page letter last sent (the board boots on the direction page)
        self._turning = False  # a button-page rotation that a direction-page Z leaves on

    def sent(self, data: bytes) -> list[HostEvent]:
        """Follow `data`; returns what it decodes to."""
        events = self._decoder.feed(data)
        for event in events:
            if isinstance(event, SwitchPage):
                self._turning = self._turning and event.letter != "K"
                self._page = event.letter
            elif self._page == "K" and isinstance(event, (Move, Stop, Noise)):
                self._turning = isinstance(event, Move) and _rotates(event)
            elif isinstance(event, Move):
                self._turning = False
        return events

    @property
    def stop(self) -> bytes:
        """The bytes that end the session with the car stopped."""
        frame = ABANDON_FRAME if self._decoder.in_frame else b""
        rotation = f"K{self._page}".encode() if self._turning and self._page != "K" else b""
        return frame + rotation + encode(Stop())

    @property
    def stop_text(self) -> str:
        """What `stop` does, for people."""
        steps = ["closes the open frame"] if self._decoder.in_frame else []
        if self._turning and self._page != "K":
            steps.append(f"ends a button-page rotation (K), back to {self._page}")
        return ", ".join([*steps, "then stop"]) if steps else "stop"


def _rotates(move: Move) -> bool:
    """A button-page letter that rotates the car on the spot (C, G)."""
    motion = BUTTON_PAGE.get(move.letter)
    return not move.numeric and motion is not None and motion.holonomic[:2] == (0, 0)


def _overlong(length: int, done: bool = False) -> str:
    if done:
        return f"over-long frame discarded ({length} bytes, limit {MAX_FRAME})"
    return f"over-long frame ({length}+ bytes, limit {MAX_FRAME}): discarding to '}}'"


# ---------------------------------------------------------------- board stream decoder

_FIELDS = re.compile(rb"-?[0-9]+(?::-?[0-9]+)*")
_RECORD_SIZES = {ord("A"): 4, ord("B"): 4, ord("C"): params.PARAM_COUNT}


def _parse_record(raw: bytes, body: bytes, terminated: bool) -> BoardEvent:
    if not body:
        return Malformed(raw, "empty record")
    letter = body[0]
    if not (0x41 <= letter <= 0x5A or 0x61 <= letter <= 0x7A):
        return Malformed(raw, "record does not start with a letter")
    fields = body[1:]
    if not _FIELDS.fullmatch(fields):
        return Malformed(raw, "fields are not ':'-separated integers")
    values = tuple(int(f) for f in fields.split(b":"))
    size = _RECORD_SIZES.get(letter)
    if size is None:
        return OtherRecord(chr(letter), values, terminated, raw)
    if len(values) != size:
        return Malformed(raw, f"{chr(letter)} record has {len(values)} fields, expected {size}")
    a, b, c, d = values[:4]
    if letter == 0x41:
        return Velocity(a, b, c, d, terminated, raw)
    if letter == 0x42:
        return Attitude(a, b, c, d, terminated, raw)
    return ParamsRecord(values, terminated, raw)  # out-of-range values too: boards hold them


_FAST = re.compile(rb"(\{[AB](-?[0-9]{1,11}):(-?[0-9]{1,11}):(-?[0-9]{1,11}):(-?[0-9]{1,11})\}\$)")
"""A complete A or B record: the common case, decoded without the general path. It opens
with a literal `{`, so the search skips to each `{` and fails within a few bytes there:
linear in the input, whatever it holds."""
_FAST_KIND = {0x41: Velocity, 0x42: Attitude}


class BoardDecoder:
    """board→host bytes → records (§3). A missing `$` is tolerated."""

    LIMIT = max(MAX_RECORD, MAX_RUN)
    """Most bytes ever held between calls."""

    def __init__(self) -> None:
        self._buf = b""

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
        parts = _FAST.split(buf)
        for i in range(0, len(parts) - 1, 6):
            gap, raw, x, y, z, w = parts[i : i + 6]
            if gap:
                general(buf, pos, pos + len(gap), out, False)
                pos += len(gap)
            append(kind[raw[1]](int(x), int(y), int(z), int(w), True, raw))
            pos += len(raw)
        pos = general(buf, pos, len(buf), out, True)
        self._buf = buf[pos:]
        return out

    @staticmethod
    def _general(buf: bytes, pos: int, n: int, out: list[BoardEvent], hold: bool) -> int:
        """Decode buf[pos:n]. With `hold`, stop where more bytes could change the outcome
        (a partial record or garbage run at the end); without, n is the start of a record.
        Returns where it stopped."""
        while pos < n:
            if buf[pos] != LBRACE:
                start = buf.find(b"{", pos, min(n, pos + MAX_RUN))
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
            if pos + 1 < n and buf[pos + 1] == LBRACE:
                after = _brace_run(buf, pos, hold, out, Malformed, "record")
                if after is None:
                    break
                pos = after
                continue
            limit = min(n, pos + MAX_RECORD)
            close = buf.find(b"}", pos + 1, limit)
            reopen = buf.find(b"{", pos + 1, close if close >= 0 else limit)
            if reopen >= 0:
                out.append(Malformed(buf[pos:reopen], _interrupted("record", 1)))
                pos = reopen
            elif close >= 0:
                if close + 1 == n and hold:
                    break  # a '$' may follow
                end = close + 2 if close + 1 < n and buf[close + 1] == DOLLAR else close + 1
                raw = buf[pos:end]
                out.append(_parse_record(raw, raw[1 : close - pos], end == close + 2))
                pos = end
            elif n - pos >= MAX_RECORD:
                out.append(Malformed(buf[pos:limit], f"over {MAX_RECORD} bytes without '}}'"))
                pos = limit
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
            return [_parse_record(raw, raw[1:-1], False)]
        return [Malformed(raw, "unterminated record at end of stream")]
