"""Standard output and error through bounded writers, for the commands that drive a car:
a pipe nobody reads, a FIFO whose reader stalls or a paused terminal never holds up the
session, its stop or a signal (`writer.BoundedWriter`).

A write never waits. A reader that left, or a full disk, is reported as a plain stream
would report it, at the next write (BrokenPipeError, OSError); a reader that takes
nothing for the writer's whole bound loses the output from there on, and the command
says so and exits non-zero (`finish`).
"""

from __future__ import annotations

import errno
import os
import sys
from typing import TYPE_CHECKING

from appmode.host import signals
from appmode.writer import CLOSE_WAIT, BoundedWriter

if TYPE_CHECKING:
    from typing import TextIO

STEP = 0.1
"""Seconds between looks at a draining writer (a signal is acted on between them)."""


class Outlet:
    """A text stream (as much of one as print and prompt_toolkit use) over a
    BoundedWriter on a copy of `stream`'s file descriptor; given the `writer` of
    another Outlet, it shares it (standard output and error keep their order)."""

    def __init__(self, stream: TextIO, name: str, writer: BoundedWriter | None = None) -> None:
        fd = os.dup(stream.fileno())
        self._stream = stream
        self.name = name
        self.encoding = getattr(stream, "encoding", None) or "utf-8"
        self.errors = "replace"
        self._fd = None if writer is None else fd
        """The descriptor this Outlet names in a shared writer (None: the writer's own)."""
        self.writer = writer or BoundedWriter(lambda: fd, name)

    def fileno(self) -> int:
        return self._stream.fileno()

    def isatty(self) -> bool:
        return self._stream.isatty()

    def writable(self) -> bool:
        return True

    def write(self, text: str) -> int:
        writer = self.writer
        error = writer.error if self._fd is None else writer.side_errors.get(self._fd)
        if error is not None:
            raise error
        writer.write(text.encode(self.encoding, self.errors), self._fd)
        return len(text)

    def flush(self) -> None:
        """Nothing to wait for: the writer writes as soon as it can."""


def install() -> tuple[Outlet, Outlet] | None:
    """Put Outlets in place of sys.stdout and sys.stderr, unless they are not the
    process's own (a test's capture): then None."""
    out, err = sys.stdout, sys.stderr
    if out is not sys.__stdout__ or err is not sys.__stderr__ or out is None or err is None:
        return None
    try:
        first = Outlet(out, "standard output")
        outlets = first, Outlet(err, "standard error", first.writer)
    except (OSError, ValueError, AttributeError):
        return None
    sys.stdout, sys.stderr = outlets  # as much of a TextIO as print and prompt_toolkit use
    return outlets


def finish(outlets: tuple[Outlet, Outlet]) -> str | None:
    """Let the outlets write what they hold and put the streams back: waiting as a
    plain stream would (a signal ends the wait), or at most CLOSE_WAIT after an ending
    signal; why output was lost, if it was (a reader that left, as `cat`, loses
    nothing worth saying)."""
    writer = outlets[0].writer
    while writer.pending and writer.failure is None and signals.ending_since() is None:
        writer.drained(STEP)
    writer.close(CLOSE_WAIT)
    sys.stdout, sys.stderr = sys.__stdout__, sys.__stderr__
    error = writer.error
    if writer.failure is None or (error is not None and error.errno == errno.EPIPE):
        return None  # `| head`: as cat does
    return f"cannot write the output: {writer.failure}"
