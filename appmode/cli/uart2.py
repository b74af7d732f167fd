"""`params`, `send` and `monitor` with `--uart2`: the same commands over the board's
control port (UART2, binary frames; docs/protocol.md Part II)."""

from __future__ import annotations

import json
import sys
from collections.abc import Iterable
from contextlib import ExitStack
from typing import TYPE_CHECKING, TextIO

from appmode.cli.hostio import until_count, with_recording
from appmode.cli.live_view import live_view
from appmode.host.control.client import ControlHost, Event
from appmode.host.control.state import PortMode
from appmode.host.control.tokens import Step, parse_setting, parse_token, perform
from appmode.host.events import LinkStatus
from appmode.host.waits import Wait
from appmode.protocol import control, params, reader, settings
from appmode.protocol.control_view import settings_table, view
from appmode.protocol.render import line
from appmode.text import counted, wrapped

if TYPE_CHECKING:
    from appmode.cli.options import Address
    from appmode.ports.choice import BoardChoice
    from appmode.protocol.channels import Viewer

QUIET_UART2 = (
    "a board sends replies only to reads, and encoder reports only while system_mode "
    "bit 6 is set (see appmode protocol 12); 'appmode send URL --uart2 wait:5' turns the "
    "report on for its session"
)
UNLIMITED = "a minibalance board takes velocities unlimited by max_speed (§13.1)"
TAKEOVER = (
    "frames sent on the control port take over the car's motion from the APP port "
    "(any 10 bytes; see appmode protocol 8.3)"
)


def open_control_host(
    stack: ExitStack,
    choice: BoardChoice,
    record: str | None,
    stop_on_close: bool = True,
    view: Viewer | None = None,
) -> ControlHost:
    """The control-port host of the board chosen, then its recording
    (hostio.with_recording)."""
    host = ControlHost(
        choice.target, stop_on_close=stop_on_close, profile=choice.profile, drive=choice.drive
    )
    return with_recording(stack, host, record, view)


WHY_TWICE = "every read goes twice: UART2 has no checksum, so two replies must agree"
"""Said once, on stderr, when a read's second copy is first shown."""


class Shown:
    """The events of a UART2 session as lines: a line of text, or (what the board sent) a
    JSON line; link and mode changes on stderr. APP records show as such while APP mode
    (bit 7) moves them here (§12). A read's second copy says why it is there."""

    def __init__(self, host: ControlHost, out: TextIO, as_json: bool) -> None:
        self._host, self._out, self._as_json = host, out, as_json
        self._last = b""
        self._explained = False

    def __call__(self, direction: str, event: reader.Event | LinkStatus | PortMode) -> None:
        host = self._host
        if isinstance(event, (LinkStatus, PortMode)):
            print(f"appmode: {event.text}", file=sys.stderr, flush=True)
            return
        if self._as_json and direction == host.sent:
            return  # JSON Lines hold what came back, as for the APP port
        body, text, shown = view(event)
        if self._as_json:
            self._out.write(json.dumps({"t": round(host.now(), 3), **body}) + "\n")
        else:
            again = isinstance(event, control.ReadFrame) and event.raw == self._last
            if direction == host.sent:
                self._last = b"" if again else event.raw
            if again:
                text += " again"
                if not self._explained:
                    print(f"appmode: {WHY_TWICE}", file=sys.stderr, flush=True)
                self._explained = True
            self._out.write(line(host.now(), direction, event.raw, text, shown) + "\n")
        self._out.flush()


# ---------------------------------------------------------------- params --uart2


def run_params(
    choice: BoardChoice,
    assignments: list[str],
    *,
    store: str | None,
    as_json: bool,
    record: str | None,
    out: TextIO,
) -> int:
    """Read the ten settings; `load` or `defaults` first, then set each (verified by
    reading back), then `save`; print them."""
    changes = [parse_setting(text, f"--set {text!r}") for text in assignments]  # checked first
    print(f"appmode: {TAKEOVER}", file=sys.stderr)
    with ExitStack() as stack:
        host = open_control_host(stack, choice, record)
        if store in ("load", "defaults"):
            host.store(store)
            print(f"{settings.STORE_BY_NAME[store].meaning} (sent)", file=sys.stderr)
        for setting, value in changes:
            host.set(setting.name, value)
            print(f"set {setting.name} = {value} (verified)", file=sys.stderr)
        if store == "save":
            host.store("save")
        values = host.settings()
        if store == "save":
            print(
                "save requested (FF FE 80 80 00 80 00 00 03 00); the board does not confirm "
                f"a save: restart it, then run appmode params {choice.target} --uart2",
                file=sys.stderr,
            )
    if as_json:
        out.write(json.dumps(values) + "\n")
    else:
        out.write(settings_table(values) + "\n")
    return 0


# ---------------------------------------------------------------- send --uart2


def run_send(
    choice: BoardChoice,
    tokens: list[str],
    *,
    listen: float,
    report: bool,
    as_json: bool,
    record: str | None,
    out: TextIO,
) -> int:
    """Send the tokens in order, printing what comes back; the zero velocity frame is
    always sent last. `report` turns the encoder report on for the session (on a board
    that has one: a profile without settings frames has no reads and no report)."""
    steps = [parse_token(token) for token in tokens]  # all checked before sending
    profile = choice.profile
    if profile.firmware_uart2 and any(
        isinstance(step, Step) and step.kind == "velocity" for step in steps
    ):
        print(f"appmode: note: {UNLIMITED}", file=sys.stderr)
    with ExitStack() as stack:
        host = open_control_host(stack, choice, record)
        host.watch = Shown(host, out, as_json)
        report_bit = params.MODE_BIT["encoder_report"]
        report = report and profile.answers_reads
        mode = host.read("system_mode") if report else report_bit
        if not mode & report_bit:  # on for the session, then as it was (before the stop)
            host.send_frame(control.setting("system_mode", mode | report_bit))
            host.put_back_on_close("system_mode", mode)
        for step in steps:
            if isinstance(step, Wait):
                _drain(host.events(step.seconds))
            elif isinstance(step, Step) and step.kind == "rotate":
                host.start_rotation(step.values[0] / 10)
                host.wait_rotation()
            else:
                perform(host, step)
            _drain(host.poll(0))
        _drain(host.events(listen))
        if host.close() is None:
            from appmode.host.link import UNDELIVERED

            print(f"appmode: {UNDELIVERED} (the link is down)", file=sys.stderr)
            return 1
    return 0


def _drain(events: Iterable[Event]) -> None:
    """Read on (the session is printed as it is decoded: `host.watch`)."""
    for _ in events:
        pass


# ---------------------------------------------------------------- monitor --uart2


def run_monitor(
    choice: BoardChoice,
    *,
    as_json: bool,
    duration: float | None,
    count: int | None,
    record: str | None,
    out: TextIO,
    stop_on_exit: bool = False,
    foxglove: Address | None = None,
) -> int:
    """Print replies and encoder reports as they arrive; passive unless `stop_on_exit`;
    live to Foxglove on `foxglove` ([HOST:]PORT)."""
    seen = errors = bursts = 0
    with ExitStack() as stack:
        view = stack.enter_context(
            live_view(foxglove, choice.profile.a_layout, drive_type=choice.known_drive)
        )
        host = open_control_host(stack, choice, record, stop_on_exit, view)
        print(f"monitoring {host.url} (Ctrl-C to stop)", file=sys.stderr, flush=True)
        host.watch = Shown(host, out, as_json)
        try:
            for event in until_count(host.events(duration), _is_answer, count):
                errors += isinstance(event, control.Garbage)
                bursts += isinstance(event, control.Status)
                seen += _is_answer(event)
        finally:
            also = f", {counted(bursts, 'status burst')} (a minibalance board's)" if bursts else ""
            print(
                f"monitor: {seen} replies and reports{also}, {counted(errors, 'error')} "
                f"in {host.now():.1f} s",
                file=sys.stderr,
            )
            if not seen:
                print(wrapped(f"monitor: {QUIET_UART2}"), file=sys.stderr)
    return 0


def _is_answer(event: Event) -> bool:
    """A reply or an encoder report: what a UART2 monitor counts."""
    return isinstance(event, (control.Reply, control.EncoderReport))
