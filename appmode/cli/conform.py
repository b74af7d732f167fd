"""`appmode conform`: run transcripts as conformance tests against a board."""

from __future__ import annotations

import argparse
import sys

from appmode.cli.options import Subparsers


def register(sub: Subparsers) -> argparse.ArgumentParser:
    conform = sub.add_parser(
        "conform",
        help="run transcripts as conformance tests against a board",
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
        "--board", metavar="URL", help="run in real time against this board instead"
    )
    conform.add_argument("--junit", metavar="FILE", help="also write a JUnit XML report")
    return conform


def run(args: argparse.Namespace) -> int:
    from appmode.transcript.runner import run_conform

    return run_conform(args.paths, args.board, args.junit, sys.stdout)
