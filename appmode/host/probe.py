"""What answers on a port, found by listening: `appmode doctor`'s probe.

A port is listened to at 9600 bps for APP records; when it carries bytes that are not
records (a wrong rate reads as such: `line/uart.py`) the other common rates are tried,
and 115200 for the control port's traffic (UART2: encoder reports, the reference
firmware's status bursts). What the bytes show is judged without I/O (`heard.judge`).
The only bytes ever sent are `{Q:P}` frames to a port that streams APP records, to read
its parameters: never a drive letter, and nothing to a silent port, where a control
port would count them toward its take-over (§8.3). What to tell people of a finding is
`appmode doctor`'s.
"""

from __future__ import annotations

import contextlib
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import serial

from appmode.board.profiles import profile_named
from appmode.errors import AppmodeError
from appmode.host import identify
from appmode.host.app.client import Host
from appmode.host.heard import STARTED, Heard, Kind, firmware, judge
from appmode.line.wire import APP_BAUD, UART2_BAUD
from appmode.ports.target import Target
from appmode.ports.urls import open_link
from appmode.protocol import app_decoders, chassis, control_decoders, param_values

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
READ_TRIES = 2
"""Rounds of `{Q:P}` for the parameters (each asks for two agreeing C records)."""

Progress = Callable[[str], None]


@dataclass(kw_only=True)
class Finding:
    """What was found on one port: the facts (`appmode doctor` says what they mean)."""

    target: Target
    kind: Kind | str
    """`app`, `uart2`, `chassis` (a car's port), `silent`, `noise`, `text`; `unopened` or
    `lost`."""
    baud: int | None = None
    """The rate the port carried what it did at (None: none showed)."""
    profile: str | None = None
    """The shipped profile the firmware fits (a car's APP port), or None."""
    nearest: identify.Judgement | None = None
    """The nearest shipped profile, and what speaks against it."""
    period_ms: float | None = None
    values: tuple[int, ...] | None = None
    """The parameters read (a car's APP port), or None."""
    failure: str = ""
    """Why the parameters did not come, or why the port did not open or failed."""
    specs: param_values.Specs = param_values.SHEET
    """The parameters' table that names `values` (the profile's, or the nearest's)."""
    heard: list[Heard] = field(default_factory=list)

    @property
    def url(self) -> str:
        return self.target.url

    @property
    def fixed(self) -> bool:
        """No line rate of its own (TCP, sim://, Bluetooth)."""
        return bool(self.target.scheme)

    @property
    def is_car(self) -> bool:
        return self.kind in ("app", "uart2", "chassis")

    @property
    def shown(self) -> Heard | None:
        """The rate whose bytes showed what the port is."""
        return next((h for h in self.heard if h.baud == self.baud), None)


def listen(
    url: Target, baud: int, seconds: float, stop: threading.Event
) -> tuple[Heard, serial.SerialBase]:
    """What comes on `url` at `baud` in `seconds` (up to STARTING while a board prints
    its start-up text); the port stays open for a read that follows."""
    port = open_link(url, timeout=0.02, baud=baud)
    heard = Heard(baud)
    app_decoder, uart2_decoder, status_decoder = (
        app_decoders.BoardDecoder(b_fields=None),  # any field count: the firmware is not known
        control_decoders.ReplyDecoder(wheels=None),
        chassis.StatusDecoder(),
    )
    start = time.monotonic()
    try:
        while not stop.is_set():
            # read, then look at the time: a process not scheduled for the whole time
            # (a loaded machine) still reads what came meanwhile before it judges
            data = port.read(max(1, port.in_waiting))
            if data:
                decoders = (app_decoder, uart2_decoder, status_decoder)
                heard.feed(data, time.monotonic() - start, *decoders)
            starting = heard.text and heard.records < STARTED
            if time.monotonic() - start >= (STARTING if starting else seconds):
                break
    except BaseException:
        close_quietly(port)
        raise
    heard.seconds = time.monotonic() - start
    return heard, port


def probe(
    target: Target,
    stop: threading.Event,
    progress: Progress,
    rates: tuple[int, ...] | None = None,
) -> Finding:
    """Listen to `target` (at `rates` only, if given) and find what it is (never raises
    AppmodeError: a port that does not open is a finding)."""
    try:
        return _probe(target, stop, progress, rates)
    except AppmodeError as exc:  # opening it failed: the message says what, then the fix
        return Finding(target=target, kind="unopened", failure=str(exc))
    except (serial.SerialException, OSError) as exc:
        return Finding(target=target, kind="lost", failure=str(exc))


def _probe(
    target: Target, stop: threading.Event, progress: Progress, only: tuple[int, ...] | None
) -> Finding:
    fixed = bool(target.scheme)  # TCP, sim://, Bluetooth: no line rate of ours to get wrong
    given = 0 if fixed else target.baud or 0
    rates = RATES[:1] if fixed else (given, *(r for r in RATES if r != given)) if given else RATES
    rates = only if only is not None and not fixed else rates
    bare = replace(target, baud=None)  # each rate tried, whatever ?baud= said
    heard: list[Heard] = []
    for n, baud in enumerate(rates, start=1):
        if stop.is_set():
            break
        progress(f"listening at {baud} bps" if not fixed else "listening")
        one, port = listen(bare, baud, LISTEN_OTHER if heard else LISTEN, stop)
        heard.append(one)
        verdict = judge(heard, fixed, more=n < len(rates))
        if verdict is not None and verdict.kind == "app":
            return _car(target, bare, one, port, heard, progress)
        close_quietly(port)
        if verdict is not None:
            return _found(target, verdict.kind, verdict.heard, heard)
    verdict = judge(heard, fixed, more=False) if heard else None
    return _found(target, "silent" if verdict is None else verdict.kind, None, heard)


def _found(target: Target, kind: Kind, shown: Heard | None, heard: list[Heard]) -> Finding:
    baud = None if shown is None else shown.baud
    mecanum = kind == "chassis" and shown is not None and shown.sideways
    profile = "wheeltec-mec" if mecanum else None  # only a mecanum car moves sideways
    return Finding(target=target, kind=kind, baud=baud, heard=heard, profile=profile)


def _car(
    target: Target,
    bare: Target,
    one: Heard,
    port: serial.SerialBase,
    heard: list[Heard],
    progress: Progress,
) -> Finding:
    """A port that streams APP records (opened as `bare`, at the rate it showed): its
    firmware, and its parameters read."""
    profile, nearest = firmware(one.sent)
    ports = [port]

    def reopen(url: Target) -> serial.SerialBase:
        return ports.pop() if ports else open_link(url, timeout=0.02, baud=one.baud)

    progress(f"reading the parameters at {one.baud} bps")
    chosen = profile or profile_named(nearest.profile.name)
    values: tuple[int, ...] | None = None
    failure = ""
    host = Host(bare, opener=reopen, stop_on_close=False, profile=chosen)
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
    return Finding(
        target=target,
        kind="app",
        baud=one.baud,
        profile=profile.name if profile else None,
        nearest=nearest,
        period_ms=one.period_ms,
        values=values,
        failure=failure,
        specs=(profile or profile_named(nearest.profile.name)).a_layout.params,
        heard=heard,
    )


def close_quietly(port: serial.SerialBase) -> None:
    with contextlib.suppress(serial.SerialException, OSError):
        port.close()
