"""`appmode convert`: a transcript to MCAP and back."""

from __future__ import annotations

import argparse

from appmode.cli.commands import COMMANDS
from appmode.cli.options import Subparsers, add_profile, file_name


def register(sub: Subparsers) -> argparse.ArgumentParser:
    convert = sub.add_parser(
        "convert",
        help=COMMANDS["convert"],
        description="Write a transcript as MCAP (OUT ends in .mcap: the raw bytes of both "
        "directions with their times, and decoded channels for Foxglove), or an MCAP "
        "recording of appmode's as a transcript. Lossless both ways: every line's time, "
        "bytes, directive and comment comes back. Needs the foxglove extra.",
    )
    convert.add_argument("source", type=file_name, metavar="IN", help="a transcript or .mcap")
    convert.add_argument("output", type=file_name, metavar="OUT", help="what to write")
    add_profile(convert, default=None, unset="IN's @board profile=…, else sheet")
    convert.add_argument(
        "--partial",
        action="store_true",
        help="of an MCAP file cut short (a recording stopped by a full disk), keep what it holds",
    )
    return convert


def run(args: argparse.Namespace) -> int:
    from appmode.transcript.convert import run_convert

    return run_convert(args.source, args.output, args.profile, args.partial)
