"""`params`, `send` and `monitor` with `--uart2`: the same commands over the board's
control port (UART2, binary frames; docs/protocol.md Part II)."""

from __future__ import annotations

import json
import sys
from collections.abc import Iterable
from contextlib import ExitStack
from typing import TextIO

from appmode.cli.hostio import with_recording
from appmode.errors import AppmodeError
from appmode.host.control_client import ControlHost, Event
from appmode.host.control_tokens import Step, parse_token
from appmode.host.state import LinkStatus
from appmode.host.tokens import Wait
from appmode.protocol import control, control_view, params, settings
from appmode.protocol.control_view import describe, hex_text, settings_table, to_json
from appmode.protocol.render import line

TAKEOVER = (
    "frames sent on the control port take over the car's motion from the APP port "
    "(any 10 bytes, docs/protocol.md §8.3)"
)


def open_control_host(
    stack: ExitStack, url: str, record: str | None, stop_on_close: bool = True
) -> ControlHost:
    """The control-port host, then its recording (hostio.with_recording)."""
    return with_recording(stack, ControlHost(url, stop_on_close=stop_on_close), record)


def show(host: ControlHost, event: Event, out: TextIO, as_json: bool) -> None:
    """One event the board sent: text or a JSON line; link changes on stderr."""
    if isinstance(event, LinkStatus):
        print(f"appmode: {event.text}", file=sys.stderr, flush=True)
        return
    if not isinstance(event, (control.Reply, control.EncoderReport, control.Garbage)):
        text = f"APP mode: {type(event).__name__}"  # records while bit 7 is on (§12)
        body = {"kind": "app", "raw": event.raw.decode("latin-1")}
        if as_json:
            out.write(json.dumps({"t": round(host.now(), 3), **body}) + "\n")
        else:
            out.write(line(host.now(), "2<", event.raw, text) + "\n")
        out.flush()
        return
    if as_json:
        out.write(json.dumps({"t": round(host.now(), 3), **to_json(event)}) + "\n")
    else:
        out.write(line(host.now(), "2<", event.raw, describe(event), hex_text(event.raw)) + "\n")
    out.flush()


def print_session(host: ControlHost, out: TextIO, as_json: bool) -> None:
    """Print the session as it goes: each event as it is decoded, and (as text) the
    bytes sent, through the host's tap (after the recording, if any)."""
    record = host.tap
    sending = control.HostDecoder()

    def tap(direction: str, now: float, data: bytes) -> None:
        if record is not None:
            record(direction, now, data)
        if direction != host.sent or as_json:
            return
        sending.drive = host.known_drive or params.DriveType.OMNI
        events = [e for e in sending.feed(data) if isinstance(e, control_view.EVENTS)]
        text = ", ".join(describe(e) for e in events) or "(part of a frame)"
        out.write(line(now, direction, data, text, hex_text(data)) + "\n")
        out.flush()

    host.tap = tap
    host.watch = lambda event: show(host, event, out, as_json)


# ---------------------------------------------------------------- params --uart2


def parse_setting(text: str) -> tuple[settings.Setting, int]:
    """`NAME=VALUE` (or `ID=VALUE`), checked against the settings table."""
    name, sep, value = text.partition("=")
    if not sep:
        raise AppmodeError(f"--set {text!r}: expected NAME=VALUE, e.g. max_speed=800")
    try:
        setting = settings.lookup(name)
    except ValueError as exc:
        raise AppmodeError(f"--set {text!r}: {exc}") from None
    number = params.whole(value)
    if number is None:
        raise AppmodeError(
            f"--set {text!r}: {setting.name} takes a whole number in {setting.range_text}"
        )
    error = settings.value_error(setting, number)
    if error is not None:
        raise AppmodeError(f"--set {text!r}: {error}")
    return setting, number


def run_params(
    url: str,
    assignments: list[str],
    *,
    store: str | None,
    as_json: bool,
    record: str | None,
    out: TextIO,
) -> int:
    """Read the ten settings; `load` or `defaults` first, then set each (verified by
    reading back), then `save`; print them."""
    changes = [parse_setting(text) for text in assignments]  # all checked first
    print(f"appmode: {TAKEOVER}", file=sys.stderr)
    with ExitStack() as stack:
        host = open_control_host(stack, url, record)
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
                f"a save: restart it, then run appmode params {url} --uart2",
                file=sys.stderr,
            )
    if as_json:
        out.write(json.dumps(values) + "\n")
    else:
        out.write(settings_table(values) + "\n")
    return 0


# ---------------------------------------------------------------- send --uart2


def run_send(
    url: str,
    tokens: list[str],
    *,
    listen: float,
    report: bool,
    as_json: bool,
    record: str | None,
    out: TextIO,
) -> int:
    """Send the tokens in order, printing what comes back; the zero velocity frame is
    always sent last. `report` turns the encoder report on for the session."""
    steps = [parse_token(token) for token in tokens]  # all checked before sending
    with ExitStack() as stack:
        host = open_control_host(stack, url, record)
        print_session(host, out, as_json)
        report_bit = params.MODE_BIT["encoder_report"]
        before = host.read("system_mode") if report else None
        if before is not None and not before & report_bit:
            host.send_frame(_set("system_mode", before | report_bit))
        for step in steps:
            if isinstance(step, Wait):
                _drain(host.events(step.seconds))
            elif isinstance(step, Step) and step.kind == "rotate":
                host.start_rotation(step.values[0] / 10)
                host.wait_rotation()
            else:
                _perform(host, step)
            _drain(host.poll(0))
        _drain(host.events(listen))
        if before is not None and not before & report_bit:
            host.send_frame(_set("system_mode", before))
        if host.close() is None:
            print("appmode: the link is down: the final stop frame was not sent", file=sys.stderr)
            return 1
    return 0


def _drain(events: Iterable[Event]) -> None:
    """Read on (the session is printed as it is decoded: print_session)."""
    for _ in events:
        pass


def _set(name: str, value: int) -> control.SetSetting:
    return control.SetSetting(settings.BY_NAME[name], value)


def _perform(host: ControlHost, step: Step | bytes) -> bytes:
    """Send one step; the bytes sent."""
    if isinstance(step, bytes):
        host.send(step)
        return step
    kind, values = step.kind, step.values
    if kind == "velocity":
        if host.drive is params.DriveType.DIFF_GYRO and len(values) == 2:
            return host.velocity(left=values[0], right=values[1])
        if len(values) != 3:
            raise AppmodeError(f"velocity: a {host.drive.cli_name} car takes X,Y,Z")
        return host.velocity(*values)
    if kind == "motors":
        return host.motors(values)
    if kind == "position":
        return host.position(*values)
    if kind == "read":
        return host.send_frame(control.read(step.name))
    if kind == "set":
        return host.send_frame(_set(step.name, values[0]))
    if kind == "stop":
        host.stop()
        return control.STOP
    return host.send_frame(control.store(kind))


# ---------------------------------------------------------------- monitor --uart2


def run_monitor(
    url: str,
    *,
    as_json: bool,
    duration: float | None,
    count: int | None,
    record: str | None,
    out: TextIO,
    stop_on_exit: bool = False,
) -> int:
    """Print replies and encoder reports as they arrive; passive unless `stop_on_exit`."""
    seen = errors = 0
    with ExitStack() as stack:
        host = open_control_host(stack, url, record, stop_on_close=stop_on_exit)
        print(f"monitoring {host.url} (Ctrl-C to stop)", file=sys.stderr, flush=True)
        try:
            for event in host.events(duration):
                show(host, event, out, as_json)
                errors += isinstance(event, control.Garbage)
                seen += isinstance(event, (control.Reply, control.EncoderReport))
                if count is not None and seen >= count:
                    break
        finally:
            print(
                f"monitor: {seen} replies and reports, {errors} errors in {host.now():.1f} s",
                file=sys.stderr,
            )
    return 0
