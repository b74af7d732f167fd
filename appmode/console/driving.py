"""`appmode drive` from start to stop: the session started, the console (or script mode)
run, and the session always closed — its stop is the last thing sent."""

from __future__ import annotations

import asyncio
import sys
from collections.abc import Iterable
from typing import TextIO

from prompt_toolkit.input import Input
from prompt_toolkit.output import Output

from appmode.console.script import run_script
from appmode.console.terminal import Console, command_history
from appmode.session.base import BaseSession
from appmode.text import wrapped


def run_drive(
    session: BaseSession,
    interactive: bool,
    script: Iterable[str],
    out: TextIO,
    input: Input | None = None,
    output: Output | None = None,
    keep_going: bool = False,
) -> int:
    """Start the session, run the console (or script mode), and always close it: the
    stop last. Values set and not saved are named at the end. Script mode ends at the
    first error (every line with `keep_going`); its exit status is 1 if any line failed,
    or (in either mode) if the recording stopped on its own or the final stop could not
    be sent to a car last told to move."""
    try:
        # the console first: one that cannot be shown fails before the car is spoken to
        console = Console(session, input, output, command_history()) if interactive else None
        session.start()
        if console is not None:
            asyncio.run(console.run())
        else:
            run_script(session, script, out, keep_going)
    finally:
        warning = session.unsaved_warning()
        try:
            session.close()
        finally:
            for note in session.closing_notes:
                print(f"appmode: WARNING: {note}", file=sys.stderr)
            if warning is not None:
                lasts = (
                    "the embedded board ends with this session"
                    if session.simulated
                    else "the board keeps it until it is switched off"
                )
                print(wrapped(f"appmode: {warning}: {lasts}"), file=sys.stderr)
            if session.recording_failure is not None and interactive:
                print(
                    f"appmode: error: {session.recording_failure}; the recording stopped there",
                    file=sys.stderr,
                )
            if session.undelivered is not None:
                print(f"appmode: {session.undelivered}", file=sys.stderr)
    failed = session.failures and not interactive
    return 1 if failed or session.recording_failure is not None or session.left_moving else 0
