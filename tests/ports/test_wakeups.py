"""Exact wake-ups: a 1 µs timer slack and a short slice while a deadline is kept, the
old ones after."""

from __future__ import annotations

import ctypes
import math
import platform
import selectors
import socket
import subprocess
import sys
import time

import pytest

from appmode.board.firmware import Board
from appmode.ports import serve
from appmode.ports.serve import GATHER, BoardServer
from appmode.ports.wakeups import (
    PR_GET_TIMERSLACK,
    SLACK_NS,
    SLICE_NS,
    SchedAttr,
    exact_wakeups,
    sched_attr,
    select_exactly,
    syscall_numbers,
)
from appmode.transcript.replay import play

linux = pytest.mark.skipif(sys.platform != "linux", reason="timer slack is Linux's")


def slack() -> int:
    return int(ctypes.CDLL(None).prctl(PR_GET_TIMERSLACK, 0, 0, 0, 0))


@linux
def test_the_slack_is_1_us_inside_and_restored_after() -> None:
    before = slack()
    assert before > SLACK_NS  # 50 µs by default
    with exact_wakeups():
        assert slack() == SLACK_NS
    assert slack() == before


@linux
def test_the_slack_is_restored_when_the_block_raises() -> None:
    before = slack()
    with pytest.raises(KeyboardInterrupt), exact_wakeups():
        raise KeyboardInterrupt
    assert slack() == before


def test_a_replay_is_never_early() -> None:
    sent: list[float] = []
    start = time.monotonic()
    late = play([(k * 0.003, b"A") for k in range(30)], lambda _: sent.append(time.monotonic()))
    assert min(late) >= 0
    assert all(s - start >= k * 0.003 for k, s in enumerate(sent))


def current() -> SchedAttr:
    attr = sched_attr(ctypes.CDLL(None))
    assert attr is not None, f"sched_getattr failed on {platform.machine()}"
    return attr


@linux
def test_the_slice_is_short_inside_and_restored_after() -> None:
    before = current()
    with exact_wakeups():
        inside = current()
    after = current()
    assert (inside.policy, inside.nice) == (before.policy, before.nice)
    # Kernels before 6.12 have no slice per thread and report none.
    assert inside.runtime == (SLICE_NS if before.runtime else 0)
    assert (after.policy, after.nice, after.runtime) == (
        before.policy,
        before.nice,
        before.runtime,
    )


@linux
def test_a_niced_thread_keeps_its_nice_value() -> None:
    code = (
        "import ctypes, os\n"
        "from appmode.ports.wakeups import exact_wakeups, sched_attr\n"
        "os.nice(5)\n"
        "with exact_wakeups():\n"
        "    print(sched_attr(ctypes.CDLL(None)).nice)\n"
        "print(sched_attr(ctypes.CDLL(None)).nice)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["5", "5"]


def test_a_32_bit_program_uses_its_own_syscall_numbers_on_a_64_bit_kernel() -> None:
    assert syscall_numbers("x86_64", 8) == (314, 315)
    assert syscall_numbers("x86_64", 4) == (351, 352)  # i386's, not x86_64's
    assert syscall_numbers("aarch64", 8) == (274, 275)
    assert syscall_numbers("aarch64", 4) == (380, 381)  # 32-bit ARM's
    assert syscall_numbers("armv7l", 4) == (380, 381)
    assert syscall_numbers("mips", 4) is None  # not known: nothing is called


class Quiet:
    """An endpoint that takes what it is given (no I/O)."""

    baud = None

    def __init__(self, sel: object, log: object) -> None:
        """Nothing to open."""

    def write(self, data: bytes) -> None:
        """Dropped."""

    def pause(self, paused: bool) -> None:
        """Never paused."""

    def close(self) -> None:
        """Nothing to close."""


@linux
def test_a_board_server_runs_with_exact_wakeups(monkeypatch: pytest.MonkeyPatch) -> None:
    """A served board's grid points are kept on a busy machine as a replay's deadlines
    are: the serving thread runs with the 1 µs slack (and short slice) while it serves."""
    seen: list[int] = []
    step = BoardServer._step

    def watched(self: BoardServer) -> float:
        seen.append(slack())
        if len(seen) == 3:
            self.stop()
        return step(self)

    monkeypatch.setattr(BoardServer, "_step", watched)
    before = slack()
    server = BoardServer([Quiet], [Board()], pace=True, log=lambda text: None, make_uart2=[Quiet])
    try:
        server.run()
    finally:
        server.close()
    assert seen == [SLACK_NS] * 3
    assert slack() == before


def test_an_exact_select_gives_what_is_ready() -> None:
    sel = selectors.DefaultSelector()
    here, there = socket.socketpair()
    try:
        sel.register(here, selectors.EVENT_READ, "mine")
        assert select_exactly(sel, 0.002) == []
        there.send(b"x")
        assert [(key.data, events) for key, events in select_exactly(sel, 5.0)] == [
            ("mine", selectors.EVENT_READ)
        ]
        assert [key.data for key, _ in select_exactly(sel, 0)] == ["mine"]
    finally:
        sel.close()
        here.close()
        there.close()


@linux
def test_an_exact_select_ends_within_the_millisecond_epoll_would_round_up_to() -> None:
    """A wait of 0.3 ms is never shorter, and not the whole millisecond an epoll
    selector's own wait takes (most of the time: the machine may be busy)."""
    sel = selectors.DefaultSelector()
    waits = []
    try:
        with exact_wakeups():
            for _ in range(40):
                start = time.monotonic()
                assert select_exactly(sel, 0.0003) == []
                waits.append(time.monotonic() - start)
    finally:
        sel.close()
    assert min(waits) >= 0.0003
    assert sorted(waits)[len(waits) // 2] < 0.0009, waits


def test_a_server_wakes_once_for_the_boards_due_in_one_slot(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Boards at their own phases of the grid are run in wake-ups at whole GATHER slots:
    fewer wake-ups than boards due, none early, none over a slot late."""
    clock = [0.0]
    wakes: list[float] = []

    def waited(sel: object, timeout: float) -> list[object]:
        clock[0] = max(clock[0] + timeout, math.nextafter(clock[0], math.inf))  # it goes on
        wakes.append(clock[0])
        if clock[0] > 1.0:
            server.stop()
        return []

    monkeypatch.setattr(serve, "select_exactly", waited)
    boards = [Board() for _ in range(100)]  # a grid point every 40 µs: 5 in a slot
    server = BoardServer([Quiet] * 100, boards, pace=True, log=lambda text: None)
    server.now = lambda: clock[0]  # type: ignore[method-assign]
    server.lateness = []
    try:
        server.run()
    finally:
        server.close()
    late = server.lateness
    assert min(late) >= 0
    assert max(late) <= GATHER + 1e-9
    slots = [round(w / GATHER) for w in wakes]
    assert all(abs(w - s * GATHER) < 1e-9 for w, s in zip(wakes, slots, strict=True))
    assert len(wakes) < 0.8 * len(late)  # boards due in one slot shared a wake-up
