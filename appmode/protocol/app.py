"""The APP protocol's grammar both ways, with no I/O (docs/protocol.md §2, §3).

The commands and records as events, and `encode(item)`, which turns any of them into
bytes. The decoders are in `app_decoders`; what ends a session with the car stopped in
`session_end`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from appmode.protocol import params
from appmode.protocol.directions import LETTERS, PAGE_LETTERS

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
