"""What `send`, `params` and `monitor` share, on either port: a host opened with its
recording, its events printed as text or JSON Lines, and read until a count."""

from __future__ import annotations

import json
import sys
from collections.abc import Callable, Iterable, Iterator
from contextlib import ExitStack, closing
from typing import TYPE_CHECKING, TextIO, TypeVar

from appmode.host.client import Event, Host
from appmode.host.control_client import ControlHost
from appmode.host.query import QueryDone, QueryFailed
from appmode.host.state import BoardWarning, LinkStatus
from appmode.protocol.layouts import VELOCITY, Layout
from appmode.protocol.recorder import Recorder
from appmode.protocol.render import describe, line, to_json

if TYPE_CHECKING:
    from appmode.ports.target import Target

H = TypeVar("H", Host, ControlHost)
E = TypeVar("E")


def open_host(
    stack: ExitStack,
    url: Target,
    record: str | None,
    stop_on_close: bool = True,
    layout: Layout = VELOCITY,
    stop_again: bytes | None = None,
    frames_stop: bool = False,
) -> Host:
    """The APP host, then its recording (`with_recording`). With `stop_again` it confirms
    its stop on the board's A records, sending those bytes while the car still moves."""
    host = Host(
        url,
        stop_on_close=stop_on_close,
        layout=layout,
        confirm_stop=stop_again is not None,
        stop_again=stop_again or b"",
        frames_stop=frames_stop,
    )
    return with_recording(stack, host, record)


def with_recording(stack: ExitStack, host: H, record: str | None) -> H:
    """An opened host, then its recording: a URL that does not open leaves the file
    untouched. The recording is closed after the host, so it holds the final stop."""
    try:
        recorder = Recorder.create(record, 0.0, host.target.directives) if record else None
    except BaseException:
        host.close()
        raise
    if recorder is not None:
        stack.enter_context(closing(recorder))
        host.tap = recorder
    return stack.enter_context(host)


def show(host: Host, event: Event, out: TextIO, as_json: bool) -> None:
    if isinstance(event, LinkStatus):
        print(f"appmode: {event.text}", file=sys.stderr, flush=True)
        return
    if isinstance(event, BoardWarning):
        print(f"appmode: WARNING: {event.text}", file=sys.stderr, flush=True)
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
