"""The stop authority: one guard over every motion of a session, whatever started it.

Motion lasts only while its source proves it is alive. The session checks the sources
at each tick (`BaseSession.watch`): a held key's repeats (`hold.HoldToDrive`), a page's
heartbeats (`lease`). This guard watches the tick itself, from a thread of its own, so
that nothing the view blocks on can keep the car moving:

- a motion whose source went quiet by its own clock (a held key's repeats, a page's
  heartbeats: `lapsed`) over LAPSE seconds ago gets its port's stop from here, whether or
  not the session could tick to act on it (a session that ticks acts on it first);
- a session whose ticks stop for STALL seconds while the car moves (a view blocked on a
  terminal, a pipe, a disk) gets its port's stop from here, and the session forgets the
  motion at its next tick. Only time the process ran counts: a gap between the guard's
  own looks of over LATE (the whole process was not scheduled, on a loaded machine)
  counts as LATE, so a session is judged on what it did while it could tick, and a
  write a shared car's host has yet to acknowledge (`host.far`) is the link's wait;
- after an ending signal (`signals.ending_since`), a session still not closed within
  GRACE seconds gets its stop from here, and the process ends (status 130): a signal
  ends the session within a second, whatever is blocked.
"""

from __future__ import annotations

import contextlib
import os
import sys
import threading
import time
from collections.abc import Callable
from pathlib import Path

from appmode.host import far, signals

STALL = 0.25
"""Seconds without a tick, the car moving, before the guard stops it."""
GRACE = 0.8
"""Seconds after an ending signal before the guard stops the car and ends the process."""
STEP = 0.02
"""Seconds between the guard's looks."""
LATE = 0.1
"""The most a gap between two of the guard's looks counts towards STALL: a longer one
means the process was not running at all (the session could not tick either)."""
STARVED = 1.0
"""Seconds without a tick, the car moving, after which the guard stops it even though
the session's thread was only waiting for a CPU (a machine too busy to run it)."""
LAPSE = 0.1
"""Seconds a motion's source may be past its own deadline before the guard stops it."""
STALLED = (
    f"over {STALL:g} s without a tick while driving (its view or script was blocked or waiting)"
)
TASKS = Path("/proc/self/task")
"""Linux's view of this process's threads (elsewhere there is none: waits count)."""


def thread_times(thread: int) -> tuple[float, float] | None:
    """Seconds a thread of this process (its native id) has run, and has waited for a
    CPU while it could run, where the system says (Linux's schedstat); else None."""
    try:
        ran, waited = (TASKS / str(thread) / "schedstat").read_bytes().split()[:2]
        return int(ran) / 1e9, int(waited) / 1e9
    except (OSError, ValueError):
        return None


def runnable(thread: int) -> bool:
    """Whether a thread of this process is running or waiting for a CPU (Linux's state
    R), rather than blocked; False where the system does not say."""
    try:
        fields = (TASKS / str(thread) / "stat").read_bytes().rsplit(b")", 1)[1].split()
    except (OSError, IndexError):
        return False
    return fields[:1] == [b"R"]


class StopGuard:
    """A thread that stops the car when the session's ticks stall (`beat` is each tick)
    or an ending signal is not acted on."""

    def __init__(
        self,
        moving: Callable[[], bool],
        stop: Callable[[], None],
        lapsed: Callable[[], str | None] = lambda: None,
    ) -> None:
        self._moving = moving
        self._stop = stop
        """Sends the port's stop and nothing else (safe from this thread: the link's
        writes are serialised)."""
        self._lapsed = lapsed
        """What to say when the motion's source is over LAPSE past its own deadline
        ("": nothing, as for a key let go); None while it is alive."""
        self.why = ""
        """Why the guard last stopped the car, for people ("" when there is nothing to
        say)."""
        self._beat = time.monotonic()
        self._ticker = threading.get_native_id()
        """The thread that ticks (the session's), whose waits for a CPU do not count."""
        self.fired = False
        """The guard sent (or is sending) a stop the session has not noted yet (`beat`)."""
        self._closed = threading.Event()
        self._thread: threading.Thread | None = None

    def start(self) -> None:
        if self._thread is None:
            self._beat = time.monotonic()
            self._thread = threading.Thread(target=self._run, name="stop guard", daemon=True)
            self._thread.start()

    def beat(self) -> bool:
        """The session ticks: whether the guard stopped the car since the last beat."""
        self._beat = time.monotonic()
        self._ticker = threading.get_native_id()
        fired, self.fired = self.fired, False
        return fired

    def close(self) -> None:
        """The session closes itself (its own stop follows): the guard ends."""
        self._closed.set()

    def _run(self) -> None:
        looked = seen = self._beat
        ran = could = 0.0  # since the beat the guard saw: time the process ran; of it,
        # time the session's thread did not wait for a CPU
        times: tuple[int, tuple[float, float] | None] = (0, None)  # the ticker's, last look
        while not self._closed.wait(STEP):
            now = time.monotonic()
            ending = signals.ending_since()
            if ending is not None and now - ending > GRACE:
                self._end_process()
                return
            beat, ticker = self._beat, self._ticker  # written by the session's thread
            step, looked = min(now - looked, LATE), now
            (was, then), times = times, (ticker, thread_times(ticker))
            worked = queued = 0.0
            if was == ticker and then is not None and times[1] is not None:
                worked, queued = times[1][0] - then[0], times[1][1] - then[1]
            if beat != seen:
                seen = beat
                ran = could = min(now - beat, LATE)
            elif far.waiting(ticker):
                pass  # the link's wait for the car's own stop authority, not a view's stall
            else:
                ran += step
                could = max(0.0, could + step - queued)  # a wait is told when it ends
            if self.fired:
                continue
            why = self._lapsed()
            if why is None and could <= STALL and ran <= STARVED:
                continue
            if why is None:
                waiting = worked < step / 2 and runnable(ticker)  # a wait not yet told
                why = STALLED if ran > STARVED or not waiting else None
            if why is not None and self._moving():
                # first: a tick that notes it before the stop is out errs on the safe side
                # (the view shows stopped, the stop follows), never the other way round
                self.why, self.fired = why, True
                self._send_stop()

    def _send_stop(self) -> None:
        with contextlib.suppress(Exception):  # a link that is down has nothing to stop
            self._stop()

    def _end_process(self) -> None:
        self._send_stop()
        said = threading.Thread(target=_say_ended, daemon=True)  # stderr may block too
        said.start()
        said.join(SAY_WAIT)
        os._exit(130)


SAY_WAIT = 0.1
"""Seconds the guard gives its last line on stderr before it ends the process."""


def _say_ended() -> None:
    with contextlib.suppress(OSError, ValueError):
        print(
            f"appmode: the session did not end within {GRACE:g} s of the signal (its view "
            "was blocked): the car was sent its stop and appmode ended",
            file=sys.stderr,
            flush=True,
        )
