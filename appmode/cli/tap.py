"""`appmode tap`: sit between an app and a board, recording both directions."""

from __future__ import annotations

import argparse

from appmode.cli.commands import COMMANDS
from appmode.cli.options import Subparsers, add_admission, file_name


def register(sub: Subparsers) -> argparse.ArgumentParser:
    tap = sub.add_parser(
        "tap",
        help=COMMANDS["tap"],
        description="Forward bytes both ways between the app side and the board side and "
        "record them, timestamped, as a transcript. URL_APP may be 'pty': a new "
        "pseudo-terminal for the app to open (its path is printed as 'port: …'), or "
        "'advertise[:NAME]': this machine's Bluetooth adapter advertised as the car's "
        "module (default name HC-08; Linux with BlueZ), for the phone's app to connect to. "
        "The tap ends when a side leaves (the transcript says which) or on Ctrl-C; the "
        "board then gets Z.",
    )
    tap.add_argument(
        "app", metavar="URL_APP", help="the app's side: a URL, 'pty' or 'advertise[:NAME]'"
    )
    tap.add_argument("board", metavar="URL_BOARD", help="the board's side")
    tap.add_argument(
        "--record", required=True, type=file_name, metavar="FILE", help="the transcript to write"
    )
    tap.add_argument(
        "--nus",
        action="store_true",
        help="with advertise: offer the Nordic UART service instead of FFE0/FFE1",
    )
    add_admission(tap)
    tap.add_argument("--quiet", "-q", action="store_true", help="no status lines")
    return tap


def run(args: argparse.Namespace) -> int:
    from appmode.transcript.tap import run_tap

    admission = None
    if args.allow or args.secure:
        from appmode.bluetooth.advertise.admission import Admission

        admission = Admission(frozenset(args.allow or ()), args.secure)
    return run_tap(args.app, args.board, args.record, args.quiet, args.nus, admission)
