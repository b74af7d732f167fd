"""`appmode conform`: run transcripts as conformance tests against a board."""

from __future__ import annotations

import argparse
import sys

from appmode.cli.commands import COMMANDS
from appmode.cli.options import Subparsers, add_chassis, add_profile, file_name, target
from appmode.errors import AppmodeError


def register(sub: Subparsers) -> argparse.ArgumentParser:
    conform = sub.add_parser(
        "conform",
        help=COMMANDS["conform"],
        description="Send each transcript's '>' lines at their times and match its '<' lines "
        "against what the board sends ('*' matches any field; unmentioned telemetry is "
        "ignored). Without --board: the embedded simulated board on virtual time (no "
        "waiting). With --board URL: in real time against any board. One line per "
        "transcript; exit status 1 if any fails.",
    )
    conform.add_argument(
        "paths",
        nargs="*",
        metavar="FILE|DIR",
        help="transcripts, or directories searched for *.transcript (default: the suite "
        "shipped with appmode)",
    )
    conform.add_argument(
        "--board",
        dest="url",
        metavar="URL",
        type=target,
        help="run in real time against this board instead",
    )
    conform.add_argument(
        "--board2",
        dest="url2",
        metavar="URL",
        type=target,
        help="with --board: the same board's control port (UART2), for transcripts with "
        "2> / 2< lines (a sim:// board has its own; elsewhere they are skipped without it)",
    )
    add_profile(
        conform,
        "run the transcripts written for this board profile (@board profile=…); "
        "without --board or with a sim:// one, on a simulated board of that profile",
        default=None,
        unset="a sim:// --board's profile, else sheet",
    )
    add_chassis(
        conform,
        "run the transcripts for a WHEELTEC profile (wheeltec-mec unless --profile says), "
        "with --board on its chassis port",
    )
    conform.add_argument(
        "--junit", type=file_name, metavar="FILE", help="also write a JUnit XML report"
    )
    conform.add_argument(
        "--yes",
        action="store_true",
        help="with --board: run without asking first (the car moves and its parameters "
        "are changed, then restored)",
    )
    return conform


WARNING = (
    "conform drives the board at {url}: the car moves (the suite tries every letter, a "
    "second each) and its parameters are changed and saved; the ones found now are "
    "restored at the end. Put the car on a stand."
)


def run(args: argparse.Namespace) -> int:
    from appmode.board.profiles import profile_named
    from appmode.cli.options import board_choice
    from appmode.transcript.runner import run_conform

    if args.url2 and not args.url:
        raise AppmodeError("--board2 names the control port of the --board: give --board too")
    board = board2 = None
    profile = profile_named(args.profile or ("wheeltec-mec" if args.chassis else "sheet")).name
    if args.url:
        choice = board_choice(args)
        board, board2 = choice.app_port or choice.target, choice.control_port
        profile = choice.profile.name
    if args.chassis and profile_named(profile).chassis is None:
        raise AppmodeError(
            f"--chassis: the {profile} profile has no chassis port: give --profile "
            "wheeltec-mec, wheeltec-akm or wheeltec-diff"
        )
    if board and not board.simulated and not args.yes:
        warning = WARNING.format(url=board)
        if not sys.stdin.isatty():
            raise AppmodeError(f"{warning} Add --yes to run it without asking.")
        print(f"{warning}\nGo on? [y/N] ", end="", file=sys.stderr, flush=True)
        if sys.stdin.readline().strip().lower() not in ("y", "yes"):
            print("not run", file=sys.stderr)
            return 1
    return run_conform(
        args.paths, board, args.junit, sys.stdout, profile, board2=board2, chassis=args.chassis
    )
