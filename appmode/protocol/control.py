"""The control port's binary grammar both ways, with no I/O (docs/protocol.md §8–§12).

The frames, replies and reports as events, and `encode(item)`, which turns a host frame,
a `#` reply or an encoder report into bytes, with range checks that name the field. The
decoders are in `control_decoders`.
"""

from __future__ import annotations

import struct

from appmode.errors import InvalidValue
from appmode.protocol import app, params, settings
from appmode.protocol.params import DriveType
from appmode.protocol.settings import Read, Setting, StoreOp
from appmode.protocol.slotted import Frozen, Slotted

HEADER = b"\xff\xfe"
VELOCITY, MOTORS, POSITION, SETTINGS = 0x01, 0x02, 0x03, 0x80
MODES = {VELOCITY: "velocity", MOTORS: "motors", POSITION: "position", SETTINGS: "settings"}
FRAME = 10
"""Bytes of every frame but a 4-motor mode-02 frame."""
MOTOR_FRAME_4 = 12
REPLY, REPORT, REPORT_END = 0x23, 0x24, 0x19
REPLY_LEN = 6
ANGLE_BIT = 0x10
U16 = 0xFFFF
MAX_DUTY = 1000
"""A differential drive's duty, in 0.1 % (§9.1)."""
MAX_RUN = 64
"""Longest run of undecodable bytes reported as one event."""
STOP = bytes([0xFF, 0xFE, VELOCITY, 0, 0, 0, 0, 0, 0, 0])
"""The control port's `Z`: a velocity frame of zeros (§8.3)."""


def motor_count(drive: DriveType) -> int:
    """Motors of a drive type: 3 on an omni, 4 on the others (§9.2)."""
    return 3 if drive is DriveType.OMNI else 4


# ---------------------------------------------------------------- host → board frames


class VelocityFrame(Frozen):
    """Mode `01`: three signed fields and angle mode (§9.1). What the fields mean depends
    on the drive type: x, y, z (omni, mecanum); reserved, y, z (diff); left, right,
    reserved (diff-gyro). With `angle`, the third field is an angle in 0.1°."""

    __slots__ = _fields = ("a", "b", "c", "angle", "raw")
    _shown = ("a", "b", "c", "angle")
    a: int
    b: int
    c: int
    angle: bool
    raw: bytes

    def __init__(self, a: int, b: int, c: int, angle: bool = False, raw: bytes = b"") -> None:
        self._fill(a, b, c, angle, raw)

    @property
    def values(self) -> tuple[int, int, int]:
        return (self.a, self.b, self.c)


class MotorFrame(Frozen):
    """Mode `02`: a signed speed for each motor, 3 or 4 (§9.2)."""

    __slots__ = _fields = ("speeds", "raw")
    _shown = ("speeds",)
    speeds: tuple[int, ...]
    raw: bytes

    def __init__(self, speeds: tuple[int, ...], raw: bytes = b"") -> None:
        self._fill(speeds, raw)

    @property
    def values(self) -> tuple[int, ...]:
        return self.speeds


class PositionFrame(Frozen):
    """Mode `03`: signed x, y, z displacements (§9.3)."""

    __slots__ = _fields = ("x", "y", "z", "raw")
    _shown = ("x", "y", "z")
    x: int
    y: int
    z: int
    raw: bytes

    def __init__(self, x: int, y: int, z: int, raw: bytes = b"") -> None:
        self._fill(x, y, z, raw)


class SetSetting(Frozen):
    """Mode `80`, SS 01–0A: set a setting (always within range when decoded)."""

    __slots__ = _fields = ("setting", "value", "raw")
    _shown = ("setting", "value")
    setting: Setting
    value: int
    raw: bytes

    def __init__(self, setting: Setting, value: int, raw: bytes = b"") -> None:
        self._fill(setting, value, raw)


class StoreFrame(Frozen):
    """Mode `80`, SS 00: load, defaults or save (§10)."""

    __slots__ = _fields = ("op", "raw")
    _shown = ("op",)
    op: StoreOp
    raw: bytes

    def __init__(self, op: StoreOp, raw: bytes = b"") -> None:
        self._fill(op, raw)


class ReadFrame(Frozen):
    """Mode `80`, a read's SS (§11): ask for a `#` reply."""

    __slots__ = _fields = ("read", "raw")
    _shown = ("read",)
    read: Read
    raw: bytes

    def __init__(self, read: Read, raw: bytes = b"") -> None:
        self._fill(read, raw)


class BadFrame(Frozen):
    """A whole frame the board discards: a value out of range, an unknown SS."""

    __slots__ = _fields = _shown = ("raw", "reason")
    raw: bytes
    reason: str

    def __init__(self, raw: bytes, reason: str) -> None:
        self._fill(raw, reason)


class Garbage(Slotted):
    """Bytes outside any frame or reply, an unknown mode's header, or a truncated frame."""

    __slots__ = _fields = _shown = ("raw", "reason")

    def __init__(self, raw: bytes, reason: str = "bytes outside any frame") -> None:
        self.raw = raw
        self.reason = reason


HostFrame = VelocityFrame | MotorFrame | PositionFrame | SetSetting | StoreFrame | ReadFrame
HostEvent = HostFrame | BadFrame | Garbage

# ---------------------------------------------------------------- board → host
# Not frozen, like the APP records and for the same reason (protocol/app.py): treat them
# as immutable all the same.


class Reply(Slotted):
    """`23 NN b3 b2 b1 b0`: the answer to a read (§11)."""

    __slots__ = _fields = ("id", "value", "raw")
    _shown = ("id", "value")

    def __init__(self, id: int, value: int, raw: bytes = b"") -> None:
        self.id = id
        self.value = value
        self.raw = raw

    @property
    def read(self) -> Read | None:
        return settings.READ_BY_REPLY.get(self.id)

    @property
    def name(self) -> str:
        read = self.read
        return read.name if read else f"0x{self.id:02X}"


class EncoderReport(Slotted):
    """`24 …  19`: target and actual speed of each wheel (§12)."""

    __slots__ = _fields = ("targets", "actuals", "raw")
    _shown = ("targets", "actuals")

    def __init__(
        self, targets: tuple[int, ...], actuals: tuple[int, ...], raw: bytes = b""
    ) -> None:
        self.targets = targets
        self.actuals = actuals
        self.raw = raw


class Status(Slotted):
    """`FF …`: what reaches the host of the 12-byte status the reference firmware writes
    after each APP record (§13.1): `FF`, then up to two bytes (`FE` and the gyro's low
    byte on the compiled firmware). Not an error: a host lets it pass."""

    __slots__ = _fields = _shown = ("raw",)

    def __init__(self, raw: bytes) -> None:
        self.raw = raw


STATUS_MAX = 3
"""Bytes of a status burst at most."""

BoardEvent = Reply | EncoderReport | Status | Garbage | app.BoardEvent
ERRORS = (BadFrame, Garbage)
"""Event types that carry bytes which decoded to nothing."""


def system_mode_set(event: object) -> int | None:
    """The system_mode that an APP set frame or a UART2 settings frame sets, or None."""
    if isinstance(event, app.SetParam) and event.index == params.SYSTEM_MODE:
        return event.value
    if isinstance(event, SetSetting) and event.setting.param == params.SYSTEM_MODE:
        return event.value
    return None


# ---------------------------------------------------------------- encoding


def _check(name: str, value: int, maximum: int) -> None:
    if not -maximum <= value <= maximum:
        raise InvalidValue(f"{name} must be in −{maximum}…{maximum}, not {value}")


def _signs(values: tuple[int, ...], bits: tuple[int, ...]) -> int:
    return sum(1 << bit for value, bit in zip(values, bits, strict=True) if value < 0)


FIELD_BITS = (2, 1, 0)
MOTOR_BITS = {3: (2, 1, 0), 4: (2, 1, 0, 3)}


def velocity(
    drive: DriveType,
    x: int = 0,
    y: int = 0,
    z: int = 0,
    *,
    left: int = 0,
    right: int = 0,
    angle: int | None = None,
) -> VelocityFrame:
    """A velocity frame for `drive` (§9.1), checked: x, y, z on omni and mecanum
    (0–65535 each way), y and z as a duty of 0–1000 on diff, left and right duties on
    diff-gyro; `angle` (0.1°, signed) instead of z on all but diff-gyro."""
    if drive is DriveType.DIFF_GYRO:
        if x or y or z or angle is not None:
            raise InvalidValue(
                "a diff-gyro car takes left and right duties, not x, y, z or an angle"
            )
        _check("left", left, MAX_DUTY)
        _check("right", right, MAX_DUTY)
        return VelocityFrame(left, right, 0)
    if left or right:
        raise InvalidValue(f"a {drive.cli_name} car takes x, y, z, not left and right")
    limit = MAX_DUTY if drive.differential else U16
    if drive.differential and x:
        raise InvalidValue("a diff car has no x: its TX[3..4] is reserved")
    _check("x", x, limit)
    _check("y", y, limit)
    if angle is not None:
        if z:
            raise InvalidValue("give z or an angle, not both")
        _check("angle", angle, U16)
        return VelocityFrame(x, y, angle, angle=True)
    _check("z", z, limit)
    return VelocityFrame(x, y, z)


def encode(item: HostFrame | Reply | EncoderReport) -> bytes:
    """The wire bytes of a frame, reply or report; ValueError when a value is out of range."""
    if isinstance(item, VelocityFrame):
        for name, value in zip("abc", item.values, strict=True):
            _check(f"velocity field {name}", value, U16)
        bits = _signs(item.values, FIELD_BITS) | (ANGLE_BIT if item.angle else 0)
        return HEADER + bytes([VELOCITY]) + _u16s(item.values) + bytes([bits])
    if isinstance(item, MotorFrame):
        count = len(item.speeds)
        if count not in MOTOR_BITS:
            raise InvalidValue(f"a motor frame has 3 or 4 speeds, not {count}")
        for i, speed in enumerate(item.speeds):
            _check(f"motor {i + 1}", speed, U16)
        signs = bytes([_signs(item.speeds, MOTOR_BITS[count])])
        return HEADER + bytes([MOTORS]) + _u16s(item.speeds) + signs
    if isinstance(item, PositionFrame):
        values = (item.x, item.y, item.z)
        for name, value in zip("xyz", values, strict=True):
            _check(name, value, U16)
        return HEADER + bytes([POSITION]) + _u16s(values) + bytes([_signs(values, FIELD_BITS)])
    if isinstance(item, SetSetting):
        error = settings.value_error(item.setting, item.value)
        if error is not None:
            raise InvalidValue(error)
        return _settings_frame(item.setting.id, item.value)
    if isinstance(item, StoreFrame):
        return _settings_frame(settings.STORE_ID, settings.STORE_PREFIX << 16 | item.op.code)
    if isinstance(item, ReadFrame):
        return _settings_frame(item.read.ss, 0)
    if isinstance(item, Reply):
        signed = item.read is not None and item.read.signed
        return bytes([REPLY, item.id]) + item.value.to_bytes(4, "big", signed=signed)
    return encode_report(item.targets, item.actuals)


def encode_report(targets: tuple[int, ...], actuals: tuple[int, ...]) -> bytes:
    """An encoder report's bytes (§12): what `encode` gives for `EncoderReport(targets,
    actuals)`, without making one (a board sends one every 50 ms)."""
    speeds = [v for pair in zip(targets, actuals, strict=True) for v in pair]
    try:
        return struct.pack(f">B{len(speeds)}iB", REPORT, *speeds, REPORT_END)
    except struct.error:
        raise InvalidValue(
            f"a report's speeds are signed 32-bit: targets {targets}, actuals {actuals}"
        ) from None


def _u16s(values: tuple[int, ...]) -> bytes:
    return b"".join(abs(v).to_bytes(2, "big") for v in values)


def _settings_frame(ss: int, value: int) -> bytes:
    return HEADER + bytes([SETTINGS, 0x80, ss]) + value.to_bytes(4, "big") + b"\0"


def setting(name: str, value: int) -> SetSetting:
    """The frame that sets a setting by name (settings.lookup); the caller checks the
    value's range."""
    return SetSetting(settings.lookup(name), value)


def read(name: str) -> ReadFrame:
    """The read frame of a setting or value by name (settings.read_named)."""
    return ReadFrame(settings.read_named(name))


def store(name: str) -> StoreFrame:
    """`load`, `defaults` or `save`."""
    try:
        return StoreFrame(settings.STORE_BY_NAME[name])
    except KeyError:
        raise InvalidValue(
            f"unknown store operation {name!r}: use {', '.join(settings.STORE_BY_NAME)}"
        ) from None
