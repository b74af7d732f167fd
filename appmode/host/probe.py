"""What answers on a port, found by listening: `appmode doctor`'s probe.

A port is listened to at 9600 bps for APP records; when it carries bytes that are not
records (a wrong rate reads as such: `line/uart.py`) the other common rates are tried,
and 115200 for the control port's traffic (UART2: encoder reports, the reference
firmware's status bursts). The only bytes ever sent are `{Q:P}` frames to a port that
streams APP records, to read its parameters: never a drive letter, and nothing to a
silent port, where a control port would count them toward its take-over (§8.3). The
firmware is told from what it sends, against the shipped profiles (`identify`).
"""

from __future__ import annotations

import contextlib
import itertools
import shlex
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import serial

from appmode.board.profiles import Profile, profile_named
from appmode.errors import AppmodeError
from appmode.host import identify
from appmode.host.client import Host
from appmode.line.wire import APP_BAUD, UART2_BAUD
from appmode.ports.target import Target, as_target
from appmode.ports.urls import open_link
from appmode.protocol import app, app_decoders, control, control_decoders, param_values
from appmode.protocol.escaping import text_part

RATES = (APP_BAUD, UART2_BAUD, 38400, 57600, 19200, 4800, 2400, 1200)
"""The rates tried, in order: the APP port's, the control port's, then a Bluetooth
module's other settings."""
LISTEN = 1.0
"""Seconds of listening at 9600 bps: about 17 records of either firmware."""
LISTEN_OTHER = 0.5
"""Seconds of listening at each other rate."""
STARTING = 2.5
"""Seconds of listening at most while a board prints its start-up text (the reference
firmware's first record comes 1.4 s after power-up)."""
ENOUGH = 3
"""Records (or control-port bursts) that show what a port carries."""
STARTED = 8
"""Records after a board's start-up text that give its period."""
READ_TRIES = 2
"""Rounds of `{Q:P}` for the parameters (each asks for two agreeing C records)."""
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

Progress = Callable[[str], None]


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
    ) -> None:
        """Count what `data`, come at `at` s, holds."""
        self.size += len(data)
        for event in app_decoder.feed(data):
            if isinstance(event, app.RECORDS) and event.terminated:
                self.record_times.append(at)
                self.record_sizes.append(len(event.raw))
                if len(self.shapes) < identify.SHOWN:
                    self.shapes.append(app.record_fields(event))
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


@dataclass
class Finding:
    """The verdict on one port."""

    url: str
    kind: str
    """`app`, `uart2` (a car's port), `silent`, `noise`, `text`, `unopened` or `lost`."""
    verdict: str
    """One line: what this is."""
    fix: str
    """What to do next: the command that drives it, or what to fix."""
    baud: int | None = None
    profile: str | None = None
    period_ms: float | None = None
    values: tuple[int, ...] | None = None
    heard: list[Heard] = field(default_factory=list)
    specs: param_values.Specs = param_values.SHEET
    """The parameters' table that names `values` (the profile's, or the nearest's)."""

    @property
    def is_car(self) -> bool:
        return self.kind in ("app", "uart2")

    def to_json(self) -> dict[str, object]:
        return {
            "port": self.url,
            "kind": self.kind,
            "car": self.is_car,
            "verdict": self.verdict,
            "fix": self.fix,
            "baud": self.baud,
            "profile": self.profile,
            "record_period_ms": None if self.period_ms is None else round(self.period_ms, 1),
            "params": None
            if self.values is None
            else {
                s.name: param_values.user_number(s, v)
                for s, v in zip(self.specs, self.values, strict=False)
            },
            "heard": [
                {
                    "baud": h.baud,
                    "seconds": round(h.seconds, 2),
                    "bytes": h.size,
                    "records": h.records,
                    "uart2_bursts": h.uart2_bursts,
                }
                for h in self.heard
            ],
        }


def firmware(sent: identify.Sent) -> tuple[Profile | None, identify.Judgement]:
    """The shipped profile that fits what was sent (None when none does), and the
    nearest one's judgement."""
    found, nearest = identify.best(sent)
    return (profile_named(found.name) if found else None), nearest


def listen(
    url: str, baud: int, seconds: float, stop: threading.Event
) -> tuple[Heard, serial.SerialBase]:
    """What comes on `url` at `baud` in `seconds` (up to STARTING while a board prints
    its start-up text); the port stays open for a read that follows."""
    port = open_link(url, timeout=0.02, baud=baud)
    heard = Heard(baud)
    app_decoder, uart2_decoder = (
        app_decoders.BoardDecoder(b_fields=None),  # any field count: the firmware is not known
        control_decoders.ReplyDecoder(wheels=None),
    )
    start = time.monotonic()
    try:
        while not stop.is_set():
            # read, then look at the time: a process not scheduled for the whole time
            # (a loaded machine) still reads what came meanwhile before it judges
            data = port.read(max(1, port.in_waiting))
            if data:
                heard.feed(data, time.monotonic() - start, app_decoder, uart2_decoder)
            starting = heard.text and heard.records < STARTED
            if time.monotonic() - start >= (STARTING if starting else seconds):
                break
    except BaseException:
        close_quietly(port)
        raise
    heard.seconds = time.monotonic() - start
    return heard, port


def probe(url: str, stop: threading.Event, progress: Progress) -> Finding:
    """Listen to `url` and say what it is (never raises AppmodeError: that is a finding)."""
    try:
        return _probe(url, stop, progress)
    except AppmodeError as exc:  # opening it failed: the message says what, then the fix
        what, _, fix = str(exc).partition(": ")
        return Finding(url, "unopened", f"cannot be opened: {what}", fix or what)
    except (serial.SerialException, OSError) as exc:
        return Finding(
            url,
            "lost",
            f"it opened, then failed while listening ({exc})",
            "the device went away: check the cable or adapter (or the program that "
            "served this pty), then run appmode doctor again",
        )


def _probe(url: str, stop: threading.Event, progress: Progress) -> Finding:
    target = as_target(url)
    fixed = bool(target.scheme)  # TCP, sim://, Bluetooth: no line rate of ours to get wrong
    path, given = (url, 0) if fixed else (target.path, target.baud or 0)
    rates = RATES[:1] if fixed else (given, *(r for r in RATES if r != given)) if given else RATES
    heard: list[Heard] = []
    for baud in rates:
        if stop.is_set():
            break
        progress(f"listening at {baud} bps" if not fixed else "listening")
        one, port = listen(path, baud, LISTEN_OTHER if heard else LISTEN, stop)
        heard.append(one)
        if one.carries_app:
            return _car(target, path, one, port, heard, progress)
        close_quietly(port)
        if one.carries_uart2 and (baud == UART2_BAUD or fixed):
            return _control_port(path, one, heard, fixed)
        if one.text and not one.records:
            break  # text that reads as text: the rate is right, and no board talks so
        if len(heard) == 2 and not any(h.size for h in heard):
            break  # silent at the APP port's rate and at the control port's
    uart2 = next((h for h in heard if h.carries_uart2), None)  # at a rate of its own
    if uart2 is not None and uart2.baud != UART2_BAUD:
        # its bursts came at the control port's rate too, if fewer in a loaded moment: a
        # link with no rate of its own (a pty), read at any; the control port's it is
        uart2 = next((h for h in heard if h.baud == UART2_BAUD and h.uart2_bursts), uart2)
    if uart2 is not None:
        return _control_port(path, uart2, heard, fixed)
    return _no_board(url, heard, fixed)


def _with_baud(url: str, baud: int, usual: int, fixed: bool) -> str:
    return url if fixed or baud == usual else f"{url}?baud={baud}"


def _car(
    given: Target,
    path: str,
    one: Heard,
    port: serial.SerialBase,
    heard: list[Heard],
    progress: Progress,
) -> Finding:
    url, fixed = given.url, bool(given.scheme)
    profile, nearest = firmware(one.sent)
    ports = [port]

    def reopen(target: str) -> serial.SerialBase:
        return ports.pop() if ports else open_link(target, timeout=0.02, baud=one.baud)

    progress(f"reading the parameters at {one.baud} bps")
    layout = (profile or profile_named(nearest.profile.name)).a_layout
    values: tuple[int, ...] | None = None
    failure = ""
    host = Host(path, opener=reopen, stop_on_close=False, layout=layout)
    try:
        values = host.read_params(tries=READ_TRIES)
    except AppmodeError as exc:
        failure = str(exc)
    finally:
        host.close()
    replied = bytes(host.state.outside)  # a `##$` before the C record names some firmware
    if replied:
        sent = one.sent
        profile, nearest = firmware(sent._replace(text=sent.text + replied))
    target = _with_baud(path, one.baud, APP_BAUD, fixed)
    rate = "" if fixed else f" at {one.baud} bps"
    period = f"a record every {5 * round((one.period_ms or 0) / 5)} ms"  # to 5 ms: a rhythm
    what = f"{profile.name if profile else 'unknown'} firmware ({period})"
    drive = _drive_it(profile, nearest, target, given.simulated)
    specs = (profile or profile_named(nearest.profile.name)).a_layout.params
    if values is None:
        return Finding(
            url,
            "app",
            f"a car's APP port{rate}, {what}; its parameters did not come",
            f"{failure}; {drive}",
            one.baud,
            profile.name if profile else None,
            one.period_ms,
            None,
            heard,
            specs,
        )
    shown = ", ".join(
        f"{s.name}={param_values.to_user(s, v)}" for s, v in zip(specs, values, strict=False)
    )
    note = (
        ""
        if fixed or one.baud == APP_BAUD
        else f" (its Bluetooth module or UART runs at {one.baud}, not 9600)"
    )
    return Finding(
        url,
        "app",
        f"this is a car: APP port{rate}{note}, {what}, parameters {shown}",
        drive,
        one.baud,
        profile.name if profile else None,
        one.period_ms,
        values,
        heard,
        specs,
    )


def _drive_it(
    profile: Profile | None, nearest: identify.Judgement, target: str, simulated: bool
) -> str:
    """What to do next with a car: the command that drives it, or how to write a profile
    for a firmware that fits none."""
    if profile is None:
        name = nearest.profile.name
        return (
            f"its records fit no shipped profile (nearest: {name}, but "
            f"{'; '.join(nearest.against[:2])}): write one for it, starting from "
            f"appmode profile show {name} --toml > mycar.toml, then "
            f"appmode drive {shlex.quote(target)} --profile mycar.toml"
        )
    flag = ""  # a sim:// URL names its own profile
    if profile.name != "sheet" and not simulated:
        flag = f" --profile {profile.name}"
    return f"drive it with: appmode drive {shlex.quote(target)}{flag}"


def _control_port(url: str, one: Heard, heard: list[Heard], fixed: bool) -> Finding:
    rate = "" if fixed else f" at {one.baud} bps"
    what = "encoder reports" if one.reports else "the reference firmware's status bursts (§13.1)"
    target = _with_baud(url, one.baud, UART2_BAUD, fixed)
    return Finding(
        url,
        "uart2",
        f"this is a car's control port (UART2){rate}: it sends {what}",
        f"drive it with: appmode drive {shlex.quote(target)} --uart2 (it takes the motion "
        "over from the APP port)",
        one.baud,
        heard=heard,
    )


def _no_board(url: str, heard: list[Heard], fixed: bool) -> Finding:
    tried = " or ".join(f"{h.baud}" for h in heard)
    spent = sum(h.seconds for h in heard)
    where = "" if fixed else f" at {tried} bps"
    if not any(h.size for h in heard):
        return Finding(
            url,
            "silent",
            f"silent: nothing came in {spent:.1f} s{where}",
            "check that the car is on and wired TX to RX (or paired, for Bluetooth); a "
            "control port (UART2) with its encoder report off is silent until spoken to: "
            f"appmode params {shlex.quote(url)} --uart2 reads it (and takes the motion over)",
            heard=heard,
        )
    talk = next((h for h in heard if h.text), None)
    if talk is not None:
        sample = bytes(talk.sample).decode("ascii", "replace").split()
        return Finding(
            url,
            "text",
            f"not a board: it sends text{'' if fixed else f' at {talk.baud} bps'} "
            f"({' '.join(sample)[:40]!r}…), no records",
            "name the car's port instead (appmode ports lists them); a pty "
            "path may now be another program's: restart the board, or use board --link",
            talk.baud,
            heard=heard,
        )
    return Finding(
        url,
        "noise",
        f"bytes but no records{where}",
        "not a board, or at a rate appmode does not try: check the wiring (TX to RX, a "
        "common ground) and the module's rate",
        heard=heard,
    )


def close_quietly(port: serial.SerialBase) -> None:
    with contextlib.suppress(serial.SerialException, OSError):
        port.close()
