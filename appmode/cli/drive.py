"""`appmode drive`: drive and tune a car from the keyboard (the main job)."""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Callable
from typing import TYPE_CHECKING

from appmode.cli.commands import COMMANDS
from appmode.cli.options import (
    HOLDS,
    Subparsers,
    add_profile,
    add_record,
    add_uart2,
    layout_for,
    number_type,
    profile_for,
    stop_again_for,
    target,
)
from appmode.errors import AppmodeError
from appmode.protocol.params import DRIVE_NAMES, DriveType
from appmode.session.hold import FIRST_TIMEOUT, REPEAT_TIMEOUT

if TYPE_CHECKING:
    from appmode.ports.target import Target
    from appmode.session.base import BaseSession
    from appmode.session.hold import HoldToDrive


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


def run(args: argparse.Namespace) -> int:
    from appmode.console.driving import run_drive  # here: start-up stays short
    from appmode.console.script import command_lines
    from appmode.session.commands import MAX_COMMAND
    from appmode.session.hold import HoldToDrive

    interactive = sys.stdin.isatty() and sys.stdout.isatty()
    driving = HoldToDrive(args.hold_first, args.hold_repeat, args.latched or not interactive)
    on_message = None if interactive else _print_message
    session = make_session(args, driving, on_message)
    script = command_lines(sys.stdin, MAX_COMMAND)
    return run_drive(session, interactive, script, sys.stdout, keep_going=args.keep_going)


def make_session(
    args: argparse.Namespace, driving: HoldToDrive, on_message: Callable[[str], None] | None
) -> BaseSession:
    """The session `add_board`'s arguments ask for: the APP port's, or the control port's
    (with the APP port of the same board if given)."""
    from appmode.session.app_session import Session
    from appmode.session.control_session import ControlSession

    board: Target = args.url.with_sim(profile=args.profile, drive=args.drive_type)
    layout = layout_for(board, args.profile)
    uart2: Target | None = args.uart2_url or args.url2
    if args.url2 and args.uart2_url:
        raise AppmodeError("give the control port once: a second URL or --uart2-url")
    if uart2 is None and not args.uart2:
        if args.drive_type and not board.simulated:
            raise AppmodeError(
                "--drive on a real board's APP port: its drive type is part of "
                "system_mode (appmode params URL --set system_mode=N), or add --uart2"
            )
        return Session(
            board,
            driving,
            args.record,
            on_message,
            layout,
            stop_again_for(board, args.profile),
            profile_for(board, args.profile).steer_in_frames,
        )
    app: Target | None = None
    if uart2 is not None:
        app, board = board, uart2.with_sim(profile=args.profile, drive=args.drive_type)
        if app.simulated and board.simulated:
            app, board = _one_board(app, board)
    profile = profile_for(board, args.profile).check_uart2()
    return ControlSession(
        board,
        driving,
        args.record,
        on_message,
        app_url=app,
        layout=layout,
        drive=DriveType.from_cli_name(args.drive_type) if args.drive_type else profile.fixed_drive,
        takeover_byte=profile.takeover_byte,
        reads=profile.answers_reads,
    )


def _one_board(app: Target, uart2: Target) -> tuple[Target, Target]:
    """Two sim:// targets as the two ports of one simulated board (its options given on
    the first, or the same on both)."""
    app_options, uart2_options = (
        {k: v for k, v in t.sim.items() if k not in ("port", "share")} for t in (app, uart2)
    )
    if uart2_options and uart2_options != app_options:
        raise AppmodeError(
            f"{app} and {uart2} are one simulated board: give its options once, on "
            f"the first URL (appmode drive '{uart2}' sim://)"
        )
    if "share" not in app.sim:
        app = app.with_sim(share=f"drive-{os.getpid()}")
    from appmode.ports.target import parse_target

    return app, parse_target(f"{app.url}&port=uart2")  # `share` made the query


def _print_message(text: str) -> None:
    """Script mode's messages: errors on stderr, the rest on stdout."""
    if text.startswith("error: "):
        print(f"appmode: {text}", file=sys.stderr, flush=True)
    else:
        print(text, flush=True)
