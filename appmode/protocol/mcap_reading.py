"""MCAP files read back as transcript lines (`mcap_format` says what the files hold):
in file order and bounded memory, each channel's messages by its encoding, times the
session's own; a corrupt, empty or cut file is one line."""

from __future__ import annotations

import json
import struct
import zlib
from collections.abc import Callable, Iterator
from dataclasses import replace
from typing import BinaryIO

from mcap.exceptions import EndOfFile, McapError, RecordLengthLimitExceeded
from mcap.records import Channel, Chunk, DataEnd, Footer, Header, Message, Metadata
from mcap.stream_reader import StreamReader, breakup_chunk

from appmode.protocol.escaping import escape
from appmode.protocol.mcap_format import (
    BY_TOPIC,
    BYTES,
    COMMENTS,
    DIRECTIVES,
    LINE_TOPICS,
    NS,
    PROFILE,
    START,
    TEXT,
)
from appmode.protocol.transcript import (
    CHASSIS_DIRECTIONS,
    UART2_DIRECTIONS,
    Comment,
    Entry,
    Line,
    TranscriptError,
    parse_directive,
    parse_entry,
    uart2_payload,
)

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
    topics: dict[int, Channel] = {}
    last = 1  # the header's line
    start = 0  # the session's time 0 (files from before the wall clock: 0)
    header = False
    try:
        for record in _records(handle):
            if isinstance(record, Header):
                header = _appmode(record, name)
            elif isinstance(record, Metadata) and record.name == START:
                start = int(record.metadata.get("start_ns", "0"))
            elif isinstance(record, Channel):
                topics[record.id] = record
            elif isinstance(record, Message):
                channel = topics.get(record.channel_id)
                if channel is None:
                    raise TranscriptError(
                        f"{name}: a message on channel {record.channel_id}, which no "
                        "channel record declares: the file is corrupt"
                    )
                if channel.topic in LINE_TOPICS:
                    last = record.sequence if record.sequence > last else last + 1
                    yield _item_of(channel, record, record.log_time - start, last, name)
    except (McapError, struct.error, ValueError, KeyError) as exc:
        if not header and not isinstance(exc, RecordLengthLimitExceeded):
            raise TranscriptError(
                f"{name}: an empty or broken MCAP file (no whole header): nothing to read"
            ) from None
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
        said = "a record cut short" if isinstance(exc, struct.error) else str(exc)
        raise TranscriptError(
            f"{name}: not a readable MCAP file ({_shown(said or type(exc).__name__)})"
        ) from None
    if not header:
        raise TranscriptError(f"{name}: an empty MCAP file (it holds no header): nothing to read")


def _appmode(header: Header, name: str) -> bool:
    """True for appmode's header; TranscriptError for another writer's."""
    if header.profile != PROFILE:
        said = f"profile {header.profile!r}" if header.profile else "no profile"
        raise TranscriptError(
            f"{name}: an MCAP file of {_shown(said)}, not an appmode recording "
            "(appmode reads the files it writes: --record FILE.mcap, appmode convert)"
        )
    return True


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
    if chunk.compression and chunk.compression not in ("zstd", "lz4"):
        raise ValueError(f"chunks compressed as {chunk.compression}")
    try:
        data = _decompressed(chunk)
    except Exception as exc:  # each library raises its own: a corrupt chunk, whatever it says
        if isinstance(exc, ImportError):
            raise
        raise ValueError(f"a {chunk.compression} chunk that does not decompress") from None
    return replace(chunk, compression="", data=data)


def _decompressed(chunk: Chunk) -> bytes:
    if chunk.compression == "zstd":
        import zstandard

        return bytes(
            zstandard.ZstdDecompressor().decompress(
                chunk.data, max_output_size=chunk.uncompressed_size
            )
        )
    if chunk.compression == "lz4":
        import lz4.frame

        return bytes(
            lz4.frame.LZ4FrameDecompressor().decompress(
                chunk.data, max_length=chunk.uncompressed_size
            )
        )
    return chunk.data


def _item_of(channel: Channel, message: Message, ns: int, lineno: int, name: str) -> Line:
    where = f"{name}:{lineno}"
    data = _payload(channel, message.data, where)
    if channel.topic == COMMENTS:
        return Comment(lineno, data.decode())
    if channel.topic == DIRECTIVES:
        return parse_directive(data.decode(), lineno, where)
    return entry_of(channel.topic, data, ns, lineno, where)


def _payload(channel: Channel, data: bytes, where: str) -> bytes:
    """A line channel's message as the bytes (or text) it stands for, by its encoding:
    JSON (a unit's `hex`, a text's `text`), or the raw forms of files before JSON."""
    if channel.message_encoding in (BYTES, TEXT):
        return data
    if channel.message_encoding != "json":
        raise TranscriptError(
            f"{where}: {channel.topic} is encoded as {_shown(channel.message_encoding)!r}, "
            "not as appmode writes it (json)"
        )
    try:
        body = json.loads(data)
        if "hex" in body:
            return bytes.fromhex(body["hex"])
        text = body["text"]
        if not isinstance(text, str):
            raise TypeError
        return text.encode()
    except (ValueError, TypeError, KeyError, RecursionError):
        raise TranscriptError(
            f"{where}: a {channel.topic} message that is not appmode's JSON (hex or text)"
        ) from None


def entry_of(topic: str, data: bytes, ns: int, lineno: int, where: str) -> Entry:
    """The transcript line an MCAP raw message was (`ns`: the session's time); TranscriptError
    if it is no line."""
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
