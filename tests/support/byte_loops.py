"""Byte-at-a-time decoders: each port's traffic read the way the firmware's interrupt
handler reads it, a byte a call, written plainly. They are the anchors of appmode's
decoders: three find the very events the decoders find (`check_same_events`; the APP
board stream's loop with its runs of garbage joined, as `appmode decode` writes them),
and the benchmark (bench/decoder.py) times each decoder against its loop. Also the
streams they are run on."""

from __future__ import annotations

import random
from collections.abc import Callable
from typing import Any, ClassVar

from appmode.protocol import app, app_decoders, control, control_decoders, settings
from appmode.protocol.app import Attitude, ParamsRecord, Velocity, encode
from appmode.protocol.app_decoders import BoardDecoder


def make_stream(size: int, noise: float, seed: int = 1) -> tuple[bytes, int]:
    """A board stream like the real one (A/B alternating, a C now and then), with noise."""
    rng = random.Random(seed)
    parts = []
    total = records = 0
    k = 0
    while total < size:
        if k % 50 == 49:
            record = encode(ParamsRecord((500, 10000, 20, 0, 10, 10, 10, 0, 1)))
        elif k % 2:
            record = encode(
                Attitude(
                    rng.randint(-9, 9),
                    rng.randint(-9, 9),
                    rng.randint(-179, 180),
                    rng.randint(0, 100),
                )
            )
        else:
            record = encode(
                Velocity(rng.randint(-600, 600), rng.randint(-600, 600), rng.randint(-600, 600), 0)
            )
        k += 1
        data = bytearray(record)
        for i in range(len(data)):
            if rng.random() < noise:
                data[i] = rng.randrange(256)
        parts.append(bytes(data))
        total += len(data)
        records += 1
    return b"".join(parts), records


class ByteAtATime:
    """The firmware's way: a handler called once per received byte (as the UART interrupt
    is), a small state machine, digits gathered into ints; records built like appmode's."""

    def __init__(self) -> None:
        self.in_record = False
        self.letter = 0
        self.fields: list[int] = []
        self.digits = bytearray()
        self.records: list[object] = []

    def feed(self, data: bytes) -> None:
        for byte in data:
            self.on_byte(byte)

    def on_byte(self, byte: int) -> None:
        if byte == 0x7B:  # '{'
            self.in_record, self.letter, self.fields = True, 0, []
            self.digits.clear()
        elif not self.in_record:
            return
        elif self.letter == 0:
            self.letter = byte
        elif byte == 0x3A or byte == 0x7D:  # ':' or '}'
            try:
                self.fields.append(int(self.digits))
            except ValueError:
                self.in_record = False
                return
            self.digits.clear()
            if byte == 0x7D:
                self.in_record = False
                self._record()
        elif byte == 0x2D or 0x30 <= byte <= 0x39:
            self.digits.append(byte)
        else:
            self.in_record = False

    def _record(self) -> None:
        fields = self.fields
        if self.letter == 0x41 and len(fields) == 4:
            x, y, z, extra = fields
            self.records.append(Velocity(x, y, z, extra))
        elif self.letter == 0x42 and len(fields) == 4:
            pitch, roll, yaw, battery = fields
            self.records.append(Attitude(pitch, roll, yaw, battery))
        elif self.letter == 0x43 and len(fields) == 9:
            self.records.append(ParamsRecord(tuple(fields)))


class SameEventsByteLoop:
    """A byte loop that finds the very events BoardDecoder finds (records, malformed
    records with their reasons, runs of other bytes), so that rendered alike they give
    byte-identical output (bench/decode_command.py checks): the anchor of `appmode
    decode`. A run of `{` is reported as BoardDecoder does, MAX_RUN at a time."""

    def __init__(self) -> None:
        self.events: list[object] = []
        self.garbage = bytearray()
        self.record: bytearray | None = None
        self.braces = 0  # `{` right after a lone `{`: a run
        self.closed: bytes | None = None  # a record up to its `}`: a `$` may follow

    def feed(self, data: bytes) -> None:
        for byte in data:
            if self.closed is not None:
                raw, self.closed = self.closed, None
                if byte == 0x24:
                    self._record(raw + b"$", True)
                    continue
                self._record(raw, False)
            record = self.record
            if record is None:
                if byte == 0x7B:
                    self._garbage()
                    self.record = bytearray(b"{")
                else:
                    self.garbage.append(byte)
                continue
            if byte == 0x7B:
                if len(record) == 1:
                    self.braces += 1
                else:
                    reason = app_decoders._interrupted("record", 1)
                    self.events.append(app.Malformed(bytes(record), reason))
                    self.record = bytearray(b"{")
                continue
            if self.braces:
                self._brace_run()
            record.append(byte)
            if byte == 0x7D:
                self.closed, self.record = bytes(record), None
            elif len(record) == app.MAX_RECORD:
                reason = f"over {app.MAX_RECORD} bytes without '}}'"
                self.events.append(app.Malformed(bytes(record), reason))
                self.record = None

    def flush(self) -> None:
        if self.closed is not None:
            self._record(self.closed, False)
        self._garbage()
        if self.record is not None:
            raw = b"{" * self.braces + bytes(self.record)
            self.events.append(app.Malformed(raw, "unterminated record at end of stream"))

    def _brace_run(self) -> None:
        while self.braces:
            count = min(self.braces, app.MAX_RUN)
            self.events.append(
                app.Malformed(b"{" * count, app_decoders._interrupted("record", count))
            )
            self.braces -= count

    def _garbage(self) -> None:
        if self.garbage:
            self.events.append(app.Garbage(bytes(self.garbage)))
            self.garbage.clear()

    def _record(self, raw: bytes, terminated: bool) -> None:
        self.events.append(app_decoders._parse_record(raw, raw[1 : raw.index(b"}")], terminated))


class HostByteAtATime:
    """The board's way of reading the APP port: a handler per byte; outside a frame a
    byte is one command; a frame is gathered to its `}` and then parsed."""

    def __init__(self) -> None:
        self.frame: bytearray | None = None
        self.events: list[object] = []

    def feed(self, data: bytes) -> None:
        for byte in data:
            frame = self.frame
            if byte == 0x7B:
                self.frame = bytearray(b"{")
            elif frame is not None:
                frame.append(byte)
                if byte == 0x7D:
                    self.events.append(app_decoders._parse_frame(bytes(frame)))
                    self.frame = None
                elif len(frame) > app.MAX_FRAME:
                    self.frame = None
            else:
                self.events.append(app_decoders.single_byte_events()[byte])


class _Gathering:
    """A byte loop that gathers `need` bytes into `buf`, then makes `events` of them."""

    def __init__(self) -> None:
        self.buf = bytearray()
        self.need = 0
        self.events: list[object] = []


MAX_RUN = control.MAX_RUN
OUTSIDE, FF_RUN = control_decoders._OUTSIDE, control_decoders._FF_RUN


class ControlBoardByteAtATime:
    """A host's way of reading UART2's board bytes one at a time, finding the very events
    ReplyDecoder (4 wheels) finds: `#` replies, encoder reports (a `24` whose 34th byte is
    `19`; else the bytes after it are read again), the reference firmware's status bursts
    (`FF` and up to two bytes that are no `FF`), runs of `FF`, and runs of other bytes,
    MAX_RUN at a time."""

    REPORT_LEN = 2 + 8 * 4

    def __init__(self) -> None:
        self.events: list[object] = []
        self.garbage = bytearray()
        self.gathering = bytearray()  # a reply, a report or a burst under way
        self.ffs = 0  # FF bytes in a row, not yet reported

    def feed(self, data: bytes) -> None:
        for byte in data:
            gathering = self.gathering
            if gathering:
                self._gather(gathering, byte)
            elif self.ffs:
                self._after_ff(byte)
            elif byte == 0xFF:
                self._garbage()
                self.ffs = 1
            elif byte == control.REPLY:
                self._garbage()
                gathering.append(byte)
            elif byte == control.REPORT:
                gathering.append(byte)
            else:
                self._outside(byte)

    def _gather(self, gathering: bytearray, byte: int) -> None:
        first = gathering[0]
        if first == 0xFF:  # a status burst
            if byte == 0xFF:
                self._event(control.Status(bytes(gathering)))
                self.ffs = 1
                return
            gathering.append(byte)
            if len(gathering) == control.STATUS_MAX:
                self._event(control.Status(bytes(gathering)))
            return
        gathering.append(byte)
        if first == control.REPLY and len(gathering) == control.REPLY_LEN:
            read = settings.READ_BY_REPLY.get(gathering[1])
            signed = read is not None and read.signed
            value = int.from_bytes(gathering[2:], "big", signed=signed)
            self._event(control.Reply(gathering[1], value, bytes(gathering)))
        elif first == control.REPORT and len(gathering) == self.REPORT_LEN:
            raw = bytes(gathering)
            gathering.clear()
            if byte != control.REPORT_END:  # no report: its 24 is a byte outside, and
                self._outside(raw[0])  # what follows is read again
                self.feed(raw[1:])
                return
            self._garbage()
            values = [int.from_bytes(raw[i : i + 4], "big", signed=True) for i in range(1, 33, 4)]
            self.events.append(control.EncoderReport(tuple(values[0::2]), tuple(values[1::2]), raw))

    def _after_ff(self, byte: int) -> None:
        if byte == 0xFF:
            self.ffs += 1
            if self.ffs == MAX_RUN + 2:  # as the decoder: MAX_RUN of them, one kept
                self.events.append(control.Garbage(b"\xff" * MAX_RUN, FF_RUN))
                self.ffs -= MAX_RUN
            return
        if self.ffs > 1:
            self.events.append(control.Garbage(b"\xff" * (self.ffs - 1), FF_RUN))
        self.ffs = 0
        self.gathering += bytes((0xFF, byte))

    def _event(self, event: object) -> None:
        self.events.append(event)
        self.gathering.clear()

    def _outside(self, byte: int) -> None:
        self.garbage.append(byte)
        if len(self.garbage) == MAX_RUN:
            self._garbage()

    def _garbage(self) -> None:
        if self.garbage:
            self.events.append(control.Garbage(bytes(self.garbage), OUTSIDE))
            self.garbage.clear()

    def flush(self) -> None:
        """What the stream ends with, reported as ReplyDecoder.flush does."""
        if self.ffs:
            if self.ffs > 1:
                self.events.append(control.Garbage(b"\xff" * (self.ffs - 1), FF_RUN))
            self.events.append(control.Status(b"\xff"))
        elif self.gathering[:1] == b"\xff":
            self.events.append(control.Status(bytes(self.gathering)))
        elif self.garbage or self.gathering:
            raw = bytes(self.garbage + self.gathering)
            self.events.append(control.Garbage(raw, "truncated reply or report at end of stream"))
        self.garbage.clear()
        self.gathering.clear()


class ControlHostByteAtATime(_Gathering):
    """The board's way of reading UART2 frames: sync on FF FE, the mode byte gives the
    length, the frame is gathered and then parsed (a 3-motor omni car)."""

    LENGTHS: ClassVar[dict[int, int]] = dict.fromkeys(control.MODES, control.FRAME)

    def feed(self, data: bytes) -> None:
        for byte in data:
            buf = self.buf
            if self.need:
                buf.append(byte)
                if len(buf) == self.need:
                    self.events.append(control_decoders._parse(bytes(buf), 3))
                    self.need = 0
                    buf.clear()
            elif len(buf) == 2:
                length = self.LENGTHS.get(byte)
                buf.append(byte)
                if length is None:
                    buf.clear()
                else:
                    self.need = length
            elif len(buf) == 1:
                if byte == 0xFE:
                    buf.append(byte)
                elif byte != 0xFF:
                    buf.clear()
            elif byte == 0xFF:
                buf.append(byte)


def _noisy(parts: list[bytes], rng: random.Random, noise: float) -> bytes:
    data = bytearray(b"".join(parts))
    for i in range(len(data)):
        if rng.random() < noise:
            data[i] = rng.randrange(256)
    return bytes(data)


def streams(size: int) -> dict[str, bytes]:
    """Each port's traffic in each direction (1 % noise), and garbage of every kind."""
    rng = random.Random(7)
    host = [b"A", b"B", b"E", b"Z", b"J", b"{Q:P}", b"{1:100}", b"{7:50}", b"{Q:W}"]
    replies = [control.encode(control.Reply(0x41, rng.randrange(1000))) for _ in range(50)]
    reports = [
        control.encode(control.EncoderReport((1, -2, 3, -4), (5, -6, 7, -8))) for _ in range(50)
    ]
    frames = [
        control.encode(control.VelocityFrame(rng.randrange(500), rng.randrange(500), 0))
        for _ in range(50)
    ] + [control.encode(control.read("speed_a"))]
    return {
        "APP board stream": make_stream(size, 0.01)[0],
        "APP host stream": _noisy([rng.choice(host) for _ in range(size // 4)], rng, 0.01),
        "UART2 replies/reports": _noisy(
            [rng.choice(replies + reports) for _ in range(size // 20)], rng, 0.01
        ),
        "UART2 frames": _noisy([rng.choice(frames) for _ in range(size // 10)], rng, 0.01),
        "random bytes": random.Random(3).randbytes(size),
        **{f"only {b!r}": b * size for b in (b"{", b"}", b"$", b"#", b"\xff", b"\xfe", b"7")},
        "'{A' and digits": b"{A" + b"1" * (size - 2),
    }


DECODERS: dict[str, tuple[Callable[[], Any], Callable[[], Any]]] = {
    "APP board decoder": (BoardDecoder, SameEventsByteLoop),
    "APP host decoder": (app_decoders.HostDecoder, HostByteAtATime),
    "UART2 board decoder": (control_decoders.ReplyDecoder, ControlBoardByteAtATime),
    "UART2 host decoder": (control_decoders.FrameDecoder, ControlHostByteAtATime),
}


SAME_EVENTS = ("UART2 board decoder",)
"""The decoders whose byte loops find the very events they find, run for run (checked on
every input; the APP board decoder's loop finds them with runs of garbage joined, which
tests/protocol/test_byte_loops.py checks in `appmode decode`'s output)."""


def check_same_events(name: str, data: bytes, chunk: int) -> None:
    """Raise unless decoder `name` and its byte loop find the same events in `data`."""
    ours, loop = DECODERS[name]
    decoder, reader = ours(), loop()
    found = [e for i in range(0, len(data), chunk) for e in decoder.feed(data[i : i + chunk])]
    found += decoder.flush()
    reader.feed(data)
    reader.flush()
    same = len(found) == len(reader.events) and all(
        type(a) is type(b) and a == b and a.raw == b.raw
        for a, b in zip(found, reader.events, strict=False)
    )
    if not same:
        raise AssertionError(f"{name}: its byte loop finds other events than it does")
