"""Transcripts as MCAP, with no I/O: the writer makes the bytes of a file, record by
record, for whoever writes them (a bounded writer, a file); the reader's side maps MCAP
messages back to a transcript's items.

The raw bytes of both directions of every port, with their times, are the lossless
source of truth: one channel per direction (`/raw/app/sent` …), each message a unit's
bytes (JSON: `hex` exact, `text` as a transcript shows them), its sequence number the
transcript line it was (a UART2 unit in APP mode, text in a transcript, on `…/as_text`;
an expectation that no bytes stand for, `??` in a `2<` line, on `…/pattern` as its
text). Directives and comments ride on `/transcript/directives` and
`/transcript/comments`. Beside them, for viewers, the decoded channels of
`protocol.channels` and `/log`. Every channel is JSON with a JSON schema, so a generic
viewer decodes each; the file is chunked (zstd) and indexed, a chunk at least every
FLUSH seconds so that a file cut short keeps all but its last ones.

Log times are the wall clock, in ns since 1970: the session's time plus its start, which
the `appmode` metadata record keeps (and a `@recorded` directive, so that a transcript
converted from the file keeps it); a reader gets the transcript's own times back. Files
of appmode's before these (raw bytes, `appmode.bytes`, log times from 0) read as before."""

from __future__ import annotations

import json
import time
from collections.abc import Iterable
from dataclasses import dataclass
from datetime import datetime, timedelta, timezone
from typing import Any

from mcap.writer import CompressionType, Writer

from appmode.protocol.channels import LOG, RAW, RAW_SCHEMA, Decoded, channels
from appmode.protocol.control_view import view
from appmode.protocol.escaping import escape
from appmode.protocol.layouts import VELOCITY, Layout
from appmode.protocol.transcript import (
    CHASSIS_DIRECTIONS,
    DIRECTIONS,
    TIME_DIGITS,
    UART2_DIRECTIONS,
    Comment,
    Directive,
    Entry,
    Line,
    TranscriptError,
    uart2_payload,
)

PROFILE = "appmode"
"""The MCAP header's profile: a file of appmode's (a transcript and its views)."""
AS_TEXT = "/as_text"
PATTERN = "/pattern"
COMMENTS = "/transcript/comments"
DIRECTIVES = "/transcript/directives"
BYTES = "appmode.bytes"
"""Before JSON: a message that is a unit's bytes, as they went (still read)."""
TEXT = "appmode.text"
"""Before JSON: a message that is UTF-8 text (still read)."""
NS = 10**9
START = "appmode"
"""The metadata record that says when the session's time 0 was (`start_ns`)."""
RECORDED = "recorded"
"""The directive that says it in a transcript: `@recorded 2026-11-29T08:00:00.000000Z`."""
TEXT_SCHEMA = {"type": "object", "properties": {"text": {"type": "string"}}}
LOG_SCHEMA = {
    "title": "foxglove.Log",
    "type": "object",
    "properties": {
        "timestamp": {
            "type": "object",
            "properties": {"sec": {"type": "integer"}, "nsec": {"type": "integer"}},
        },
        "level": {"type": "integer", "description": "1 debug, 2 info, 3 warning, 4 error"},
        "message": {"type": "string"},
        "name": {"type": "string"},
        "file": {"type": "string"},
        "line": {"type": "integer"},
    },
}
DEBUG = 1
CHUNK = 256 * 1024
"""Bytes of messages a chunk holds at most before it is written."""
FLUSH = 1.0
"""Seconds of messages a chunk spans at most (what a file cut short loses)."""


@dataclass(frozen=True, slots=True)
class RawChannel:
    """Where a direction's units go, and how: `form` "" (bytes, shown as the format
    shows them), "as_text" (UART2 bytes shown as APP text), "pattern" (text)."""

    direction: str
    form: str

    @property
    def topic(self) -> str:
        suffix = {"": "", "as_text": AS_TEXT, "pattern": PATTERN}[self.form]
        return RAW[self.direction] + suffix


RAW_CHANNELS = tuple(
    RawChannel(d, form)
    for d in DIRECTIONS
    for form in (("", "pattern") if d in CHASSIS_DIRECTIONS else ("", "as_text", "pattern"))
)
BY_TOPIC = {channel.topic: channel for channel in RAW_CHANNELS}
LINE_TOPICS = {*BY_TOPIC, COMMENTS, DIRECTIVES}
"""The channels a transcript's lines are on (the rest are views of them)."""


def log_time(seconds: float) -> int:
    """A session's time as MCAP's nanoseconds, to the transcript's 0.1 ms."""
    return exact_time(round(seconds, TIME_DIGITS))


def exact_time(seconds: float) -> int:
    """A transcript line's time as MCAP's nanoseconds (read back as the same float to
    the nanosecond: every time a transcript writes)."""
    return max(0, round(seconds * NS))


class _Sink:
    """Where the MCAP writer writes (a stream to it, not a raw one it would buffer): it
    keeps what was written since the last `take`, and counts every byte, for the
    offsets the writer reads with `tell`."""

    def __init__(self) -> None:
        self._data = bytearray()
        self._count = 0

    def flush(self) -> None:
        """Nothing to flush: `take` hands out every byte written."""

    def write(self, data: Any) -> int:
        size = len(data)
        self._data += data
        self._count += size
        return size

    def tell(self) -> int:
        return self._count

    def take(self) -> bytes:
        data = bytes(self._data)
        self._data.clear()
        return data


def recorded(start_ns: int) -> str:
    """The `@recorded` directive's argument for a start (UTC, to the microsecond)."""
    moment = datetime(1970, 1, 1, tzinfo=timezone.utc) + timedelta(microseconds=start_ns // 1000)
    return moment.strftime("%Y-%m-%dT%H:%M:%S.%fZ")


def start_of(text: str, where: str) -> int:
    """The start a `@recorded` argument says, in ns since 1970; TranscriptError if none."""
    try:
        moment = datetime.strptime(text, "%Y-%m-%dT%H:%M:%S.%fZ").replace(tzinfo=timezone.utc)
    except ValueError:
        raise TranscriptError(
            f"{where}: @recorded takes a UTC time such as 2026-11-29T08:00:00.000000Z"
        ) from None
    return (moment - datetime(1970, 1, 1, tzinfo=timezone.utc)) // timedelta(microseconds=1) * 1000


class McapLines:
    """An MCAP file made a record at a time: each method returns the bytes it adds (a
    chunk's when one is done, else nothing). `start_ns`: the wall-clock time of the
    session's time 0 (None: now, a recording's, which `start` writes as a `@recorded`
    directive; a converted transcript's is its own `@recorded`, or 0)."""

    def __init__(
        self, layout: Layout = VELOCITY, library: str = "appmode", start_ns: int | None = None
    ) -> None:
        self._sink = _Sink()
        self._writer = Writer(
            self._sink,  # type: ignore[arg-type]  # a stream to it: write, tell, flush
            chunk_size=CHUNK,
            compression=CompressionType.ZSTD,
            enable_data_crcs=True,
        )
        self._library = library
        self._decoded = Decoded(layout)
        self._layout = layout
        self._ids: dict[str, int] = {}
        self._time = 0
        self._flushed = 0
        self._dated = start_ns is None  # a recording: its start is said in a directive
        self.start_ns = time.time_ns() // 1000 * 1000 if start_ns is None else start_ns

    def _taken(self) -> bytes:
        return self._sink.take()

    def start(self, directives: Iterable[str] = ()) -> bytes:
        """The header, the start's metadata, every channel, and `directives` (`board
        profile=…`; a recording adds `recorded …`)."""
        directives = list(directives)
        if self._dated:
            directives.append(f"{RECORDED} {recorded(self.start_ns)}")
        self._time = self._flushed = self.start_ns
        self._writer.start(profile=PROFILE, library=self._library)
        self._writer.add_metadata(
            START, {"start_ns": str(self.start_ns), "start": recorded(self.start_ns)}
        )
        raw = self._schema("appmode.bytes", RAW_SCHEMA)
        text = self._schema("appmode.text", TEXT_SCHEMA)
        for channel in RAW_CHANNELS:
            self._ids[channel.topic] = self._writer.register_channel(
                channel.topic,
                "json",
                text if channel.form == "pattern" else raw,
                {"direction": channel.direction},
            )
        for topic in (COMMENTS, DIRECTIVES):
            self._ids[topic] = self._writer.register_channel(topic, "json", text, {})
        views = [
            (s.topic, s.schema_name, s.schema, s.description)
            for s in channels(self._layout).values()
        ]
        for topic, name, schema, description in [*views, (LOG, "foxglove.Log", LOG_SCHEMA, "")]:
            self._ids[topic] = self._writer.register_channel(
                topic, "json", self._schema(name, schema), {"description": description}
            )
        for number, directive in enumerate(directives, start=2):
            self._put(DIRECTIVES, {"text": f"@{directive}"}, 0, number)
        return self._taken()

    def _schema(self, name: str, schema: dict[str, Any]) -> int:
        return int(self._writer.register_schema(name, "jsonschema", json.dumps(schema).encode()))

    def _put(self, topic: str, body: dict[str, Any], ns: int, sequence: int = 0) -> None:
        """A message at `ns` of the session's time (the file's in time order)."""
        self._time = max(self._time, self.start_ns + ns)
        self._writer.add_message(
            self._ids[topic],
            log_time=self._time,
            data=json.dumps(body, ensure_ascii=False).encode(),
            publish_time=self._time,
            sequence=sequence & 0xFFFFFFFF,
        )
        if self._time - self._flushed >= FLUSH * NS:
            self._flushed = self._time
            self._writer.flush()  # type: ignore[no-untyped-call]

    def _raw(self, topic: str, data: bytes, ns: int, sequence: int = 0) -> None:
        body = {"text": escape(data), "hex": data.hex(), "length": len(data)}
        self._put(topic, body, ns, sequence)

    def line(self, time: float, raw: bytes, direction: str, text: bool, event: Any = None) -> bytes:
        """A unit as it happened (`text`: a UART2 unit shown as APP text), timed to the
        transcript's 0.1 ms, and its decoded views."""
        form = "as_text" if text and direction in UART2_DIRECTIONS else ""
        self._raw(RawChannel(direction, form).topic, raw, log_time(time))
        if event is not None:
            self._views(time, direction, event)
        return self._taken()

    def decoded(self, time: float, direction: str, event: Any) -> bytes:
        """The decoded views of a unit (for viewers: a reader of the file skips them)."""
        self._views(time, direction, event)
        return self._taken()

    def _views(self, time: float, direction: str, event: Any) -> None:
        ns = exact_time(time)
        wall = (self.start_ns + ns) / NS
        for topic, body in self._decoded.unit(wall, direction, event):
            self._put(topic, body, ns)
        line = f"{direction} {escape(event.raw)}  {view(event, self._layout)[1]}"
        stamp = {"sec": (self.start_ns + ns) // NS, "nsec": (self.start_ns + ns) % NS}
        log = {"timestamp": stamp, "level": DEBUG, "message": line, "name": "appmode"}
        self._put(LOG, {**log, "file": "", "line": 0}, ns)

    def comment(self, time: float, text: str, lineno: int = 0) -> bytes:
        self._put(COMMENTS, {"text": text}, log_time(time), lineno)
        return self._taken()

    def item(self, item: Line, time: float) -> bytes:
        """A transcript's line, as it reads (an entry's bytes where they stand for its
        text, else its text: a `??` pattern); a comment or directive at `time`."""
        if isinstance(item, Comment):
            self._put(COMMENTS, {"text": item.text}, exact_time(time), item.lineno)
        elif isinstance(item, Directive):
            text = " ".join(("@" + item.name, *item.args))
            self._put(DIRECTIVES, {"text": text}, exact_time(time), item.lineno)
        else:
            form = _form(item)
            channel = RawChannel(item.direction, form)
            if form == "pattern":
                self._put(channel.topic, {"text": item.text}, exact_time(item.time), item.lineno)
            else:
                self._raw(channel.topic, item.data, exact_time(item.time), item.lineno)
        return self._taken()

    def finish(self) -> bytes:
        """The last chunk, the file's indexes and summary, its end."""
        self._writer.finish()  # type: ignore[no-untyped-call]
        return self._taken()


def is_pattern(entry: Entry) -> bool:
    """The line is an expectation no bytes stand for (`*`, `LO..HI`, `??`)."""
    return _form(entry) == "pattern"


def _form(entry: Entry) -> str:
    """How `entry`'s bytes show in a transcript: "" as the format writes bytes, "as_text"
    (UART2 APP text), or "pattern" when no bytes stand for its text."""
    if entry.direction in CHASSIS_DIRECTIONS:
        return "" if entry.text == entry.data.hex(" ").upper() else "pattern"
    if entry.direction in UART2_DIRECTIONS:
        if entry.text == uart2_payload(entry.data, False):
            return ""
        return "as_text" if entry.text == uart2_payload(entry.data, True) else "pattern"
    return "" if entry.text == escape(entry.data) else "pattern"
