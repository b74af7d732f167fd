"""The stop authority: one guard over every motion of a session, whatever started it.

Motion lasts only while its source proves it is alive. The session checks the sources
at each tick (`BaseSession.watch`): a held key's repeats (`hold.HoldToDrive`), a page's
heartbeats (`lease`). This guard watches the tick itself, from a thread of its own, so
that nothing the view blocks on can keep the car moving:

- a session whose ticks stop for STALL seconds while the car moves (a view blocked on a
  terminal, a pipe, a disk) gets its port's stop from here, and the session forgets the
  motion at its next tick. Only time the process ran counts: a gap between the guard's
  own looks of over LATE (the whole process was not scheduled, on a loaded machine)
  counts as LATE, so a session is judged on what it did while it could tick;
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

from appmode.host import signals

STALL = 0.25
"""Seconds without a tick, the car moving, before the guard stops it."""
GRACE = 0.8
"""Seconds after an ending signal before the guard stops the car and ends the process."""
STEP = 0.02
"""Seconds between the guard's looks."""
LATE = 0.1
"""The most a gap between two of the guard's looks counts towards STALL: a longer one
means the process was not running at all (the session could not tick either)."""


class StopGuard:
    """A thread that stops the car when the session's ticks stall (`beat` is each tick)
    or an ending signal is not acted on."""

    def __init__(self, moving: Callable[[], bool], stop: Callable[[], None]) -> None:
        self._moving = moving
        self._stop = stop
        """Sends the port's stop and nothing else (safe from this thread: the link's
        writes are serialised)."""
        self._beat = time.monotonic()
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
        fired, self.fired = self.fired, False
        return fired

    def close(self) -> None:
        """The session closes itself (its own stop follows): the guard ends."""
        self._closed.set()

    def _run(self) -> None:
        looked = seen = self._beat
        stalled = 0.0  # the time the process ran since the last beat the guard saw (`seen`)
        while not self._closed.wait(STEP):
            now = time.monotonic()
            ending = signals.ending_since()
            if ending is not None and now - ending > GRACE:
                self._end_process()
                return
            beat = self._beat  # one read: `beat` writes it from the session's thread
            if beat != seen:
                seen, stalled = beat, min(now - beat, LATE)
            else:
                stalled += min(now - looked, LATE)
            looked = now
            if not self.fired and stalled > STALL and self._moving():
                # first: a tick that notes it before the stop is out errs on the safe side
                # (the view shows stopped, the stop follows), never the other way round
                self.fired = True
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
