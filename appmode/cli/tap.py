"""`appmode tap`: sit between an app and a board, recording both directions."""

from __future__ import annotations

import argparse

from appmode.cli.commands import COMMANDS
from appmode.cli.options import Subparsers, file_name


def register(sub: Subparsers) -> argparse.ArgumentParser:
    tap = sub.add_parser(
        "tap",
        help=COMMANDS["tap"],
        description="Forward bytes both ways between the app side and the board side and "
        "record them, timestamped, as a transcript. APP may be 'pty': a new pseudo-terminal "
        "for the app to open (its path is printed as 'port: …'). On exit the board gets Z.",
    )
    tap.add_argument("app", metavar="URL_APP", help="the app's side (or 'pty')")
    tap.add_argument("board", metavar="URL_BOARD", help="the board's side")
    tap.add_argument(
        "--record", required=True, type=file_name, metavar="FILE", help="the transcript to write"
    )
    tap.add_argument("--quiet", "-q", action="store_true", help="no status lines")
    return tap


def run(args: argparse.Namespace) -> int:
    from appmode.transcript.tap import run_tap

    return run_tap(args.app, args.board, args.record, args.quiet)
