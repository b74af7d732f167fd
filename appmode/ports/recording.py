"""A recording written to a file the user names (`--record FILE`, a board's own): the
file opened here, the transcript written by `protocol.recorder.Recorder` in the format
its name's suffix chooses (`protocol.formats.WRITERS`: MCAP for `.mcap`), as
python-can's logger does."""

from __future__ import annotations

import contextlib
import os
from functools import partial

from appmode.errors import AppmodeError
from appmode.files import is_fifo, open_fifo
from appmode.protocol.formats import written_as
from appmode.protocol.layouts import VELOCITY, Layout
from appmode.protocol.recorder import Recorder
from appmode.writer import BoundedWriter

_CLOEXEC = getattr(os, "O_CLOEXEC", 0)  # Windows has none
HEADER_WAIT = 0.1
"""Seconds `open_recorder` waits to see a file take its header once its writer's thread
has run (a file or device takes it at once; a full one fails then, and the caller is
told)."""
THREAD_WAIT = 5.0
"""Seconds `open_recorder` waits for that thread to run at all: on a busy machine one
not scheduled for 0.1 s had its empty file refused as if full."""


def open_recorder(
    path: str | os.PathLike[str],
    origin: float = 0.0,
    directives: tuple[str, ...] = (),
    background: bool = True,
    layout: Layout = VELOCITY,
) -> Recorder:
    """A recorder of the file `path`, written by a `BoundedWriter`: a full disk, a FIFO
    nobody reads or a stalled reader never holds up the caller (the recording stops, and
    the next call or `close` says why). With `background` False it is written on the
    caller's thread, which its reader may slow down (a simulated board's own recording:
    nothing waits for it, and a flood is recorded whole). A `.mcap` file is MCAP, its
    decoded channels in `layout`'s terms (needs the `foxglove` extra's mcap)."""
    shown = os.fspath(path)
    form = written_as(shown)
    lines = form.lines(layout)
    if is_fifo(path) and background:  # its open waits for a reader: in the writer
        opener = partial(open_fifo, path, "transcript", "the session goes on meanwhile")
        return Recorder(BoundedWriter(opener, shown), origin, directives, lines=lines)
    new = not os.path.lexists(path)
    try:
        if is_fifo(path):
            fd = open_fifo(path, "transcript")
        else:
            fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC | _CLOEXEC, 0o666)
    except OSError as exc:
        raise AppmodeError(f"cannot write transcript {shown}: {exc.strerror}") from None
    try:
        if not background:
            out = os.fdopen(fd, "wb") if form.binary else os.fdopen(fd, "w", encoding="utf-8")
            try:
                return Recorder(out, origin, directives, shown, closes=True, lines=lines)
            except AppmodeError:  # not even the header fits
                with contextlib.suppress(OSError):
                    out.close()
                raise
        writer = BoundedWriter(lambda: fd, shown)
        recorder = Recorder(writer, origin, directives, lines=lines)
        writer.ran(THREAD_WAIT)
        if not writer.drained(HEADER_WAIT):  # not even the header fits (a full disk)
            why = writer.failure or f"its first line unwritten after {HEADER_WAIT:g} s"
            writer.close(0.0)
            raise AppmodeError(f"cannot write transcript {shown}: {why}")
    except AppmodeError:
        if new:  # leave nothing
            with contextlib.suppress(OSError):
                os.unlink(path)
        raise
    return recorder
