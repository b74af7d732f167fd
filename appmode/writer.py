"""A bounded writer: bytes handed over at once, written by a thread of their own.

Whoever drives the car must never wait for a disk, a pipe nobody reads, a FIFO whose
reader stalls or a terminal that is paused: a recording or an output line written on
that path would hold up the stop and the signals. `BoundedWriter.write` only queues;
its thread opens the file (a FIFO's open waits for a reader there, not here) and writes.
It holds at most `limit` bytes; when its reader cannot keep up, or a write fails (a full
disk, a file size limit, a reader that left), it stops writing for good and keeps why
in `failure`, which the caller reports (stderr, a non-zero exit) while the session and
its stop go on.
"""

from __future__ import annotations

import contextlib
import errno
import os
import threading
from collections import deque
from collections.abc import Callable

LIMIT = 1 << 20
"""Bytes a writer holds for a slow reader before it gives up: minutes of a recording."""
CLOSE_WAIT = 0.5
"""Seconds `close` waits for the writer to drain: a signal ends a session within 1 s."""


class BoundedWriter:
    """Writes to the file descriptor that `opener` gives (called in the writer's thread),
    in order, from a queue of at most `limit` bytes; a write may name another descriptor
    (standard error beside standard output), kept in the same order."""

    def __init__(
        self,
        opener: Callable[[], int],
        name: str,
        limit: int = LIMIT,
    ) -> None:
        self.name = name
        self.limit = limit
        self.failure: str | None = None
        """Why writing stopped (None while it goes on)."""
        self.error: OSError | None = None
        """The error that stopped it, where one did (not a reader too slow)."""
        self.side_errors: dict[int, OSError] = {}
        """Errors writing another descriptor (its bytes are dropped from then on)."""
        self._opener = opener
        self._queue: deque[tuple[int | None, bytes]] = deque()
        self._held = 0  # bytes queued and not yet written
        self._closing = False
        self._opened = False  # the opener has returned
        self._ran = threading.Event()  # the opener has returned or failed
        self._done = threading.Event()  # the thread has ended
        self._lock = threading.Condition()
        self._thread = threading.Thread(target=self._run, name=f"writer {name}", daemon=True)
        self._thread.start()

    def write(self, data: bytes, fd: int | None = None) -> bool:
        """Queue `data` (for `fd`, by default the opened one); never waits. False once
        writing has stopped (see `failure`)."""
        with self._lock:
            if self.failure is not None or self._closing:
                return False
            if self._held + len(data) > self.limit:
                self._fail(f"its reader took nothing for {self._held:,} bytes")
                return False
            self._queue.append((fd, data))
            self._held += len(data)
            self._lock.notify()
        return True

    @property
    def pending(self) -> int:
        """Bytes queued and not yet written."""
        return self._held

    def ran(self, wait: float) -> bool:
        """Wait at most `wait` seconds for the writer's thread to have opened its file,
        or failed to; whether it has (a thread not yet scheduled, on a busy machine, has
        not)."""
        return self._ran.wait(wait)

    def drained(self, wait: float = CLOSE_WAIT) -> bool:
        """Wait at most `wait` seconds for what is queued to be written; whether it was
        (False also once writing has stopped)."""
        with self._lock:
            self._lock.wait_for(lambda: not self._held or self.failure is not None, wait)
            return not self._held and self.failure is None

    def close(self, wait: float = CLOSE_WAIT) -> bool:
        """Let the writer finish what it holds, for at most `wait` seconds, and end it;
        whether everything was written (else `failure` says why)."""
        with self._lock:
            self._closing = True
            self._lock.notify()
        if not self._done.wait(wait):
            with self._lock:
                if self.failure is None and not self._opened:
                    self._fail(f"no program opened it to read within {wait:g} s of the end")
                elif self.failure is None:
                    self._fail(f"{self._held:,} bytes were still unwritten after {wait:g} s")
            return False
        return self.failure is None

    def _fail(self, why: str) -> None:
        """Stop writing (the lock held): what is queued is dropped."""
        if self.failure is None:
            self.failure = why
        self._queue.clear()
        self._held = 0
        self._lock.notify_all()

    def _run(self) -> None:
        try:
            fd = self._opener()
            self._opened = True
        except OSError as exc:
            with self._lock:
                self.error = exc
                self._fail(reason(exc))
            self._ran.set()
            self._done.set()
            return
        self._ran.set()
        try:
            self._drain(fd)
        finally:
            with contextlib.suppress(OSError):
                os.close(fd)
            self._done.set()

    def _drain(self, fd: int) -> None:
        while True:
            with self._lock:
                while not self._queue and not self._closing and self.failure is None:
                    self._lock.wait()
                if self.failure is not None or not self._queue:
                    return
                item = self._queue[0]
            target, data = item
            try:  # outside the lock: `write` never waits for this
                if target not in self.side_errors:
                    view = memoryview(data)
                    while view:
                        view = view[os.write(fd if target is None else target, view) :]
            except OSError as exc:
                with self._lock:
                    if target is None:
                        self.error = exc
                        self._fail(reason(exc))
                        return
                    self.side_errors[target] = exc
            with self._lock:
                if self._queue and self._queue[0] is item:
                    self._queue.popleft()
                    self._held -= len(data)
                    self._lock.notify_all()


def reason(exc: OSError) -> str:
    """Why a write failed, for people."""
    if exc.errno == errno.EPIPE:
        return "its reader left"
    if exc.errno == errno.EFBIG:
        return "the file size limit was reached"
    return exc.strerror or str(exc)
