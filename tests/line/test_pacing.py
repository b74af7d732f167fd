"""Pacing (docs/design.md): 10 bits a byte at the baud rate, deadline-based, no drift."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from appmode.board.firmware import Board
from appmode.line.pacing import Line, byte_time
from appmode.line.wire import Wire
from appmode.protocol.app import Velocity
from appmode.protocol.app_decoders import BoardDecoder

BYTE = 10 / 9600


def test_byte_time_is_ten_bits() -> None:
    assert byte_time(9600) == pytest.approx(1 / 960)
    assert byte_time(None) == 0.0


def test_bytes_are_delivered_at_the_end_of_their_transmission() -> None:
    line = Line(9600)
    line.push(b"abc", 1.0)
    assert line.take(1.0 + BYTE * 0.99) == b""
    assert line.take_timed(1.0 + 2 * BYTE) == [(1.0 + BYTE, b"a"), (1.0 + 2 * BYTE, b"b")]
    assert line.next_due() == pytest.approx(1.0 + 3 * BYTE)
    assert line.take(2.0) == b"c"
    assert line.next_due() is None


def test_a_busy_line_queues_behind_what_it_is_sending() -> None:
    line = Line(9600)
    line.push(b"x" * 10, 0.0)
    line.push(b"y", 0.001)  # the line is busy until 10 byte times
    timed = line.take_timed(1.0)
    assert timed[-1] == (pytest.approx(11 * BYTE), b"y")


def test_no_drift_over_a_million_bytes() -> None:
    line = Line(9600)
    for k in range(1000):
        line.push(b"z" * 1000, 0.0 if k == 0 else 0.5)
    last = line.take_timed(10_000.0)[-1][0]
    assert last == pytest.approx(1_000_000 * BYTE, abs=1e-6)


@pytest.mark.parametrize("baud", [9600, None])
def test_take_gives_every_byte_once_in_order_and_bursts_say_whether_any_remain(
    baud: int | None,
) -> None:
    line = Line(baud)
    sent, got = b"", b""
    for k in range(200):
        now = k * 0.0025
        if k % 7 == 0:  # two bursts at once: a take may end one and start the next
            for data in (bytes([65 + k % 26]) * (1 + k % 5), b"%d" % k):
                line.push(data, now)
                sent += data
        got += line.take(now)
        assert bool(line.bursts) == (len(line) > 0)
    got += line.take(10.0)
    assert got == sent
    assert not line.bursts and len(line) == 0


def test_unpaced_line_delivers_at_once() -> None:
    line = Line(None)
    line.push(b"abc", 2.0)
    assert line.take_timed(2.0) == [(2.0, b"abc")]


def test_wire_output_never_exceeds_the_line_rate() -> None:
    wire = Wire(Board(), 9600)
    wire.to_host.push(b"x" * 6000, 0.0)  # a backlog: the line is saturated for 6.25 s
    delivered = 0
    for ms in range(1, 5001):
        delivered += len(wire.pump(ms / 1000))
        assert delivered <= ms / 1000 * 960 + 1
    assert delivered > 4.9 * 960


def test_wire_board_acts_when_the_byte_would_have_arrived() -> None:
    wire = Wire(Board(), 9600)
    wire.write(b"A", 0.0495)  # arrives 1.04 ms later: after the 50 ms slot
    wire.pump(0.0499)
    assert wire.board.direction == 0
    wire.pump(0.051)
    assert wire.board.direction == 1


def test_wire_records_leave_at_slot_time() -> None:
    seen: list[tuple[str, float, bytes]] = []
    wire = Wire(Board(), None, tap=lambda d, t, b: seen.append((d, t, b)))
    wire.pump(0.2)
    assert [round(t, 3) for _, t, _ in seen] == [0.0, 0.05, 0.1, 0.15, 0.2]
    assert isinstance(BoardDecoder().feed(seen[0][2])[0], Velocity)


def test_wire_catches_up_after_a_stall_without_a_flood() -> None:
    wire = Wire(Board(), 9600)
    wire.pump(0.0)
    out = wire.pump(3600.0)
    assert len(out) < 2000


def test_wire_backlog_to_the_host_is_bounded() -> None:
    wire = Wire(Board(), 9600)
    wire.write(b"".join(b"{%d:4294967295}" % n for n in range(2, 8)), 0.0)
    for k in range(2000):  # a C record (up to 100 bytes) asked for in every 50 ms slot
        wire.write(b"{Q:P}", k * 0.05)
        wire.pump(k * 0.05 + 0.01)
    assert len(wire.to_host) <= 960 + 128
    assert wire.dropped > 0


@given(
    st.lists(
        st.tuples(st.floats(0, 0.05), st.binary(max_size=12), st.sampled_from([9600, 115200])),
        max_size=40,
    )
)
def test_take_gives_what_take_timed_gives_by_then(steps: list[tuple[float, bytes, int]]) -> None:
    """`take`'s one-burst path gives exactly the bytes the general one gives: a twin
    line read with `take_timed` at the same times."""
    baud = steps[0][2] if steps else 9600
    line, twin = Line(baud), Line(baud)
    now = 0.0
    for gap, data, _ in steps:
        now += gap
        line.push(data, now)
        twin.push(data, now)
        now += gap / 2
        assert line.take(now) == b"".join(data for _, data in twin.take_timed(now))
        assert len(line) == len(twin) and bool(line.bursts) == bool(twin.bursts)
