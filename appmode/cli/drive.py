"""`appmode drive`: drive and tune a car from the keyboard (the main job)."""

from __future__ import annotations

import argparse
import sys

from appmode.cli.commands import COMMANDS
from appmode.cli.live_view import LiveViews, add_foxglove
from appmode.cli.options import (
    HOLDS,
    Subparsers,
    add_chassis,
    add_profile,
    add_record,
    add_uart2,
    board_choice,
    number_type,
    target,
)
from appmode.protocol.drive_types import DRIVE_NAMES
from appmode.session.timeouts import FIRST_TIMEOUT, REPEAT_TIMEOUT


def register(sub: Subparsers) -> argparse.ArgumentParser:
    drive = sub.add_parser(
        "drive",
        help=COMMANDS["drive"],
        description="The driving console: a live status panel, arrow keys and a 3x3 key grid "
        "(q w e / a s d / z x c) to drive, space to stop, and a command line (:) for "
        "everything else. With no URL it drives the embedded simulated board. When stdin "
        "is not a terminal, commands are read from it line by line (try: help). Whatever "
        "ends the session, the last byte sent is Z. With --uart2 it drives over the "
        "board's control port instead (velocity frames; the last frame sent is the zero "
        "velocity frame); with --uart2-url (or a second URL) it holds both ports of one "
        "board: it drives over UART2 and shows the APP port's records.",
    )
    add_board(drive)
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
    drive.add_argument(
        "--keep-going",
        action="store_true",
        help="script mode (commands on stdin): run every line after an error (by default "
        "the first error ends the script); the exit status is 1 if any line failed",
    )
    return drive


def add_board(parser: argparse.ArgumentParser) -> None:
    """Which board, and which of its ports, a driving session opens (drive and web)."""
    parser.add_argument(
        "url",
        nargs="?",
        default="sim://",
        type=target,
        metavar="URL",
        help="the board (default: sim://, the simulated board); see "
        "'appmode params -h' for URL forms",
    )
    parser.add_argument(
        "url2",
        nargs="?",
        type=target,
        metavar="URL2",
        help="the same board's control port: as --uart2-url",
    )
    add_uart2(parser, "drive over the board's control port (UART2, velocity frames)")
    add_chassis(parser, "drive over the board's chassis port")
    parser.add_argument(
        "--uart2-url",
        type=target,
        metavar="URL",
        help="open the board's control port there too: drive over it and show the APP "
        "port's records (two sim:// URLs are one simulated board)",
    )
    parser.add_argument(
        "--drive",
        "--drive-type",
        dest="drive_type",
        choices=DRIVE_NAMES,
        metavar="TYPE",
        help=f"the car's drive type ({', '.join(DRIVE_NAMES)}): the embedded board's "
        "(sim://?drive=; default: omni), "
        "or with UART2 a board's that does not answer reads (default: read from "
        "system_mode)",
    )
    add_profile(
        parser,
        f"the board's profile: with no URL, the simulated board's; with a URL, {HOLDS}",
        default=None,
    )
    add_record(parser)
    add_foxglove(parser, drives=True)


def run(args: argparse.Namespace) -> int:
    from appmode.console.driving import run_drive  # here: start-up stays short
    from appmode.console.script import command_lines
    from appmode.session.command_line import MAX_COMMAND
    from appmode.session.hold import HoldToDrive
    from appmode.session.opener import open_session

    with LiveViews(args.foxglove, args.foxglove_drive) as views:
        choice = board_choice(args)
        interactive = sys.stdin.isatty() and sys.stdout.isatty()
        driving = HoldToDrive(args.hold_first, args.hold_repeat, args.latched or not interactive)
        on_message = None if interactive else _print_message
        session = open_session(choice, driving, on_message, args.record, views.make)
        script = command_lines(sys.stdin, MAX_COMMAND)
        return run_drive(session, interactive, script, sys.stdout, keep_going=args.keep_going)


def _print_message(text: str) -> None:
    """Script mode's messages: errors on stderr, the rest on stdout."""
    if text.startswith("error: "):
        print(f"appmode: {text}", file=sys.stderr, flush=True)
    else:
        print(text, flush=True)
