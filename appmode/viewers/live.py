"""A live Foxglove server for a session, a board or a replay (`--foxglove [HOST:]PORT`),
through the official foxglove-sdk (the `foxglove` extra).

Nothing here may slow the car's stop: the caller only appends to a bounded queue
(`QUEUE` items; what does not fit is dropped and counted; a `SimpleQueue`, which takes
no lock that a signal's KeyboardInterrupt could leave held), and a worker thread decodes
the bytes (`PortsReader`) into the channels of `protocol.channels` and logs them. The
SDK keeps each viewer's backlog bounded too (`BACKLOG` messages; the oldest dropped for
a viewer that does not read), so a viewer that connects and never reads costs nothing
but its own messages."""

from __future__ import annotations

import json
import logging
import queue
import threading
import time
from typing import Any

from appmode.errors import AppmodeError, install_line
from appmode.protocol.channels import LOG, RAW, RAW_SCHEMA, channels
from appmode.protocol.control_view import view
from appmode.protocol.escaping import escape
from appmode.protocol.layouts import VELOCITY, Layout
from appmode.protocol.params import DriveType
from appmode.protocol.reader import PortsReader
from appmode.session.desk import Desk, Values

QUEUE = 4096
"""Units and notes waiting for the worker at most (seconds of a flood: they are small)."""
BACKLOG = 1024
"""Messages the SDK keeps for each viewer at most (the oldest are dropped)."""


class LiveView:
    """A Foxglove WebSocket server on `host`:`port` (0: a free port), fed as a tap:
    `view(direction, time, data)` with a session's times (seconds from its start),
    `view.note(text)` for what the session says."""

    def __init__(
        self,
        host: str,
        port: int,
        layout: Layout = VELOCITY,
        name: str = "appmode",
        drive: bool = False,
        drive_type: DriveType | None = None,
    ) -> None:
        try:
            import foxglove

            from appmode.viewers import listener
        except ImportError:
            raise AppmodeError(
                f"--foxglove needs the foxglove SDK: {install_line('foxglove')}"
            ) from None
        self._foxglove = foxglove
        self._context = foxglove.Context()
        self.watched = threading.Event()
        """Set when a viewer first subscribes to a channel."""
        self.desk = Desk(self._publish_values) if drive else None
        """What viewers ask of the session (`--foxglove-drive`: drive and tune), if they may."""
        self._listener = listener.Listener(self.watched, self.desk, self.note)
        _quiet_sdk(listener.SdkLog(self._listener))
        try:
            self._server = foxglove.start_server(
                name=name,
                host=host,
                port=port,
                context=self._context,
                message_backlog_size=BACKLOG,
                server_listener=self._listener,
                capabilities=listener.DRIVING if drive else None,
                supported_encodings=listener.ENCODINGS if drive else None,
            )
        except Exception as exc:  # the SDK raises its own errors: a port in use, say
            raise AppmodeError(
                f"--foxglove {host}:{port}: cannot serve there ({exc}): pick another port "
                "(0 picks a free one)"
            ) from None
        self.host = host
        self.port = int(self._server.port)
        self.epoch = time.time()
        """The wall-clock time of the session's time 0 (set by whoever feeds it)."""
        self.dropped = 0
        """Units and notes the queue had no room for."""
        served = [(spec.topic, spec.schema_name, spec.schema) for spec in channels(layout).values()]
        served += [(topic, "appmode.bytes", RAW_SCHEMA) for topic in RAW.values()]
        self._channels: dict[str, Any] = {
            topic: foxglove.Channel(
                topic,
                schema=foxglove.Schema(
                    name=kind, encoding="jsonschema", data=json.dumps(schema).encode()
                ),
                message_encoding="json",
                context=self._context,
            )
            for topic, kind, schema in served
        }
        self._log = foxglove.channels.LogChannel(LOG, context=self._context)
        self._layout = layout
        self._drive_type = drive_type
        self._queue: queue.SimpleQueue[tuple[Any, ...] | None] = queue.SimpleQueue()
        self._thread = threading.Thread(target=self._run, name="foxglove", daemon=True)
        self._thread.start()

    @property
    def url(self) -> str:
        host = f"[{self.host}]" if ":" in self.host else self.host
        return f"ws://{host}:{self.port}"

    # ------------------------------------------------------------ the caller's side

    def __call__(self, direction: str, time: float, data: bytes) -> None:
        self._put(("bytes", direction, time, data))

    def note(self, text: str) -> None:
        self._put(("note", time.time(), text))

    def _put(self, item: tuple[Any, ...]) -> None:
        if self._queue.qsize() < QUEUE:
            self._queue.put(item)
        else:
            self.dropped += 1

    def _publish_values(self, values: Values) -> None:
        """The parameters read back, to the viewers that watch them."""
        from appmode.viewers.listener import listed

        self._server.publish_parameter_values(listed(values, []))

    def close(self, wait: float = 1.0) -> None:
        """Log what is queued (at most `wait` seconds), then stop the server."""
        self._queue.put(None)
        self._thread.join(wait)
        self._server.stop()

    # ------------------------------------------------------------ the worker's side

    def _run(self) -> None:
        from appmode.protocol.channels import Decoded

        reader = PortsReader(layout=self._layout)
        decoded = Decoded(self._layout, self._drive_type)
        while (item := self._queue.get()) is not None:
            if item[0] == "note":
                self._note(item[1], item[2])
                continue
            _, direction, at, data = item
            for shown, event in reader.feed(direction, data):
                self._unit(self.epoch + at, shown, event)
                for topic, body in decoded.unit(self.epoch + at, shown, event):
                    self._channels[topic].log(body, log_time=_ns(self.epoch + at))

    def _unit(self, when: float, direction: str, event: Any) -> None:
        """A unit's bytes, and its line in the log."""
        ns, raw = _ns(when), event.raw
        self._channels[RAW[direction]].log(
            {"text": escape(raw), "hex": raw.hex(), "length": len(raw)}, log_time=ns
        )
        text = view(event, self._layout)[1]
        self._note(when, f"{direction} {escape(raw)}  {text}", level="Debug")

    def _note(self, when: float, text: str, level: str = "Info") -> None:
        fox = self._foxglove
        ns = _ns(when)
        self._log.log(
            fox.messages.Log(
                timestamp=fox.messages.Timestamp(sec=ns // 10**9, nsec=ns % 10**9),
                level=getattr(fox.messages.LogLevel, level),
                message=text,
                name="appmode",
                file="",
                line=0,
            ),
            log_time=ns,
        )


def _quiet_sdk(handler: logging.Handler) -> None:
    """The SDK's log to `handler` alone (its lines would land over a console's screen)."""
    sdk = logging.getLogger("foxglove")
    for old in sdk.handlers[:]:
        sdk.removeHandler(old)
    sdk.addHandler(handler)
    sdk.propagate = False


def _ns(when: float) -> int:
    return round(when * 1e9)
