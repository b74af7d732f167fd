"""Exact wake-ups: a 1 µs timer slack while a deadline is kept, the old one after."""

from __future__ import annotations

import ctypes
import sys
import time

import pytest

from appmode.ports.wakeups import PR_GET_TIMERSLACK, SLACK_NS, exact_wakeups
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
