"""The `appmode` console script and `python -m appmode`: a signal while the command line
is still loading ends it quietly, as one during a command does (exit 130, no traceback),
and one after the command is over changes nothing."""

from __future__ import annotations

import signal
import sys

from appmode import quit_while_loading


def main() -> int:
    quit_while_loading()  # the rest of appmode is not loaded yet
    from appmode.cli.main import main as run
    from appmode.host.signals import ENDING_SIGNALS

    try:
        return run()
    finally:
        for signum in (signal.SIGINT, *ENDING_SIGNALS):
            signal.signal(signum, signal.SIG_IGN)  # the command is over: its exit stands


if __name__ == "__main__":
    sys.exit(main())
