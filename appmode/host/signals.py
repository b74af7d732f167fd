"""The signals that end a host session the way Ctrl-C does, the car stopped.

SIGTERM is a polite kill; SIGHUP is a closed terminal or a dropped SSH connection; SIGINT
is Ctrl-C. `install()` gives all three one handler, which:

- raises KeyboardInterrupt once: a session that has begun to end is not interrupted
  again (systemd sends SIGTERM and SIGHUP together), so its stop goes out;
- waits while an `atomic()` step runs — a write and the bookkeeping of what it sent —
  so that what the session end knows is what really left;
- calls the action of `diverted()` instead, where raising would land in the wrong place
  (the console's event loop: the action asks it to quit);
- does not raise inside `threading.Condition`'s `__enter__` or `__exit__` (queues and
  events use them): there it would leave the lock held and the next hand on it (a
  queue's, a writer's) waiting for good; the signal comes again RETRY seconds later,
  and after PUT_OFF seconds of that (a lock that another thread never lets go) it raises.
"""

from __future__ import annotations

import signal
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing: start-up stays short
if TYPE_CHECKING:
    from types import FrameType
    from typing import Any

ENDING_SIGNALS: tuple[signal.Signals, ...] = tuple(
    getattr(signal, name) for name in ("SIGTERM", "SIGHUP") if hasattr(signal, name)
)


class _Ending:
    def __init__(self) -> None:
        self.ended = False  # an ending signal has been acted on
        self.since: float | None = None  # when the first ending signal came (monotonic)
        self.depth = 0  # atomic steps under way
        self.put_off = 0  # times a signal came again, having landed in a lock step
        self.pending = False  # a signal came during one
        self.action: Callable[[], None] | None = None
        self.before: dict[int, Any] = {}  # the handlers install() replaced


_ending = _Ending()


def install() -> None:
    """Handle SIGINT, SIGTERM and SIGHUP as above (in the main thread), from now: an
    ending acted on before is forgotten."""
    _ending.ended = _ending.pending = False
    _ending.put_off = 0
    _ending.since = None
    for signum in (signal.SIGINT, *ENDING_SIGNALS):
        _ending.before[signum] = signal.signal(signum, _handle)


def finish() -> None:
    """The command is over: after an ending, further signals are ignored to the end
    (the interpreter's shutdown would otherwise meet them with the default action);
    else the handlers `install` found are put back."""
    for signum, before in _ending.before.items():
        signal.signal(signum, signal.SIG_IGN if _ending.ended else before)
    _ending.before.clear()


def ending_since() -> float | None:
    """When (time.monotonic) the first ending signal of this command came, or None:
    the stop guard (`session.authority`) acts when the session has not ended soon
    after."""
    return _ending.since


LAST_WAIT = 0.1
"""Seconds a wait at the end of a command has at least, even when an ending signal's
budget is spent: a reader that reads (a pipe, a FIFO with a reader) gets what is left."""


def left(budget: float) -> float:
    """Seconds of a wait of `budget` for a reader at the end of a command: all of it, or
    after an ending signal what is left of it counted from the signal, and LAST_WAIT at
    least (a loaded machine that acts on the signal late does not make the end later
    still by a whole budget)."""
    since = _ending.since
    return budget if since is None else max(LAST_WAIT, since + budget - time.monotonic())


RETRY = 0.005
"""Seconds after which a signal that came inside a Condition's lock step comes again."""
PUT_OFF = 0.5
"""Seconds a signal is put off so at most: a step that long is waiting for the lock, not
holding it, and raising there leaves nothing held."""

_LOCK_STEPS = frozenset(
    (threading.Condition.__enter__.__code__, threading.Condition.__exit__.__code__)
)


def _handle(signum: int, frame: FrameType | None) -> None:
    if _ending.since is None:
        _ending.since = time.monotonic()
    if _ending.ended:
        return
    if _ending.depth:
        _ending.pending = True
        return
    if frame is not None and frame.f_code in _LOCK_STEPS and _ending.put_off * RETRY < PUT_OFF:
        _ending.put_off += 1
        again = threading.Timer(RETRY, _again, (signum,))
        again.daemon = True
        again.start()
        return
    _ending.ended = True
    if _ending.action is not None:
        _ending.action()
        return
    raise KeyboardInterrupt


def _again(signum: int) -> None:
    """A signal put off by `_handle`, sent again while its handler is still ours: to the
    main thread, whose wait (a sleep, a read) it cuts short as the first one would."""
    if signal.getsignal(signum) is not _handle:
        return
    main = threading.main_thread().ident
    if hasattr(signal, "pthread_kill") and main is not None:
        signal.pthread_kill(main, signum)
    else:  # Windows: its one ending signal, SIGINT, wakes the main thread's waits
        signal.raise_signal(signum)


@contextmanager
def atomic() -> Iterator[None]:
    """A step that an ending signal must not cut in two: the signal takes effect when
    the step is done. Signals reach the main thread only: another thread's step (the
    stop guard's) needs no such care."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    _ending.depth += 1
    try:
        yield
    finally:
        _ending.depth -= 1
        if not _ending.depth and _ending.pending:
            _ending.pending = False
            _handle(0, None)


@contextmanager
def diverted(action: Callable[[], None]) -> Iterator[None]:
    """While inside, an ending signal calls `action` (which must be safe to call from a
    signal handler) instead of raising KeyboardInterrupt."""
    before = _ending.action
    _ending.action = action
    try:
        yield
    finally:
        _ending.action = before
