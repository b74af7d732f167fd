"""What `send`, `params` and `monitor` share, on either port: a host opened with its
recording, its events printed as text or JSON Lines, and read until a count."""

from __future__ import annotations

import json
import sys
import time
from collections.abc import Callable, Iterable, Iterator
from contextlib import ExitStack, closing
from typing import TYPE_CHECKING, TextIO, TypeVar

from appmode.board.profiles import board_line
from appmode.host.app.client import Event, Host
from appmode.host.app.query import QueryDone
from appmode.host.chassis.client import ChassisHost
from appmode.host.control.client import ControlHost
from appmode.host.events import BoardWarning, FarStop, LinkStatus
from appmode.host.outcomes import QueryFailed
from appmode.line.wire import every
from appmode.ports.recording import open_recorder
from appmode.protocol.render import describe, line, to_json

if TYPE_CHECKING:
    from appmode.ports.choice import BoardChoice
    from appmode.protocol.channels import Viewer

H = TypeVar("H", Host, ControlHost, ChassisHost)
E = TypeVar("E")


def open_host(
    stack: ExitStack,
    choice: BoardChoice,
    record: str | None,
    stop_on_close: bool = True,
    confirm_stop: bool = False,
    view: Viewer | None = None,
) -> Host:
    """The APP host of the board chosen, then its recording (`with_recording`); with
    `confirm_stop` it checks its stop on the board's A records."""
    host = Host(
        choice.target,
        stop_on_close=stop_on_close,
        profile=choice.profile,
        confirm_stop=confirm_stop,
    )
    return with_recording(stack, host, record, view)


def with_recording(stack: ExitStack, host: H, record: str | None, view: Viewer | None = None) -> H:
    """An opened host, then its recording: a URL that does not open leaves the file
    untouched. The recording is closed after the host, so it holds the final stop. A
    live `view` (`--foxglove`) is fed the same bytes."""
    try:
        recorder = (
            open_recorder(
                record,
                0.0,
                board_line(host.profile, host.target.sim_drive),
                layout=host.profile.a_layout,
            )
            if record
            else None
        )
    except BaseException:
        host.close()
        raise
    if recorder is not None:
        stack.enter_context(closing(recorder))
    if view is not None:
        view.epoch = time.time() - host.now()
    tap = every(view, recorder)
    if tap is not None:
        host.tap = tap
    return stack.enter_context(host)


def show(host: Host, event: Event, out: TextIO, as_json: bool) -> None:
    if isinstance(event, LinkStatus):
        print(f"appmode: {event.text}", file=sys.stderr, flush=True)
        return
    if isinstance(event, BoardWarning):
        print(f"appmode: WARNING: {event.text}", file=sys.stderr, flush=True)
        return
    if isinstance(event, FarStop):
        said = "stopped the car" if event.stopped else "could not stop the car"
        print(f"appmode: the car's host {said}: {event.text}", file=sys.stderr, flush=True)
        return
    if isinstance(event, (QueryDone, QueryFailed)):
        return
    if as_json:
        body = to_json(event, host.state.layout)
        out.write(json.dumps({"t": round(host.now(), 3), **body}) + "\n")
    else:
        out.write(line(host.now(), "<", event.raw, describe(event, host.state.layout)) + "\n")
    out.flush()


def until_count(events: Iterable[E], counts: Callable[[E], bool], count: int | None) -> Iterator[E]:
    """`events` until `count` of them are ones that `counts` (all of them when None): a
    monitor on either port stops after its --count."""
    seen = 0
    for event in events:
        yield event
        seen += counts(event)
        if count is not None and seen >= count:
            return


def close_host(host: Host | ChassisHost) -> bytes | None:
    """Close `host`, its stop last, saying on stderr what closing had to do besides and
    when the link was down (the stop not delivered); the stop's bytes, or None. Where
    the stop did not take, the AppmodeError that says so is all that is said."""
    stop = host.close()
    for note in host.notes:
        print(f"appmode: WARNING: {note}", file=sys.stderr)
    if stop is None:
        from appmode.host.link import UNDELIVERED

        print(f"appmode: {UNDELIVERED} (the link is down)", file=sys.stderr)
    return stop
