"""Shared helpers: feed decoders whole, split at every boundary, and byte by byte."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from appmode.protocol import app_decoders

Decoder = app_decoders.HostDecoder | app_decoders.BoardDecoder


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
    make: Callable[[], Any], data: bytes, cuts: list[int], limit: int | None = None
) -> None:
    """Fed in pieces of `cuts` sizes: no exception, buffer within `limit` (the decoder's
    LIMIT by default), every byte in one event, and the same events as fed whole."""
    decoder = make()
    bound = decoder.LIMIT if limit is None else limit
    events: list[Any] = []
    pos = 0
    for size in [*cuts, len(data)]:
        events += decoder.feed(data[pos : pos + size])
        assert decoder.buffered <= bound
        pos += size
    events += decoder.flush()
    assert b"".join(e.raw for e in events) == data
    assert events == decode_whole(make, data)
