"""`appmode drive`: drive and tune a car from the keyboard (the main job)."""

from __future__ import annotations

import argparse
import sys

from appmode.cli.options import Subparsers, add_profile, add_record, layout_for, number_type
from appmode.console.hold import FIRST_TIMEOUT, REPEAT_TIMEOUT


def register(sub: Subparsers) -> argparse.ArgumentParser:
    drive = sub.add_parser(
        "drive",
        help="drive and tune a car from the keyboard (the main job)",
        description="The driving console: a live status panel, arrow keys and a 3x3 key grid "
        "(q w e / a s d / z x c) to drive, space to stop, and a command line (:) for "
        "everything else. With no URL it drives the embedded simulated board. When stdin "
        "is not a terminal, commands are read from it line by line (try: help). Whatever "
        "ends the session, the last byte sent is Z.",
    )
    drive.add_argument(
        "url",
        nargs="?",
        default="sim://",
        metavar="URL",
        help="the board (default: sim://, the simulated board); see "
        "'appmode params -h' for URL forms",
    )
    drive.add_argument(
        "--hold-first",
        type=number_type(0, 60, low_open=True),
        default=FIRST_TIMEOUT,
        metavar="S",
        help="stop this long after a first key press with no repeat; longer "
        f"than the OS auto-repeat delay (default {FIRST_TIMEOUT})",
    )
    drive.add_argument(
        "--hold-repeat",
        type=number_type(0, 60, low_open=True),
        default=REPEAT_TIMEOUT,
        metavar="S",
        help=f"stop this long after the last auto-repeat (default {REPEAT_TIMEOUT})",
    )
    drive.add_argument(
        "--latched", action="store_true", help="a direction stays until stop (key l toggles it)"
    )
    add_profile(
        drive,
        "the board's profile: with no URL, the simulated board's (sheet or minibalance: the "
        "reference firmware, docs/protocol.md §13); with a URL, what its A record holds",
        default=None,
    )
    add_record(drive)
    return drive


def run(args: argparse.Namespace) -> int:
    from appmode.console.app import run_drive
    from appmode.console.hold import HoldToDrive
    from appmode.console.session import Session

    interactive = sys.stdin.isatty() and sys.stdout.isatty()
    driving = HoldToDrive(args.hold_first, args.hold_repeat, args.latched or not interactive)
    url = args.url
    if args.profile and url.lower().startswith("sim://") and "profile=" not in url:
        url += f"{'&' if '?' in url else '?'}profile={args.profile}"
    session = Session(
        url,
        driving,
        args.record,
        on_message=None if interactive else _print_message,
        layout=layout_for(url, args.profile),
    )
    return run_drive(session, interactive, sys.stdin, sys.stdout)


def _print_message(text: str) -> None:
    print(text, flush=True)
