"""Script mode: `appmode drive` with stdin that is no TTY runs the console's commands
line by line, and lets time pass with `wait`."""

from __future__ import annotations

import sys
import time
from collections.abc import Iterable, Iterator
from typing import TextIO

from appmode.console.panel import status_text
from appmode.host.waits import Wait
from appmode.session.base import BaseSession
from appmode.session.command_line import Quit, ShowHelp, ShowStatus, Step

REFRESH = 0.02
"""Seconds between reads of the link while time passes."""


def command_lines(stream: TextIO, limit: int) -> Iterator[str]:
    """`stream`'s lines, never more than `limit` + 1 characters of one held: a longer
    line (a file piped in by mistake) is given at once as its first `limit` + 1
    characters, and its rest is read and let go only when the next line is asked for
    (a script that ends at the error does not read on: /dev/zero has no line end)."""
    while line := stream.readline(limit + 1):
        yield line
        if len(line) > limit and not line.endswith("\n"):
            while (rest := stream.readline(limit + 1)) and not rest.endswith("\n"):
                pass


def run_script(
    session: BaseSession, lines: Iterable[str], out: TextIO, keep_going: bool = False
) -> None:
    """Run commands line by line; `wait S` lets S seconds pass.

    A parameter read or set finishes before the next line runs. The first error ends
    the script, unless `keep_going`.
    """
    settle(session, 0.0)
    for raw in lines:
        try:
            step = session.run(raw)
        except Quit:
            break  # run_drive names what was not saved
        show(session, step)
        settle(session, step.seconds if isinstance(step, Wait) else 0.0)
        if session.failures and not keep_going:  # before the next line is read
            print(
                "appmode: the script stopped at its first error (--keep-going runs on)",
                file=sys.stderr,
            )
            break
    out.flush()


def show(session: BaseSession, step: Step) -> None:
    """What a command returned for the view: the panel for `status`, the help for
    `help`, as messages."""
    if isinstance(step, ShowStatus):
        text = status_text(session)
        session.say(text)
    elif isinstance(step, ShowHelp):
        for text in session.help_lines:
            session.say(text)


def settle(session: BaseSession, seconds: float) -> None:
    """Let `seconds` pass, and any parameter query end, reading the link meanwhile."""
    end = time.monotonic() + seconds
    session.tick()
    while time.monotonic() < end or session.busy:
        time.sleep(min(REFRESH, max(0.0, end - time.monotonic())) or REFRESH)
        session.tick()
