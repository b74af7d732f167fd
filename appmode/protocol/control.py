"""The control port's binary grammar both ways, with no I/O (docs/protocol.md §8–§12).

`encode(item)` turns a host frame, a `#` reply or an encoder report into bytes, with
range checks that name the field. `HostDecoder(drive)` turns the host→board stream into
frames, `BoardDecoder(wheels)` the board→host stream into replies and reports (and APP
records while APP mode is on). Like the APP decoders they never raise on bytes, hold a
bounded buffer, keep a read index, resynchronise at the next `FF FE`, and give every byte
to exactly one event's `raw`, whatever the split into `feed` calls.
"""

from __future__ import annotations

import functools
import re
from dataclasses import dataclass, field

from appmode.errors import InvalidValue
from appmode.protocol import app, params, settings
from appmode.protocol.bulk import linear
from appmode.protocol.params import DriveType
from appmode.protocol.settings import Read, Setting, StoreOp

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


def _raw() -> bytes:
    return field(default=b"", compare=False, repr=False)


def motor_count(drive: DriveType) -> int:
    """Motors of a drive type: 3 on an omni, 4 on the others (§9.2)."""
    return 3 if drive is DriveType.OMNI else 4


# ---------------------------------------------------------------- host → board frames


@dataclass(frozen=True, slots=True)
class VelocityFrame:
    """Mode `01`: three signed fields and angle mode (§9.1). What the fields mean depends
    on the drive type: x, y, z (omni, mecanum); reserved, y, z (diff); left, right,
    reserved (diff-gyro). With `angle`, the third field is an angle in 0.1°."""

    a: int
    b: int
    c: int
    angle: bool = False
    raw: bytes = _raw()

    @property
    def values(self) -> tuple[int, int, int]:
        return (self.a, self.b, self.c)


@dataclass(frozen=True, slots=True)
class MotorFrame:
    """Mode `02`: a signed speed for each motor, 3 or 4 (§9.2)."""

    speeds: tuple[int, ...]
    raw: bytes = _raw()

    @property
    def values(self) -> tuple[int, ...]:
        return self.speeds


@dataclass(frozen=True, slots=True)
class PositionFrame:
    """Mode `03`: signed x, y, z displacements (§9.3)."""

    x: int
    y: int
    z: int
    raw: bytes = _raw()


@dataclass(frozen=True, slots=True)
class SetSetting:
    """Mode `80`, SS 01–0A: set a setting (always within range when decoded)."""

    setting: Setting
    value: int
    raw: bytes = _raw()


@dataclass(frozen=True, slots=True)
class StoreFrame:
    """Mode `80`, SS 00: load, defaults or save (§10)."""

    op: StoreOp
    raw: bytes = _raw()


@dataclass(frozen=True, slots=True)
class ReadFrame:
    """Mode `80`, a read's SS (§11): ask for a `#` reply."""

    read: Read
    raw: bytes = _raw()


@dataclass(frozen=True, slots=True)
class BadFrame:
    """A whole frame the board discards: a value out of range, an unknown SS."""

    raw: bytes
    reason: str


@dataclass(slots=True)
class Garbage:
    """Bytes outside any frame or reply, an unknown mode's header, or a truncated frame."""

    raw: bytes
    reason: str = "bytes outside any frame"


HostFrame = VelocityFrame | MotorFrame | PositionFrame | SetSetting | StoreFrame | ReadFrame
HostEvent = HostFrame | BadFrame | Garbage

# ---------------------------------------------------------------- board → host
# Not frozen, like the APP records and for the same reason (protocol/app.py): treat them
# as immutable all the same.


@dataclass(slots=True)
class Reply:
    """`23 NN b3 b2 b1 b0`: the answer to a read (§11)."""

    id: int
    value: int
    raw: bytes = _raw()

    @property
    def read(self) -> Read | None:
        return settings.READ_BY_REPLY.get(self.id)

    @property
    def name(self) -> str:
        read = self.read
        return read.name if read else f"0x{self.id:02X}"


@dataclass(slots=True)
class EncoderReport:
    """`24 …  19`: target and actual speed of each wheel (§12)."""

    targets: tuple[int, ...]
    actuals: tuple[int, ...]
    raw: bytes = _raw()


@dataclass(slots=True)
class Status:
    """`FF …`: what reaches the host of the 12-byte status the reference firmware writes
    after each APP record (§13.1): `FF`, then up to two bytes (`FE` and the gyro's low
    byte on the compiled firmware). Not an error: a host lets it pass."""

    raw: bytes


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


_FIELD_BITS = (2, 1, 0)
_MOTOR_BITS = {3: (2, 1, 0), 4: (2, 1, 0, 3)}


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
        bits = _signs(item.values, _FIELD_BITS) | (ANGLE_BIT if item.angle else 0)
        return HEADER + bytes([VELOCITY]) + _u16s(item.values) + bytes([bits])
    if isinstance(item, MotorFrame):
        count = len(item.speeds)
        if count not in _MOTOR_BITS:
            raise InvalidValue(f"a motor frame has 3 or 4 speeds, not {count}")
        for i, speed in enumerate(item.speeds):
            _check(f"motor {i + 1}", speed, U16)
        signs = bytes([_signs(item.speeds, _MOTOR_BITS[count])])
        return HEADER + bytes([MOTORS]) + _u16s(item.speeds) + signs
    if isinstance(item, PositionFrame):
        values = (item.x, item.y, item.z)
        for name, value in zip("xyz", values, strict=True):
            _check(name, value, U16)
        return HEADER + bytes([POSITION]) + _u16s(values) + bytes([_signs(values, _FIELD_BITS)])
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
    out = bytearray([REPORT])
    for target, actual in zip(item.targets, item.actuals, strict=True):
        out += target.to_bytes(4, "big", signed=True) + actual.to_bytes(4, "big", signed=True)
    out.append(REPORT_END)
    return bytes(out)


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


# ---------------------------------------------------------------- host stream decoder


def _signed(raw: bytes, at: int, bits: int, bit: int) -> int:
    value = raw[at] << 8 | raw[at + 1]
    return -value if bits >> bit & 1 else value


def _parse(raw: bytes, motors: int) -> HostEvent:
    mode, bits = raw[2], raw[len(raw) - 1]
    if mode == VELOCITY:
        a, b, c = (_signed(raw, 3 + 2 * i, bits, bit) for i, bit in enumerate(_FIELD_BITS))
        return VelocityFrame(a, b, c, bool(bits & ANGLE_BIT), raw)
    if mode == MOTORS:
        order = _MOTOR_BITS[motors]
        speeds = tuple(_signed(raw, 3 + 2 * i, bits, bit) for i, bit in enumerate(order))
        return MotorFrame(speeds, raw)
    if mode == POSITION:
        x, y, z = (_signed(raw, 3 + 2 * i, bits, bit) for i, bit in enumerate(_FIELD_BITS))
        return PositionFrame(x, y, z, raw)
    if raw[3] != 0x80:
        return BadFrame(raw, f"settings frame with TX[3] = {raw[3]:02X}, expected 80")
    ss = raw[4]
    value = int.from_bytes(raw[5:9], "big")
    setting = settings.BY_ID.get(ss)
    if setting is not None:
        error = settings.value_error(setting, value)
        return BadFrame(raw, error) if error else SetSetting(setting, value, raw)
    if ss == settings.STORE_ID:
        op = settings.STORE_BY_CODE.get(value & U16)
        if value >> 16 != settings.STORE_PREFIX or op is None:
            return BadFrame(
                raw, f"load/save frame with value {value:08X}: expected 80000001–80000003"
            )
        return StoreFrame(op, raw)
    read = settings.READ_BY_SS.get(ss)
    if read is not None:
        return ReadFrame(read, raw)
    return BadFrame(raw, f"unknown setting or read SS {ss:02X}")


class HostDecoder:
    """host→board bytes → frames (§8.2). `drive` fixes a mode-02 frame's length."""

    LIMIT = max(MOTOR_FRAME_4, MAX_RUN)
    """Most bytes ever held between calls."""

    def __init__(self, drive: DriveType = DriveType.OMNI, app_mode: bool = False) -> None:
        self._buf = b""
        self.drive = drive
        self._app: app.HostDecoder | None = app.HostDecoder() if app_mode else None

    @property
    def app_mode(self) -> bool:
        return self._app is not None

    def set_app_mode(self, on: bool) -> list[HostEvent | app.HostEvent]:
        """Switch between binary frames and APP commands (§12); what was held is reported."""
        if on == self.app_mode:
            return []
        out = self.flush()
        self._app = app.HostDecoder() if on else None
        return out

    @property
    def drive(self) -> DriveType:
        return self._drive

    @drive.setter
    def drive(self, drive: DriveType) -> None:
        self._drive = drive
        self._motors = motor_count(drive)
        self._lengths = {
            VELOCITY: FRAME,
            MOTORS: MOTOR_FRAME_4 if self._motors == 4 else FRAME,
            POSITION: FRAME,
            SETTINGS: FRAME,
        }

    @property
    def buffered(self) -> int:
        return len(self._buf) + (self._app.buffered if self._app else 0)

    @linear
    def feed(self, data: bytes) -> list[HostEvent | app.HostEvent]:
        if self._app is not None:
            return list(self._app.feed(data))
        buf = self._buf + data if self._buf else bytes(data)
        out: list[HostEvent | app.HostEvent] = []
        pos, n = 0, len(buf)
        lengths = self._lengths
        while pos < n:
            if buf[pos] != 0xFF or (pos + 1 < n and buf[pos + 1] != 0xFE):
                start = buf.find(HEADER, pos + 1, min(n, pos + MAX_RUN + 1))
                if start < 0:
                    if n - pos <= MAX_RUN:
                        break  # the run may go on (or end in a header's FF): hold it
                    start = pos + MAX_RUN
                out.append(Garbage(buf[pos:start]))
                pos = start
                continue
            if n - pos < 3:
                break
            length = lengths.get(buf[pos + 2])
            if length is None:
                out.append(Garbage(buf[pos : pos + 3], f"unknown mode {buf[pos + 2]:02X}"))
                pos += 3
                continue
            if n - pos < length:
                break
            out.append(_parse(buf[pos : pos + length], self._motors))
            pos += length
        self._buf = buf[pos:]
        return out

    def rest(self) -> bytes:
        """Zeros completing the frame being received (its mode `01` after a bare header),
        so that what is sent next is read from its start; b"" when no frame is open."""
        buf = self._buf
        if self._app is not None or not buf.startswith(HEADER):
            return b""
        if len(buf) == len(HEADER):
            return bytes([VELOCITY]) + bytes(FRAME - len(HEADER) - 1)
        return bytes(self._lengths[buf[2]] - len(buf))

    def flush(self) -> list[HostEvent | app.HostEvent]:
        """Report what is held at the end of the stream (a truncated frame)."""
        if self._app is not None:
            return list(self._app.flush())
        raw, self._buf = self._buf, b""
        if not raw:
            return []
        if raw.startswith(HEADER) or raw == b"\xff":
            return [Garbage(raw, "truncated frame at end of stream")]
        return [Garbage(raw)]


# ---------------------------------------------------------------- board stream decoder

_REPORT_3, _REPORT_4 = 2 + 8 * 3, 2 + 8 * 4


def _report_length(buf: bytes, pos: int) -> int | None:
    """The length of the report at `pos` when its wheel count is not given: 3 wheels if
    its 26th byte is `19`, else 4; None while too few bytes tell."""
    if len(buf) - pos < _REPORT_3:
        return None
    return _REPORT_3 if buf[pos + _REPORT_3 - 1] == REPORT_END else _REPORT_4


_FFS = re.compile(rb"\xff{2,%d}" % (MAX_RUN + 1))
_OUTSIDE = "bytes outside any reply or report"
_FF_RUN = "a run of FF, no status burst (an idle line read at a wrong baud rate)"


@functools.cache
def _starts(wheels: int | None) -> re.Pattern[bytes]:
    """Where a run of bytes outside any reply or report ends: a reply's or a status
    burst's first byte, or a report's whose `19` is in place or has yet to come (`wait`)
    (found in C, not byte by byte: a flood of `24` is one run, not a report per byte)."""
    lengths = [2 + 8 * w for w in ((wheels,) if wheels else (3, 4))]
    ends = b"|".join(rb"(?=.{%d}\x19)" % (length - 2) for length in lengths)
    room = max(lengths) - 1
    return re.compile(rb"[\x23\xff]|\x24(?:%s|(?P<wait>)(?!.{%d}))" % (ends, room), re.DOTALL)


class BoardDecoder:
    """board→host bytes → `#` replies, encoder reports (§11, §12) and the reference
    firmware's status bursts (§13.1); while `app_mode`
    (system_mode bit 7) is on, APP records (§3) instead. `wheels` (3 or 4) fixes a
    report's length; None tells it by where the report's `19` is: a 3-wheel report's
    end falls where a 4-wheel report holds wheel D's top byte, never 19 for a speed."""

    def __init__(self, wheels: int | None = 4, app_mode: bool = False) -> None:
        self._buf = b""
        self.wheels = wheels
        self.limit = max(2 + 8 * (wheels or 4), MAX_RUN, app.BoardDecoder.LIMIT)
        """Most bytes ever held between calls."""
        self._app: app.BoardDecoder | None = app.BoardDecoder() if app_mode else None

    @property
    def app_mode(self) -> bool:
        return self._app is not None

    @property
    def wheels(self) -> int | None:
        return self._wheels

    @wheels.setter
    def wheels(self, wheels: int | None) -> None:
        self._wheels = wheels
        self._start = _starts(wheels)

    @property
    def buffered(self) -> int:
        return len(self._buf) + (self._app.buffered if self._app else 0)

    def set_app_mode(self, on: bool) -> list[BoardEvent]:
        """Switch between binary replies and APP records; what was held is reported."""
        if on == self.app_mode:
            return []
        out = self.flush()
        self._app = app.BoardDecoder() if on else None
        return out

    @linear
    def feed(self, data: bytes) -> list[BoardEvent]:
        if self._app is not None:
            return list(self._app.feed(data))
        buf = self._buf + data if self._buf else bytes(data)
        out: list[BoardEvent] = []
        pos, n = 0, len(buf)
        fixed = None if self.wheels is None else 2 + 8 * self.wheels
        while pos < n:
            byte = buf[pos]
            if byte == REPLY:
                if n - pos < REPLY_LEN:
                    break
                raw = buf[pos : pos + REPLY_LEN]
                read = settings.READ_BY_REPLY.get(raw[1])
                signed = read is not None and read.signed
                out.append(Reply(raw[1], int.from_bytes(raw[2:], "big", signed=signed), raw))
                pos += REPLY_LEN
                continue
            if byte == HEADER[0] and pos + 1 < n and buf[pos + 1] == HEADER[0]:
                run = _FFS.match(buf, pos)
                assert run is not None
                if run.end() - pos <= MAX_RUN and run.end() == n:
                    break  # the run may go on: hold it
                end = run.end() - 1  # its last FF may start a burst
                out.append(Garbage(buf[pos:end], _FF_RUN))
                pos = end
                continue
            if byte == HEADER[0]:
                end = buf.find(HEADER[:1], pos + 1, pos + STATUS_MAX)
                if end < 0:
                    if n - pos < STATUS_MAX:
                        break  # the burst may go on: hold it
                    end = pos + STATUS_MAX
                out.append(Status(buf[pos:end]))
                pos = end
                continue
            if byte == REPORT:
                report_len = fixed or _report_length(buf, pos)
                if report_len is None or n - pos < report_len:
                    break
                raw = buf[pos : pos + report_len]
                if raw[-1] == REPORT_END:
                    values = [
                        int.from_bytes(raw[i : i + 4], "big", signed=True)
                        for i in range(1, report_len - 1, 4)
                    ]
                    out.append(EncoderReport(tuple(values[0::2]), tuple(values[1::2]), raw))
                    pos += report_len
                    continue
            start = self._start.search(buf, pos + 1)
            end = n if start is None else start.start()
            while end - pos > MAX_RUN:  # runs of MAX_RUN bytes up to the next start
                out.append(Garbage(buf[pos : pos + MAX_RUN], _OUTSIDE))
                pos += MAX_RUN
            if start is not None and start.group("wait") is not None:
                break  # whether the run ends at this `24` is not known yet: hold it
            if end == n and n - pos < MAX_RUN:
                break  # the run may go on: hold it
            out.append(Garbage(buf[pos:end], _OUTSIDE))
            pos = end
        self._buf = buf[pos:]
        return out

    def flush(self) -> list[BoardEvent]:
        """Report what is held at the end of the stream."""
        if self._app is not None:
            return list(self._app.flush())
        raw, self._buf = self._buf, b""
        if raw.startswith(b"\xff\xff"):  # a run of FF, held whole
            return [Garbage(raw[:-1], _FF_RUN), Status(raw[-1:])]
        if raw.startswith(HEADER[:1]):
            return [Status(raw)]
        return [Garbage(raw, "truncated reply or report at end of stream")] if raw else []
