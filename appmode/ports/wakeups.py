"""Exact wake-ups: Linux wakes a sleeping thread up to 50 µs after its timeout (the
thread's timer slack, so that wake-ups can be batched); a thread whose point is a
deadline asks for 1 µs while it keeps one. Elsewhere this changes nothing."""

from __future__ import annotations

import sys
from collections.abc import Iterator
from contextlib import contextmanager

PR_SET_TIMERSLACK, PR_GET_TIMERSLACK = 29, 30
SLACK_NS = 1000


@contextmanager
def exact_wakeups() -> Iterator[None]:
    """This thread's sleeps and select timeouts end within ~1 µs of their time while
    the block runs (prctl PR_SET_TIMERSLACK on Linux); the slack is restored after."""
    if sys.platform != "linux":
        yield
        return
    import ctypes

    try:
        prctl = ctypes.CDLL(None, use_errno=True).prctl
    except (OSError, AttributeError):
        yield
        return
    old = prctl(PR_GET_TIMERSLACK, 0, 0, 0, 0)
    changed = old > 0 and prctl(PR_SET_TIMERSLACK, SLACK_NS, 0, 0, 0) == 0
    try:
        yield
    finally:
        if changed:
            prctl(PR_SET_TIMERSLACK, old, 0, 0, 0)
