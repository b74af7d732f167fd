"""`send` and `monitor` with `--chassis`: the same commands over a WHEELTEC board's chassis
port (7B … 7D frames at 115200 bps; docs/protocol.md §15)."""

from __future__ import annotations

import json
import sys
from contextlib import ExitStack
from typing import TYPE_CHECKING, TextIO

from appmode.cli.hostio import close_host, until_count, with_recording
from appmode.cli.live_view import live_view
from appmode.host.chassis.client import RESEND, ChassisHost, Event
from appmode.host.chassis.tokens import parse_token
from appmode.host.events import LinkStatus
from appmode.host.waits import Wait
from appmode.protocol import chassis
from appmode.protocol.render import line
from appmode.protocol.twist import Twist
from appmode.text import counted

if TYPE_CHECKING:
    from appmode.cli.options import Address
    from appmode.ports.choice import BoardChoice
    from appmode.protocol.channels import Viewer

RESENDING = (
    "a chassis acknowledges nothing and may never stop by itself: the velocity in force "
    f"is sent again every {RESEND:g} s while it drives, and a zero frame last"
)
BOOTING = (
    "the board's status says Flag_Stop: it ignores velocity frames until its start-up "
    "has passed (about 10 s after power-up, while the gyro is zeroed)"
)
QUIET = (
    "a chassis port sends a status frame every 50 ms: check the cable, that the car is "
    "on, and the port (/dev/wheeltec_controller on the vendor's image)"
)


def open_chassis_host(
    stack: ExitStack,
    choice: BoardChoice,
    record: str | None,
    stop_on_close: bool = True,
    confirm_stop: bool = False,
    view: Viewer | None = None,
) -> ChassisHost:
    """The chassis host of the board chosen, then its recording (hostio.with_recording)."""
    host = ChassisHost(
        choice.target,
        stop_on_close=stop_on_close,
        profile=choice.profile,
        confirm_stop=confirm_stop,
    )
    return with_recording(stack, host, record, view)


class Shown:
    """A chassis session's events as lines: text, or (what the board sent) JSON; link
    changes on stderr, and once what Flag_Stop means."""

    def __init__(self, host: ChassisHost, out: TextIO | None, as_json: bool) -> None:
        self._host, self._out, self._as_json = host, out, as_json
        self._booting_said = False

    def __call__(self, direction: str, event: chassis.Event | LinkStatus) -> None:
        if isinstance(event, LinkStatus):
            print(f"appmode: {event.text}", file=sys.stderr, flush=True)
            return
        booting = isinstance(event, chassis.Status) and event.flag_stop
        if booting and not self._booting_said and self._host.state.in_force is not None:
            self._booting_said = True
            print(f"appmode: note: {BOOTING}", file=sys.stderr, flush=True)
        out = self._out
        if out is None or (self._as_json and direction == self._host.sent):
            return
        now = self._host.now()
        if self._as_json:
            out.write(json.dumps({"t": round(now, 3), **chassis.as_json(event)}) + "\n")
        else:
            out.write(line(now, direction, event.raw, str(event), event.raw.hex(" ")) + "\n")
        out.flush()


def run_send(
    choice: BoardChoice,
    tokens: list[str],
    *,
    listen: float,
    as_json: bool,
    record: str | None,
    out: TextIO,
) -> int:
    """Send the tokens in order, printing what comes back: a velocity holds (sent again
    every RESEND seconds) until the next token that moves or stops; a zero frame is
    always sent last, confirmed on the status frames."""
    steps = [parse_token(token) for token in tokens]  # all checked before sending
    print(f"appmode: {RESENDING}", file=sys.stderr, flush=True)
    with ExitStack() as stack:
        host = open_chassis_host(stack, choice, record, confirm_stop=True)
        shown = Shown(host, out, as_json)
        for step in steps:
            if isinstance(step, Wait):
                _hold(host, shown, step.seconds)
                continue
            sent = host.velocity(step) if isinstance(step, Twist) else _raw(host, step)
            for event in chassis.CommandDecoder().feed(sent):
                shown(host.sent, event)
            _hold(host, shown, 0)
        _hold(host, shown, listen)
        sent_at = host.now()  # the stop goes first; confirming it takes a while after
        stop = close_host(host)
        if stop is None:
            return 1
        if not as_json:
            out.write(line(sent_at, host.sent, stop, "stop: a zero frame", stop.hex(" ")) + "\n")
    return 0


def _raw(host: ChassisHost, data: bytes) -> bytes:
    host.send(data)
    return data


def _hold(host: ChassisHost, shown: Shown, seconds: float) -> None:
    """Read for `seconds`, sending the velocity in force again as it falls due."""
    end = host.now() + seconds
    while True:
        for event in host.poll(max(0.0, min(end, host.resend_due()) - host.now())):
            shown(host.received, event)
        host.resend()  # not shown again: it is the frame shown when first sent
        if host.now() >= end:
            return


def run_monitor(
    choice: BoardChoice,
    *,
    as_json: bool,
    duration: float | None,
    count: int | None,
    record: str | None,
    out: TextIO | None,
    stop_on_exit: bool = False,
    foxglove: Address | None = None,
    name: str = "monitor",
) -> int:
    """Print status frames as they arrive (`out` None: none, `appmode record`); passive
    unless `stop_on_exit`."""
    seen = errors = 0
    with ExitStack() as stack:
        view = stack.enter_context(live_view(foxglove, choice.profile.a_layout))
        host = open_chassis_host(stack, choice, record, stop_on_exit, view=view)
        doing = f"recording {host.url} to {record}" if out is None else f"monitoring {host.url}"
        print(f"{doing} (Ctrl-C to stop)", file=sys.stderr, flush=True)
        shown = Shown(host, out, as_json)
        try:
            for event in until_count(host.events(duration), _is_status, count):
                shown(host.received, event)
                errors += isinstance(event, chassis.Junk)
                seen += _is_status(event)
        finally:
            print(
                f"{name}: {counted(seen, 'status frame')}, {counted(errors, 'error')} in "
                f"{host.now():.1f} s",
                file=sys.stderr,
            )
            if not seen:
                print(f"{name}: {QUIET}", file=sys.stderr)
    return 0


def _is_status(event: Event | LinkStatus) -> bool:
    return isinstance(event, chassis.Status)
