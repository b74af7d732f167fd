"""The control port's decoders, with no I/O (docs/protocol.md §8–§13).

`FrameDecoder(drive)` turns the host→board stream into frames, `ReplyDecoder(wheels)` the
board→host stream into replies and reports (and APP records while APP mode is on). Like
the APP decoders they never raise on bytes, hold a bounded buffer, keep a read index,
resynchronise at the next `FF FE`, and give every byte to exactly one event's `raw`,
whatever the split into `feed` calls.
"""

from __future__ import annotations

import functools
import re

from appmode.protocol import app, app_decoders, settings
from appmode.protocol.bulk import linear
from appmode.protocol.control import (
    ANGLE_BIT,
    FIELD_BITS,
    FRAME,
    HEADER,
    MAX_RUN,
    MOTOR_BITS,
    MOTOR_FRAME_4,
    MOTORS,
    POSITION,
    REPLY,
    REPLY_LEN,
    REPORT,
    REPORT_END,
    SETTINGS,
    STATUS_MAX,
    U16,
    VELOCITY,
    BadFrame,
    BoardEvent,
    EncoderReport,
    Garbage,
    HostEvent,
    MotorFrame,
    PositionFrame,
    ReadFrame,
    Reply,
    SetSetting,
    Status,
    StoreFrame,
    VelocityFrame,
    motor_count,
)
from appmode.protocol.params import DriveType


def _signed(raw: bytes, at: int, bits: int, bit: int) -> int:
    value = raw[at] << 8 | raw[at + 1]
    return -value if bits >> bit & 1 else value


def _parse(raw: bytes, motors: int) -> HostEvent:
    mode, bits = raw[2], raw[len(raw) - 1]
    if mode == VELOCITY:
        a, b, c = (_signed(raw, 3 + 2 * i, bits, bit) for i, bit in enumerate(FIELD_BITS))
        return VelocityFrame(a, b, c, bool(bits & ANGLE_BIT), raw)
    if mode == MOTORS:
        order = MOTOR_BITS[motors]
        speeds = tuple(_signed(raw, 3 + 2 * i, bits, bit) for i, bit in enumerate(order))
        return MotorFrame(speeds, raw)
    if mode == POSITION:
        x, y, z = (_signed(raw, 3 + 2 * i, bits, bit) for i, bit in enumerate(FIELD_BITS))
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


class FrameDecoder:
    """host→board bytes → frames (§8.2). `drive` fixes a mode-02 frame's length."""

    LIMIT = max(MOTOR_FRAME_4, MAX_RUN)
    """Most bytes ever held between calls."""

    def __init__(self, drive: DriveType = DriveType.OMNI, app_mode: bool = False) -> None:
        self._buf = b""
        self.drive = drive
        self._app: app_decoders.HostDecoder | None = (
            app_decoders.HostDecoder() if app_mode else None
        )

    @property
    def app_mode(self) -> bool:
        return self._app is not None

    def set_app_mode(self, on: bool) -> list[HostEvent | app.HostEvent]:
        """Switch between binary frames and APP commands (§12); what was held is reported."""
        if on == self.app_mode:
            return []
        out = self.flush()
        self._app = app_decoders.HostDecoder() if on else None
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


class ReplyDecoder:
    """board→host bytes → `#` replies, encoder reports (§11, §12) and the reference
    firmware's status bursts (§13.1); while `app_mode`
    (system_mode bit 7) is on, APP records (§3) instead. `wheels` (3 or 4) fixes a
    report's length; None tells it by where the report's `19` is: a 3-wheel report's
    end falls where a 4-wheel report holds wheel D's top byte, never 19 for a speed."""

    def __init__(self, wheels: int | None = 4, app_mode: bool = False) -> None:
        self._buf = b""
        self.wheels = wheels
        self.limit = max(2 + 8 * (wheels or 4), MAX_RUN, app_decoders.BoardDecoder.LIMIT)
        """Most bytes ever held between calls."""
        self._app: app_decoders.BoardDecoder | None = (
            app_decoders.BoardDecoder() if app_mode else None
        )

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
        self._app = app_decoders.BoardDecoder() if on else None
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
