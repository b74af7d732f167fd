"""What a port carries, judged on the bytes alone (no I/O): `Heard` counts what came at
one rate — APP records and their rhythm, control-port traffic, a chassis port's status
frames, text — and `judge` says what the rates heard so far show: a car's APP port, its
control port, a WHEELTEC chassis port, a port that is silent, one that talks text, or
noise; or that the next rate is worth a listen. The
firmware is told from what it sends, against the shipped profiles (`identify`)."""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from typing import Literal

from appmode.board.profiles import Profile, profile_named
from appmode.host import identify
from appmode.line.wire import CHASSIS_BAUD, UART2_BAUD
from appmode.protocol import app, app_decoders, chassis, control, control_decoders
from appmode.protocol.escaping import text_part

ENOUGH = 3
"""Records (or control-port bursts) that show what a port carries."""
STARTED = 8
"""Records after a board's start-up text that give its period."""
STATUS_RATE = 40
"""Status bursts a second at most from a control port that sends only those: the
reference firmware sends one after each record (about 17 a second); a device that
streams `00 FF` without pause makes thousands."""
SAMPLE = 48
"""Bytes of text kept to show what a port that is not a board sent."""
BURST = 0.3
"""Records closer than this fraction of the mean period came in a burst."""
HELD = 2.0
"""Records further apart than this many mean periods: one was held up on the way."""
TEXT = 4096
"""Bytes of text kept for firmware identification (a start-up text is about 400)."""


@dataclass
class Heard:
    """What came at one rate."""

    baud: int
    seconds: float = 0.0
    size: int = 0
    record_times: list[float] = field(default_factory=list)
    record_sizes: list[int] = field(default_factory=list)
    uart2_bytes: int = 0
    uart2_bursts: int = 0
    reports: int = 0
    outside: int = 0
    """Bytes decoded outside records."""
    printable: int = 0
    sample: bytearray = field(default_factory=bytearray)
    shapes: list[tuple[str, tuple[int, ...]]] = field(default_factory=list)
    """The first records (letter, values), whatever their field counts."""
    said: bytearray = field(default_factory=bytearray)
    """The first text outside records (a start-up text, a `##$` reply)."""
    statuses: int = 0
    """A chassis port's status frames (§15)."""
    status_bytes: int = 0
    sideways: bool = False
    """A status frame showed sideways motion: only a mecanum car's can."""
    booting: bool = False
    """A status frame had Flag_Stop set."""

    @property
    def sent(self) -> identify.Sent:
        """What firmware identification reads of it."""
        return identify.Sent(self.shapes, self.period_ms, bytes(self.said), self.steady)

    @property
    def steady(self) -> bool:
        """No two records came much closer than the mean period, or much further apart (a
        burst of records held up and delivered at once, or one held up: the measured
        period is the host's, not the board's)."""
        times, period = self.record_times, self.period_ms
        if period is None:
            return False
        low, high = BURST * period / 1000, HELD * period / 1000
        return all(low <= b - a <= high for a, b in itertools.pairwise(times))

    @property
    def records(self) -> int:
        return len(self.record_times)

    @property
    def carries_app(self) -> bool:
        """APP records: at least ENOUGH, and more of the bytes than what is neither a
        record nor text (a board's start-up text, a record caught half way)."""
        noise = self.size - sum(self.record_sizes) - self.printable
        return self.records >= ENOUGH and sum(self.record_sizes) >= noise

    @property
    def carries_uart2(self) -> bool:
        """Control-port traffic: encoder reports, or status bursts in a firmware's rhythm
        (a few a second, not a stream of them), making up most of the bytes."""
        if self.uart2_bursts < ENOUGH or 10 * self.uart2_bytes < 8 * self.size:
            return False
        return self.reports > 0 or self.uart2_bursts <= STATUS_RATE * max(self.seconds, 0.1)

    @property
    def carries_chassis(self) -> bool:
        """A chassis port's status frames, making up most of the bytes."""
        return self.statuses >= ENOUGH and 10 * self.status_bytes >= 8 * self.size

    @property
    def text(self) -> bool:
        """Mostly printable text outside records: a program that talks, or a board's
        start-up text, not a board at a wrong rate (whose bytes are mostly not text)."""
        return self.outside >= 8 and 10 * self.printable >= 9 * self.outside

    @property
    def period_ms(self) -> float | None:
        """The mean time from one record to the next."""
        if self.records < ENOUGH:
            return None
        return 1000 * (self.record_times[-1] - self.record_times[0]) / (self.records - 1)

    def feed(
        self,
        data: bytes,
        at: float,
        app_decoder: app_decoders.BoardDecoder,
        uart2_decoder: control_decoders.ReplyDecoder,
        status_decoder: chassis.StatusDecoder,
    ) -> None:
        """Count what `data`, come at `at` s, holds."""
        self.size += len(data)
        for status in status_decoder.feed(data):
            if isinstance(status, chassis.Status):
                self.statuses += 1
                self.status_bytes += len(status.raw)
                self.sideways |= status.vy != 0
                self.booting |= bool(status.flag_stop)
        for event in app_decoder.feed(data):
            if isinstance(event, app.RECORDS) and event.terminated:
                self.record_times.append(at)
                self.record_sizes.append(len(event.raw))
                if len(self.shapes) < identify.SHOWN:
                    self.shapes.append((event.letter, event.values))
            elif not isinstance(event, app.RECORDS):
                self.outside += len(event.raw)
                printable = text_part(event.raw)
                self.printable += len(printable)
                if len(printable) == len(event.raw):
                    self.sample += printable[: SAMPLE - len(self.sample)]
                    self.said += printable[: TEXT - len(self.said)]
        for burst in uart2_decoder.feed(data):
            if isinstance(burst, (control.EncoderReport, control.Status, control.Reply)):
                self.uart2_bursts += 1
                self.uart2_bytes += len(burst.raw)
                self.reports += isinstance(burst, control.EncoderReport)


Kind = Literal["app", "uart2", "chassis", "silent", "text", "noise"]


@dataclass(frozen=True, slots=True)
class Verdict:
    """What a port is, and the rate whose bytes showed it (none for a silent port, or
    noise at every rate)."""

    kind: Kind
    heard: Heard | None


def judge(heard: list[Heard], fixed: bool, more: bool) -> Verdict | None:
    """What the rates heard so far (the newest last) show, or None while listening at
    the next rate is worth it (`more`: a rate is left). `fixed`: the link has no line
    rate of its own (TCP, sim://, Bluetooth), so the first is the only one."""
    one = heard[-1]
    if one.carries_app:
        return Verdict("app", one)
    if one.carries_uart2 and (one.baud == UART2_BAUD or fixed):
        return Verdict("uart2", one)
    if one.carries_chassis and (one.baud == CHASSIS_BAUD or fixed):
        return Verdict("chassis", one)
    settled = (one.text and not one.records) or (len(heard) == 2 and not any(h.size for h in heard))
    # text that reads as text: the rate is right, and no board talks so; or silent at the
    # APP port's rate and at the control port's
    if more and not settled:
        return None
    uart2 = next((h for h in heard if h.carries_uart2), None)  # at a rate of its own
    if uart2 is not None and uart2.baud != UART2_BAUD:
        # its bursts came at the control port's rate too, if fewer in a loaded moment: a
        # link with no rate of its own (a pty), read at any; the control port's it is
        uart2 = next((h for h in heard if h.baud == UART2_BAUD and h.uart2_bursts), uart2)
    if uart2 is not None:
        return Verdict("uart2", uart2)
    if not any(h.size for h in heard):
        return Verdict("silent", None)
    talk = next((h for h in heard if h.text), None)
    return Verdict("text", talk) if talk is not None else Verdict("noise", None)


def firmware(sent: identify.Sent) -> tuple[Profile | None, identify.Judgement]:
    """The shipped profile that fits what was sent (None when none does), and the
    nearest one's judgement."""
    found, nearest = identify.best(sent)
    return (profile_named(found.name) if found else None), nearest
