"""`appmode decode`: a raw byte stream in, JSON Lines out."""

from __future__ import annotations

import json
from collections.abc import Iterable, Iterator
from typing import BinaryIO, TextIO

from . import protocol
from .render import coalesce, to_json

CHUNK = 65536


def decode_chunks(chunks: Iterable[bytes], source: str) -> Iterator[protocol.Event]:
    """Events of a stream from the host (`host`) or the board (`board`)."""
    decoder = protocol.HostDecoder() if source == "host" else protocol.BoardDecoder()
    for chunk in chunks:
        yield from decoder.feed(chunk)
    yield from decoder.flush()


def read_chunks(stream: BinaryIO) -> Iterator[bytes]:
    """Chunks as they arrive (a pipe from a live port is decoded as it goes)."""
    read = getattr(stream, "read1", stream.read)
    while chunk := read(CHUNK):
        yield chunk


def run_decode(stream: BinaryIO, out: TextIO, source: str) -> int:
    """Write one JSON object a line; returns the number of undecodable runs."""
    errors = 0
    for event in coalesce(decode_chunks(read_chunks(stream), source)):
        errors += isinstance(event, protocol.ERRORS)
        out.write(json.dumps(to_json(event), ensure_ascii=False) + "\n")
        out.flush()
    return errors
