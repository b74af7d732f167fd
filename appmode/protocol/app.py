"""The APP protocol's grammar both ways, with no I/O (docs/protocol.md §2, §3).

The commands and records as events, and `encode(item)`, which turns any of them into
bytes. The decoders are in `app_decoders`; what ends a session with the car stopped in
`session_end`.
"""

from __future__ import annotations

from collections.abc import Sequence

from appmode.protocol import params
from appmode.protocol.directions import LETTERS, PAGE_LETTERS
from appmode.protocol.slotted import Frozen, Slotted

LBRACE, RBRACE, DOLLAR, COLON = 0x7B, 0x7D, 0x24, 0x3A
MAX_FRAME = 50
"""Longest host frame, braces included (§2.2)."""
MAX_RECORD = 128
"""Longest board record kept whole: a C record of nine 10-digit values is 100 bytes."""
MAX_RUN = 64
"""Longest run of undecodable bytes reported as one event."""
SEPARATOR = COLON


# ---------------------------------------------------------------- host → board commands
# Commands are immutable and hashable; each names its fields in `__slots__` and the ones
# compared and shown in `_shown` (protocol/slotted.py). `raw` is the bytes it came from.


class Move(Frozen):
    """Drive in direction 1…8: letters A–H, or the raw bytes 0x01–0x08 when `numeric`."""

    __slots__ = _fields = ("direction", "numeric", "raw")
    _shown = ("direction", "numeric")
    direction: int
    numeric: bool
    raw: bytes

    def __init__(self, direction: int, numeric: bool = False, raw: bytes = b"") -> None:
        self._fill(direction, numeric, raw)

    @property
    def letter(self) -> str:
        return LETTERS[self.direction - 1]


class Stop(Frozen):
    """`Z`: stop."""

    __slots__ = _fields = ("raw",)
    raw: bytes

    def __init__(self, raw: bytes = b"") -> None:
        self._fill(raw)


class SwitchPage(Frozen):
    """`I` (gravity) or `J` (joystick): the direction page; `K`: the button page."""

    __slots__ = _fields = ("letter", "raw")
    _shown = ("letter",)
    letter: str
    raw: bytes

    def __init__(self, letter: str, raw: bytes = b"") -> None:
        self._fill(letter, raw)


class _QFrame(Frozen):
    """A `{Q?x}` frame. `separator` is the byte in position 2 (§2.2)."""

    __slots__ = _fields = ("separator", "raw")
    _shown = ("separator",)
    separator: int
    raw: bytes

    def __init__(self, separator: int = SEPARATOR, raw: bytes = b"") -> None:
        self._fill(separator, raw)

    @property
    def warning(self) -> str | None:
        return _separator_warning(self.separator)


class ReadParams(_QFrame):
    """`{Q:P}`: ask for a C record."""

    __slots__ = ()


class SaveParams(_QFrame):
    """`{Q:W}`: save the running parameters to non-volatile memory."""

    __slots__ = ()


class SetParam(Frozen):
    """`{n:v}`: set parameter n to v (always within range when decoded)."""

    __slots__ = _fields = ("index", "value", "raw")
    _shown = ("index", "value")
    index: int
    value: int
    raw: bytes

    def __init__(self, index: int, value: int, raw: bytes = b"") -> None:
        self._fill(index, value, raw)

    @property
    def name(self) -> str:
        return params.PARAMS[self.index].name


class Noise(Frozen):
    """A byte outside any frame that is no command: the board stops (§2.1)."""

    __slots__ = _fields = ("raw",)
    _shown = ("raw",)
    raw: bytes

    def __init__(self, raw: bytes) -> None:
        self._fill(raw)


class BadFrame(Frozen):
    """A `{…}` frame the board discards: over-long, unknown, or a bad set frame."""

    __slots__ = _fields = ("raw", "reason")
    _shown = ("raw", "reason")
    raw: bytes
    reason: str

    def __init__(self, raw: bytes, reason: str) -> None:
        self._fill(raw, reason)


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
# class costs three to four times as much to build, and the decoders build hundreds of
# thousands a second (bench/decoder.py). Treat them as immutable all the same. A
# record's `letter` and `values` are its wire letter and fields; its `terminated` is False
# when its `$` was missing.


class Velocity(Slotted):
    """`{A x:y:z:0}$`: body velocity, lateral (right +), forward (+), rotation (cw +)."""

    __slots__ = _fields = ("x", "y", "z", "extra", "terminated", "raw")
    _shown = ("x", "y", "z", "extra")

    def __init__(
        self, x: int, y: int, z: int, extra: int = 0, terminated: bool = True, raw: bytes = b""
    ) -> None:
        self.x = x
        self.y = y
        self.z = z
        self.extra = extra
        self.terminated = terminated
        self.raw = raw

    letter = "A"

    @property
    def values(self) -> tuple[int, ...]:
        """The record's fields in wire order."""
        return (self.x, self.y, self.z, self.extra)


class Attitude(Slotted):
    """`{B pitch:roll:yaw:battery}$`: degrees and battery percent."""

    __slots__ = _fields = ("pitch", "roll", "yaw", "battery", "terminated", "raw")
    _shown = ("pitch", "roll", "yaw", "battery")

    def __init__(
        self,
        pitch: int,
        roll: int,
        yaw: int,
        battery: int,
        terminated: bool = True,
        raw: bytes = b"",
    ) -> None:
        self.pitch = pitch
        self.roll = roll
        self.yaw = yaw
        self.battery = battery
        self.terminated = terminated
        self.raw = raw

    letter = "B"

    @property
    def values(self) -> tuple[int, ...]:
        """The record's fields in wire order."""
        return (self.pitch, self.roll, self.yaw, self.battery)


class ParamsRecord(Slotted):
    """`{C p0:…:p8}$`: the nine parameters in index order."""

    __slots__ = _fields = ("values", "terminated", "raw")
    _shown = ("values",)

    def __init__(self, values: tuple[int, ...], terminated: bool = True, raw: bytes = b"") -> None:
        self.values = values
        self.terminated = terminated
        self.raw = raw

    letter = "C"


class OtherRecord(Slotted):
    """A well-formed record whose letter this protocol does not define."""

    __slots__ = _fields = ("letter", "values", "terminated", "raw")
    _shown = ("letter", "values")

    def __init__(
        self, letter: str, values: tuple[int, ...], terminated: bool = True, raw: bytes = b""
    ) -> None:
        self.letter = letter
        self.values = values
        self.terminated = terminated
        self.raw = raw


class Malformed(Slotted):
    """Bytes from `{` that do not make a record: truncated, over-long or ill-formed."""

    __slots__ = _fields = ("raw", "reason")
    _shown = ("raw", "reason")

    def __init__(self, raw: bytes, reason: str) -> None:
        self.raw = raw
        self.reason = reason


class Garbage(Slotted):
    """A run of bytes outside any record."""

    __slots__ = _fields = ("raw",)
    _shown = ("raw",)

    def __init__(self, raw: bytes) -> None:
        self.raw = raw


Record = Velocity | Attitude | ParamsRecord | OtherRecord
BoardEvent = Record | Malformed | Garbage
Event = HostEvent | BoardEvent
RECORDS = (Velocity, Attitude, ParamsRecord, OtherRecord)
ERRORS = (Noise, BadFrame, Malformed, Garbage)
"""Event types that carry bytes which decoded to nothing."""

# ---------------------------------------------------------------- encoding


def set_frame(index: int, value: int) -> bytes:
    """`{n:v}`, unchecked: the caller checked `value` against its profile's table
    (`encode(SetParam(…))` checks it against the sheet's)."""
    return b"{%d:%d}" % (index, value)


def record_bytes(letter: bytes, values: Sequence[int]) -> bytes:
    """A record's wire bytes: `{`, its letter, its values joined by `:`, `}$`."""
    return b"{%s%s}$" % (letter, b":".join(b"%d" % v for v in values))


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
        return set_frame(item.index, item.value)
    if isinstance(item, Velocity):
        return record_bytes(b"A", (item.x, item.y, item.z, item.extra))
    if isinstance(item, Attitude):
        return record_bytes(b"B", (item.pitch, item.roll, item.yaw, item.battery))
    if isinstance(item, ParamsRecord):  # any values: a real board sends what it holds (§3.3)
        if len(item.values) != params.PARAM_COUNT:
            raise ValueError(f"a C record has {params.PARAM_COUNT} values, not {len(item.values)}")
        return record_bytes(b"C", item.values)
    if isinstance(item, OtherRecord):
        if len(item.letter) != 1 or not item.letter.isalpha() or not item.letter.isascii():
            raise ValueError(f"record letter must be one ASCII letter, not {item.letter!r}")
        return record_bytes(item.letter.encode(), item.values)
    return item.raw
