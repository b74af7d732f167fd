"""Shared helpers: feed decoders whole, split at every boundary, and byte by byte."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from appmode.protocol import app

Decoder = app.HostDecoder | app.BoardDecoder


def decode_whole(make: Callable[[], Decoder], data: bytes) -> list[Any]:
    decoder = make()
    return [*decoder.feed(data), *decoder.flush()]


def decode_chunks(make: Callable[[], Decoder], chunks: list[bytes]) -> list[Any]:
    decoder = make()
    events: list[Any] = []
    for chunk in chunks:
        events += decoder.feed(chunk)
    return events + decoder.flush()


def assert_split_invariant(make: Callable[[], Decoder], data: bytes) -> list[Any]:
    """Decode whole, split at every boundary and byte by byte; all must agree exactly."""
    whole = decode_whole(make, data)
    for cut in range(1, len(data)):
        assert decode_chunks(make, [data[:cut], data[cut:]]) == whole, f"split at {cut}"
    assert decode_chunks(make, [data[i : i + 1] for i in range(len(data))]) == whole
    assert b"".join(e.raw for e in whole) == data, "every byte belongs to one event"
    return whole


def assert_any_bytes_ok(
    make: type[app.HostDecoder] | type[app.BoardDecoder], data: bytes, cuts: list[int]
) -> None:
    """Fed in pieces of `cuts` sizes: no exception, buffer within LIMIT, every byte in one
    event, and the same events as fed whole."""
    decoder = make()
    events: list[Any] = []
    pos = 0
    for size in [*cuts, len(data)]:
        events += decoder.feed(data[pos : pos + size])
        assert decoder.buffered <= make.LIMIT
        pos += size
    events += decoder.flush()
    assert b"".join(e.raw for e in events) == data
    assert events == decode_whole(make, data)
