"""Transcripts as MCAP, with no I/O: the writer makes the bytes of a file, record by
record, for whoever writes them (a bounded writer, a file); the reader's side maps MCAP
messages back to a transcript's items.

The raw bytes of both directions of both ports, with their times, are the lossless
source of truth: one channel per direction (`/raw/app/sent` …), each message a unit's
bytes, its log time the unit's, its sequence number the transcript line it was (a
UART2 unit in APP mode, text in a transcript, on `…/as_text`; an expectation that no
bytes stand for, `??` in a `2<` line, on `…/pattern` as its text). Directives and
comments ride on `/transcript/directives` and `/transcript/comments`. Beside them, for
viewers, the decoded channels of `protocol.channels`, JSON with JSON schemas."""

from __future__ import annotations

import json
import struct
import zlib
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, replace
from typing import Any, BinaryIO

from mcap.exceptions import EndOfFile, McapError, RecordLengthLimitExceeded
from mcap.opcode import Opcode
from mcap.records import Channel, Chunk, DataEnd, Footer, Header, Message
from mcap.stream_reader import StreamReader, breakup_chunk
from mcap.writer import CompressionType, Writer

from appmode.protocol.channels import RAW, Decoded, channels
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
    parse_directive,
    parse_entry,
    uart2_payload,
)

PROFILE = "appmode"
"""The MCAP header's profile: a file of appmode's (a transcript and its views)."""
AS_TEXT = "/as_text"
PATTERN = "/pattern"
COMMENTS = "/transcript/comments"
DIRECTIVES = "/transcript/directives"
BYTES = "appmode.bytes"
"""A message that is a unit's bytes, as they went."""
TEXT = "appmode.text"
"""A message that is UTF-8 text: a comment, a directive, a pattern's payload."""
NS = 10**9


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
        self.crc = 0
        """CRC-32 of every byte taken so far (the data section, until `finish`)."""

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
        self.crc = zlib.crc32(data, self.crc)
        return data


class McapLines:
    """An MCAP file made a record at a time: each method returns the bytes it adds
    (unchunked, so that a file cut short keeps every message written before)."""

    def __init__(self, layout: Layout = VELOCITY, library: str = "appmode") -> None:
        self._sink = _Sink()
        self._writer = Writer(
            self._sink,  # type: ignore[arg-type]  # a stream to it: write, tell, flush
            use_chunking=False,
            compression=CompressionType.NONE,
        )
        self._library = library
        self._decoded = Decoded(layout)
        self._layout = layout
        self._ids: dict[str, int] = {}
        self._time = 0

    def _taken(self) -> bytes:
        return self._sink.take()

    def start(self, directives: Iterable[str] = ()) -> bytes:
        """The header, every channel, and `directives` (`board profile=…`)."""
        self._writer.start(profile=PROFILE, library=self._library)
        for channel in RAW_CHANNELS:
            encoding = TEXT if channel.form == "pattern" else BYTES
            self._ids[channel.topic] = self._writer.register_channel(
                channel.topic, encoding, 0, {"direction": channel.direction}
            )
        for topic in (COMMENTS, DIRECTIVES):
            self._ids[topic] = self._writer.register_channel(topic, TEXT, 0, {})
        for spec in channels(self._layout).values():
            schema = self._writer.register_schema(
                spec.schema_name, "jsonschema", json.dumps(spec.schema).encode()
            )
            self._ids[spec.topic] = self._writer.register_channel(
                spec.topic, "json", schema, {"description": spec.description}
            )
        for number, directive in enumerate(directives, start=2):
            self._put(DIRECTIVES, f"@{directive}".encode(), 0, number)
        return self._taken()

    def _put(self, topic: str, data: bytes, ns: int, sequence: int = 0) -> None:
        self._time = max(self._time, ns)  # the file's messages in time order
        self._writer.add_message(
            self._ids[topic],
            log_time=self._time,
            data=data,
            publish_time=self._time,
            sequence=sequence & 0xFFFFFFFF,
        )

    def line(self, time: float, raw: bytes, direction: str, text: bool, event: Any = None) -> bytes:
        """A unit as it happened (`text`: a UART2 unit shown as APP text), timed to the
        transcript's 0.1 ms, and its decoded views."""
        form = "as_text" if text and direction in UART2_DIRECTIONS else ""
        self._put(RawChannel(direction, form).topic, raw, log_time(time))
        if event is not None:
            self._views(time, direction, event)
        return self._taken()

    def decoded(self, time: float, direction: str, event: Any) -> bytes:
        """The decoded views of a unit (for viewers: a reader of the file skips them)."""
        self._views(time, direction, event)
        return self._taken()

    def _views(self, time: float, direction: str, event: Any) -> None:
        for topic, body in self._decoded.unit(time, direction, event):
            self._put(topic, json.dumps(body).encode(), exact_time(time))

    def comment(self, time: float, text: str, lineno: int = 0) -> bytes:
        self._put(COMMENTS, text.encode(), log_time(time), lineno)
        return self._taken()

    def item(self, item: Line, time: float) -> bytes:
        """A transcript's line, as it reads (an entry's bytes where they stand for its
        text, else its text: a `??` pattern); a comment or directive at `time`."""
        if isinstance(item, Comment):
            self._put(COMMENTS, item.text.encode(), exact_time(time), item.lineno)
        elif isinstance(item, Directive):
            text = " ".join(("@" + item.name, *item.args))
            self._put(DIRECTIVES, text.encode(), exact_time(time), item.lineno)
        else:
            form = _form(item)
            data = item.text.encode() if form == "pattern" else item.data
            channel = RawChannel(item.direction, form)
            self._put(channel.topic, data, exact_time(item.time), item.lineno)
        return self._taken()

    def finish(self) -> bytes:
        """The file's end: its Data End record carries the CRC of all before it (the
        writer leaves it 0 in a file it does not chunk), so a reader finds a flipped
        byte."""
        crc = self._sink.crc
        self._writer.finish()  # type: ignore[no-untyped-call]
        data = bytearray(self._sink.take())
        at = 0
        while data[at] != Opcode.DATA_END:  # channels registered and not yet written
            (length,) = struct.unpack_from("<Q", data, at + 1)
            crc = zlib.crc32(data[at : at + 9 + length], crc)
            at += 9 + length
        struct.pack_into("<I", data, at + 9, crc)
        return bytes(data)


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


RECORD_LIMIT = 16 * 1024 * 1024
"""Bytes one MCAP record (a chunk, compressed or not) may take: a reader's memory bound."""


def read_items(
    handle: BinaryIO,
    name: str,
    warn: Callable[[str], None],
    whole: bool | None = None,
    partial: bool = False,
) -> Iterator[Line]:
    """The transcript lines an MCAP file holds, in file order, in bounded memory: its
    raw channels' messages as entries, its comments and directives; the decoded
    channels are for viewers and skipped. TranscriptError (one line) if the file is no
    appmode MCAP, is corrupt or cut short (a recording stopped by a full disk: with
    `partial`, what it holds, and `warn` says it was cut). `whole`: whether the file ends as MCAP
    files end (then a bad record is corruption), None if that could not be seen (a
    pipe: a bad record at its end is taken for an end cut short)."""
    topics: dict[int, str] = {}
    last = 1  # the header's line
    try:
        for record in _records(handle):
            if isinstance(record, Header) and record.profile != PROFILE:
                said = f"profile {record.profile!r}" if record.profile else "no profile"
                raise TranscriptError(
                    f"{name}: an MCAP file of {_shown(said)}, not an appmode recording "
                    "(appmode reads the files it writes: --record FILE.mcap, appmode convert)"
                )
            if isinstance(record, Channel):
                topics[record.id] = record.topic
            elif isinstance(record, Message):
                topic = topics.get(record.channel_id)
                if topic is None:
                    raise TranscriptError(
                        f"{name}: a message on channel {record.channel_id}, which no "
                        "channel record declares: the file is corrupt"
                    )
                if topic in LINE_TOPICS:
                    last = record.sequence if record.sequence > last else last + 1
                    yield _item_of(topic, record, last, name)
    except (McapError, struct.error, ValueError, KeyError) as exc:
        if isinstance(exc, RecordLengthLimitExceeded):
            whole = True  # no cut makes a record longer
        if not whole and (whole is False or isinstance(exc, EndOfFile) or not handle.read(1)):
            if not partial:
                raise TranscriptError(
                    f"{name}: the MCAP file is cut short (it has no end): appmode convert "
                    f"--partial {name} OUT writes what it holds"
                ) from None
            warn(f"{name}: the MCAP file is cut short (it has no end): read what it holds")
            return
        raise TranscriptError(f"{name}: not a readable MCAP file ({_shown(str(exc))})") from None


def _shown(text: str, limit: int = 100) -> str:
    """Text from a file, fit for a message: one line of printable characters."""
    text = "".join(c if c.isprintable() else "?" for c in text)
    return text if len(text) <= limit else text[: limit - 1] + "…"


class _Summed:
    """A stream read through, keeping the CRC-32 of what was read since `mark`, but for
    the last 4 bytes (a Footer's own CRC, when it was the last record read)."""

    def __init__(self, handle: BinaryIO) -> None:
        self._handle = handle
        self._tail = b""
        self.crc = 0

    def read(self, size: int = -1) -> bytes:
        data = self._handle.read(size)
        both = self._tail + data
        self.crc = zlib.crc32(both[:-4], self.crc)
        self._tail = both[-4:]
        return data

    def mark(self) -> None:
        self.crc, self._tail = 0, b""


def _records(handle: BinaryIO) -> Iterator[object]:
    """The file's records, chunks opened (each at most RECORD_LIMIT bytes, whatever its
    header claims), their CRCs checked: the data section's, each chunk's, the
    summary's."""
    summed = _Summed(handle)
    reader = StreamReader(
        summed,  # type: ignore[arg-type]  # a stream: read
        emit_chunks=True,
        validate_crcs=True,
        record_size_limit=RECORD_LIMIT,
    )
    for record in reader.records:
        if isinstance(record, Chunk):
            yield from breakup_chunk(_opened(record), validate_crc=True)
            continue
        if isinstance(record, DataEnd):
            summed.mark()
        elif isinstance(record, Footer) and record.summary_crc not in (0, summed.crc):
            raise ValueError("the summary's CRC does not match: the file is corrupt")
        yield record


def _opened(chunk: Chunk) -> Chunk:
    """`chunk` decompressed, in at most RECORD_LIMIT bytes."""
    if chunk.uncompressed_size > RECORD_LIMIT:
        raise ValueError(f"a chunk of {chunk.uncompressed_size:,} bytes")
    if chunk.compression == "zstd":
        import zstandard

        data = zstandard.ZstdDecompressor().decompress(
            chunk.data, max_output_size=chunk.uncompressed_size
        )
    elif chunk.compression == "lz4":
        import lz4.frame

        data = lz4.frame.LZ4FrameDecompressor().decompress(
            chunk.data, max_length=chunk.uncompressed_size
        )
    elif chunk.compression:
        raise ValueError(f"chunks compressed as {chunk.compression}")
    else:
        data = chunk.data
    return replace(chunk, compression="", data=data)


def _item_of(topic: str, message: Message, lineno: int, name: str) -> Line:
    where = f"{name}:{lineno}"
    if topic == COMMENTS:
        return Comment(lineno, message.data.decode())
    if topic == DIRECTIVES:
        return parse_directive(message.data.decode(), lineno, where)
    return entry_of(topic, message.data, message.log_time, lineno, where)


def entry_of(topic: str, data: bytes, ns: int, lineno: int, where: str) -> Entry:
    """The transcript line an MCAP raw message was; TranscriptError if it is no line."""
    channel = BY_TOPIC[topic]
    time = ns / NS
    if channel.form == "pattern":
        return parse_entry(f"{time} {channel.direction} {data.decode()}", lineno, where)
    if channel.direction in CHASSIS_DIRECTIONS:
        payload = data.hex(" ").upper()
    elif channel.direction in UART2_DIRECTIONS:
        payload = uart2_payload(data, channel.form == "as_text")
    else:
        payload = escape(data)
    return Entry(lineno, time, channel.direction, data, payload)
