"""`appmode record`: log a board's telemetry to a transcript, passively."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from appmode.cli.commands import COMMANDS
from appmode.cli.monitor import add_limits, run_monitor
from appmode.cli.options import Subparsers, add_chassis, add_url, board_choice, file_name
from appmode.errors import AppmodeError

if TYPE_CHECKING:
    from appmode.ports.choice import BoardChoice


def register(sub: Subparsers) -> argparse.ArgumentParser:
    rec = sub.add_parser(
        "record",
        help=COMMANDS["record"],
        description="Write everything the board sends to a transcript, until Ctrl-C, "
        "--duration or --count. It only listens: nothing is written to the port (for a "
        "session that also sends, use --record on drive, send or tap). Read the result "
        "with appmode dump or plot.",
    )
    add_url(rec)
    rec.add_argument("file", type=file_name, metavar="FILE", help="the transcript to write")
    add_limits(rec, "count only these (the transcript holds everything)")
    add_chassis(rec, "record the status frames of the board's chassis port")
    return rec


def run(args: argparse.Namespace) -> int:
    from appmode.line.wire import APP, CHASSIS

    choice = board_choice(args)
    return {APP: _on_app, CHASSIS: _on_chassis}[choice.port](choice, args)


def _on_chassis(choice: BoardChoice, args: argparse.Namespace) -> int:
    from appmode.cli import chassis

    if args.filter is not None:
        raise AppmodeError("--filter picks APP records: not with --chassis")
    return chassis.run_monitor(
        choice,
        as_json=False,
        duration=args.duration,
        count=args.count,
        record=args.file,
        out=None,
        name="record",
    )


def _on_app(choice: BoardChoice, args: argparse.Namespace) -> int:
    return run_monitor(
        choice,
        as_json=False,
        duration=args.duration,
        count=args.count,
        record=args.file,
        kinds=args.filter,
        out=None,
        name="record",
    )
