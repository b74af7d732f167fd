"""The ending signals' handler (`host.signals`): where raising would break a lock."""

from __future__ import annotations

import signal
import sys
import threading
import time
from collections.abc import Iterator
from types import FrameType
from typing import Any

import pytest

from appmode.host import signals


@pytest.fixture
def handled(monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    """`signals.install()` for the test, this process's handlers put back after it."""
    monkeypatch.setattr(signals, "_ending", signals._Ending())
    before = {
        signum: signal.getsignal(signum) for signum in (signal.SIGINT, *signals.ENDING_SIGNALS)
    }
    signals.install()
    try:
        yield
    finally:
        for signum, handler in before.items():
            signal.signal(signum, handler)


def _signal_at(when: str, code: Any) -> Any:
    """A tracer that calls SIGTERM's handler (as the interpreter does, with the frame it
    is in) at `code`'s "call" (before its first line) or "return" (its work done)."""

    def tracer(frame: FrameType, event: str, arg: object) -> Any:
        if event == when and frame.f_code is code:
            sys.settrace(None)
            signals._handle(signal.SIGTERM, frame)
        return tracer

    return tracer


def test_an_ending_signal_inside_a_conditions_enter_comes_again_with_the_lock_let_go(
    handled: None,
) -> None:
    """A KeyboardInterrupt raised when Condition.__enter__ has taken its lock, but before
    the `with` block began, would leave the lock taken for good (a queue's: every later
    put waits forever). The signal comes again once the block is done."""
    lock = threading.Lock()
    ready = threading.Condition(lock)
    started = time.monotonic()
    inside = False
    with pytest.raises(KeyboardInterrupt):
        sys.settrace(_signal_at("return", threading.Condition.__enter__.__code__))
        try:
            with ready:
                inside = True
        finally:
            sys.settrace(None)
        time.sleep(10)  # the signal comes again here
    assert inside, "the block ran: the signal did not land in the lock step"
    assert not lock.locked(), "the lock is let go"
    assert time.monotonic() - started < 5


def test_an_ending_signal_inside_a_conditions_exit_comes_again_with_the_lock_let_go(
    handled: None,
) -> None:
    lock = threading.Lock()
    ready = threading.Condition(lock)
    with pytest.raises(KeyboardInterrupt):
        sys.settrace(_signal_at("call", threading.Condition.__exit__.__code__))  # lock held
        try:
            with ready:
                pass
        finally:
            sys.settrace(None)
        time.sleep(10)
    assert not lock.locked()


def test_an_ending_signal_elsewhere_raises_at_once(handled: None) -> None:
    with pytest.raises(KeyboardInterrupt):
        signals._handle(signal.SIGTERM, sys._getframe())
    assert signals._ending.ended


def test_an_ending_signal_while_waiting_for_a_lock_held_for_good_still_raises(
    handled: None,
) -> None:
    """A Condition's lock that another thread never lets go: the signal, put off while
    the main thread waits in `__enter__`, raises within PUT_OFF (nothing is held)."""
    lock = threading.Lock()
    lock.acquire()  # held for good, as by a thread that hangs
    ready = threading.Condition(lock)
    sent: list[float] = []

    def signal_the_waiting_main_thread() -> None:
        """SIGTERM once the main thread waits in `__enter__` (a timer could land before
        it got there on a loaded machine, and the signal then rightly raised at once)."""
        main = threading.main_thread().ident
        assert main is not None
        end = time.monotonic() + 5
        while time.monotonic() < end:
            frame = sys._current_frames().get(main)
            if frame is not None and frame.f_code is threading.Condition.__enter__.__code__:
                sent.append(time.monotonic())
                signal.pthread_kill(main, signal.SIGTERM)
                return
            time.sleep(0.01)

    watchdog = threading.Timer(5, lock.release)  # were the signal put off for good
    watchdog.start()
    threading.Thread(target=signal_the_waiting_main_thread, daemon=True).start()
    try:
        with pytest.raises(KeyboardInterrupt), ready:
            time.sleep(10)  # reached only after the watchdog: the signal lands here
    finally:
        watchdog.cancel()
    assert sent, "the main thread never waited in Condition.__enter__"
    took = time.monotonic() - sent[0]
    assert took >= signals.PUT_OFF - 0.1, f"raised at once ({took:.2f} s)"
    assert took < 5, f"raised only after {took:.2f} s"
