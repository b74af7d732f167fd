"""The `appmode` console script and `python -m appmode`: a signal while the command line
is still loading ends it quietly, as one during a command does (exit 130, no traceback),
and one after the command is over changes nothing."""

from __future__ import annotations

import signal
import sys


def _quit(signum: int, frame: object) -> None:
    raise SystemExit(130)


def quit_while_loading() -> None:
    """Ctrl-C ends the program quietly until the command's own handling takes over."""
    signal.signal(signal.SIGINT, _quit)


def main() -> int:
    quit_while_loading()  # the rest of appmode is not loaded yet
    from appmode.cli.main import main as run
    from appmode.host.signals import ENDING_SIGNALS

    try:
        return run()
    finally:
        for signum in (signal.SIGINT, *ENDING_SIGNALS):
            signal.signal(signum, signal.SIG_IGN)  # the command is over: its exit stands


def started_as_program() -> bool:
    """This interpreter runs `appmode` or `python -m appmode` (not a program that imports
    appmode, whose signals are its own)."""
    argv = getattr(sys, "argv", None) or [""]  # an embedding interpreter may have none
    if argv[0] == "-m":  # `python -m NAME` while NAME's package loads
        return sys.orig_argv[sys.orig_argv.index("-m") + 1 :][:1] == ["appmode"]
    return argv[0].replace("\\", "/").rsplit("/", 1)[-1] in ("appmode", "appmode.exe")


AS_PROGRAM = started_as_program()
"""This process is the `appmode` program (its commands open ports through ports.urls)."""
if AS_PROGRAM:
    quit_while_loading()

if __name__ == "__main__":
    sys.exit(main())
