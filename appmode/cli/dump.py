"""`appmode dump`: decode a transcript."""

from __future__ import annotations

import argparse
import sys

from appmode.cli.commands import COMMANDS
from appmode.cli.options import Subparsers, add_chassis, add_profile, file_name


def register(sub: Subparsers) -> argparse.ArgumentParser:
    dump = sub.add_parser(
        "dump",
        help=COMMANDS["dump"],
        description="Decode every command and record of a transcript: text, JSON Lines or CSV.",
    )
    dump.add_argument("file", type=file_name, metavar="FILE", help="the transcript")
    fmt = dump.add_mutually_exclusive_group()
    fmt.add_argument("--json", action="store_true", help="JSON Lines")
    fmt.add_argument("--csv", action="store_true", help="CSV with a header row")
    add_profile(dump, default=None, unset="the transcript's @board profile=…, else sheet")
    add_chassis(dump, "only the chassis port's lines (c> and c<), in SI")
    return dump


def run(args: argparse.Namespace) -> int:
    from appmode.protocol.transcript import CHASSIS_DIRECTIONS
    from appmode.transcript.dump import run_dump

    fmt = "json" if args.json else "csv" if args.csv else "text"
    only = CHASSIS_DIRECTIONS if args.chassis else None
    return run_dump(args.file, fmt, sys.stdout, args.profile, only)
