"""A paced board's bytes trickle in as from a real UART: never faster than the line,
never a whole record at once (a host that expects whole records per read must fail
here as it would on a car)."""

from __future__ import annotations

import os
import selectors
import time
import tty

import pytest

from appmode.line.pacing import byte_time
from appmode.protocol.app import ParamsRecord
from appmode.protocol.app_decoders import BoardDecoder
from tests.support.processes import board_process

BYTE = byte_time(9600)


def _read_timed(fd: int, seconds: float) -> list[tuple[float, bytes]]:
    sel = selectors.DefaultSelector()
    sel.register(fd, selectors.EVENT_READ)
    chunks = []
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        if sel.select(0.05):
            chunks.append((time.monotonic(), os.read(fd, 4096)))
    return chunks


@pytest.mark.timing
def test_a_c_record_arrives_over_its_wire_time_and_never_faster() -> None:
    """Judged on a read the reader made in time: a reader the machine kept waiting past
    the record's 32 ms (beside six workers on two cores) finds it whole, as on a car,
    and that read tells nothing; each of three tries reads the C record afresh."""
    spreads = []
    for _ in range(3):
        chunks, spread, wire = _c_record()
        spreads.append(spread)
        # never faster than the line: after the first read, bytes come at most one per
        # byte time (one read's worth of slack for a reader that was late)
        t0, before = chunks[0][0], 0
        for t, chunk in chunks[1:]:
            before += len(chunk)
            assert before <= (t - t0) / BYTE + 8, f"{before} bytes in {1000 * (t - t0):.1f} ms"
        if spread > wire / 2:
            return
    raise AssertionError(f"the C record came whole each time: {spreads} s, its wire time {wire}")


def _c_record() -> tuple[list[tuple[float, bytes]], float, float]:
    """A board's answer to `{Q:P}` as read: the timed chunks, the time between the C
    record's first and last bytes' reads, and its wire time."""
    with board_process("--quiet") as board:
        fd = os.open(board.url, os.O_RDWR | os.O_NOCTTY)
        try:
            tty.setraw(fd)
            os.write(fd, b"{Q:P}")
            chunks = _read_timed(fd, 1.0)
        finally:
            os.close(fd)
    data = b"".join(c for _, c in chunks)
    events = BoardDecoder().feed(data)
    assert any(isinstance(e, ParamsRecord) for e in events), data[:200]
    # where the C record's first and last bytes arrived
    start = data.index(b"{C")
    end = start + len(next(e for e in events if isinstance(e, ParamsRecord)).raw) - 1
    offsets, pos = [], 0
    for t, chunk in chunks:
        offsets.append((pos, pos + len(chunk), t))
        pos += len(chunk)
    first = next(t for a, b, t in offsets if a <= start < b)
    last = next(t for a, b, t in offsets if a <= end < b)
    return chunks, last - first, (end - start + 1) * BYTE  # 31 bytes: 32 ms
